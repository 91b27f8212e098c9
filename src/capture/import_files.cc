#include "src/capture/import_files.h"

#include <cctype>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace sft {
namespace {
namespace fs = std::filesystem;

Status CopyFile(const std::string& from, const std::string& to) {
  return WriteAtomically(to, [&from](const std::string& tmp) {
    std::error_code ec;
    fs::copy_file(from, tmp, fs::copy_options::overwrite_existing, ec);
    if (ec) return Status::Error(from + ": cannot copy (" + ec.message() + ")");
    return Status::Ok();
  });
}

std::string FormatName(const std::string& ext) {
  if (ext == "jpg" || ext == "jpeg") return "JPEG";
  if (ext == "tif" || ext == "tiff") return "TIFF";
  if (ext == "webp") return "WebP";
  std::string upper = ext;
  for (char& c : upper) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return upper;
}

}  // namespace

Status ReadImageAsStored(const std::string& path, int flags, cv::Mat* mat) {
  if (!FileExists(path)) return Status::Error(path + ": file not found");
  try {
    *mat = cv::imread(path, flags);
  } catch (const cv::Exception& e) {
    return Status::Error(path + ": cannot decode image (" + e.msg + ")");
  }
  if (mat->empty()) return Status::Error(path + ": cannot decode image");
  return Status::Ok();
}

Status WritePngMat(const std::string& path, const cv::Mat& mat) {
  return WriteAtomically(path, [&mat](const std::string& tmp) {
    try {
      if (cv::imwrite(tmp, mat)) return Status::Ok();
    } catch (const cv::Exception& e) {
      return Status::Error(tmp + ": cannot write PNG (" + e.msg + ")");
    }
    return Status::Error(tmp + ": cannot write PNG");
  });
}

Status StoreImportedImage(const std::string& source, const cv::Mat& mat, const std::string& root,
                          const std::string& out_name, std::string* encoding) {
  const std::string ext = FileExtension(source);
  const int depth = mat.depth();
  const std::string bits = depth == CV_16U ? "16-bit" : "8-bit";
  if (ext == "exr") {
    *encoding = "linear EXR";
    return CopyFile(source, JoinPath(root, out_name));
  }
  if (depth != CV_8U && depth != CV_16U) {
    return Status::Error(source + ": only 8- and 16-bit images (or EXR) can be imported");
  }
  if (ext == "png") {
    *encoding = "sRGB " + bits + " PNG";
    return CopyFile(source, JoinPath(root, out_name));
  }
  *encoding = "sRGB " + bits + " " + FormatName(ext) + " converted to PNG";
  return WritePngMat(JoinPath(root, out_name), mat);
}

Status ReadMaskFile(const std::string& masks, const std::string& name, int width, int height,
                    cv::Mat* binary) {
  std::string path = JoinPath(masks, name + ".png");
  if (!FileExists(path)) path = JoinPath(masks, WithoutExtension(name) + ".png");
  if (!FileExists(path)) {
    return Status::Error(JoinPath(masks, name + ".png") + ": mask of image " + name +
                         " not found (nor " + path + ")");
  }
  cv::Mat mat;
  SFT_RETURN_IF_ERROR(ReadImageAsStored(path, cv::IMREAD_GRAYSCALE, &mat));
  if (mat.cols != width || mat.rows != height) {
    return Status::Error(path + ": mask is " + std::to_string(mat.cols) + "x" +
                         std::to_string(mat.rows) + " but image " + name + " is " +
                         std::to_string(width) + "x" + std::to_string(height));
  }
  cv::threshold(mat, *binary, 127, 255, cv::THRESH_BINARY);  // > 127 = object (docs/dataset.md).
  return Status::Ok();
}

std::string WithoutExtension(const std::string& path) {
  const fs::path p(path);
  return (p.parent_path() / p.stem()).generic_string();
}

Status BuildDatasetFolder(const std::string& out, const RunInputs& inputs, bool overwrite,
                          const std::function<Status(const std::string& partial)>& fill) {
  SFT_RETURN_IF_ERROR(CheckOutputDirectory(out, inputs, "--out"));
  const std::string partial = out + ".partial";
  SFT_RETURN_IF_ERROR(CheckOutputDirectory(partial, inputs, "--out (OUT.partial)"));
  std::error_code ec;
  if (fs::exists(out, ec) && !fs::is_empty(out, ec) && !overwrite) {
    return Status::Error(out + ": output exists and is not empty (use --overwrite)");
  }
  fs::remove_all(partial, ec);
  SFT_RETURN_IF_ERROR(MakeDirectories(partial));
  Status status = fill(partial);
  if (status.ok()) {
    if (fs::exists(out, ec)) fs::remove_all(out, ec);
    fs::rename(partial, out, ec);
    if (ec) {
      status =
          Status::Error(out + ": cannot move the finished dataset in place (" + ec.message() + ")");
    }
  }
  if (!status.ok()) fs::remove_all(partial, ec);
  return status;
}

}  // namespace sft
