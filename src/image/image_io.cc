#include "src/image/image_io.h"

#include <tinyexr.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <limits>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "src/core/file_util.h"

namespace sft {
namespace {

// Largest EXR read (DecodeExr): 65536 pixels a side, 2 GiB of decoded 32-bit channel values
// (a 16384x8192 RGB float probe is 1.5 GiB).
constexpr int64_t kMaxExrSide = 65536;
constexpr int64_t kMaxExrBytes = int64_t{2} << 30;

Status PathError(const std::string& path, const std::string& what) {
  return Status::Error(path + ": " + what);
}

// Takes ownership of a tinyexr error message (which may be null) and returns it as a string.
std::string TakeExrError(const char* err) {
  if (err == nullptr) return "unknown error";
  std::string message(err);
  FreeEXRErrorMessage(err);
  // tinyexr's messages may end in (or contain) newlines; errors are one line.
  for (char& c : message) {
    if (c == '\n' || c == '\r') c = ' ';
  }
  while (!message.empty() && message.back() == ' ') message.pop_back();
  return message;
}

// Frees a parsed EXR header and its loaded pixels on scope exit.
struct ExrHolder {
  EXRHeader header;
  EXRImage image;
  bool header_parsed = false;
  bool image_loaded = false;
  ExrHolder() {
    InitEXRHeader(&header);
    InitEXRImage(&image);
  }
  ~ExrHolder() {
    if (image_loaded) FreeEXRImage(&image);
    if (header_parsed) FreeEXRHeader(&header);
  }
};

// The channel name without a layer prefix ("ViewLayer.Combined.R" -> "R").
std::string ChannelSuffix(const std::string& name) {
  const size_t dot = name.rfind('.');
  return dot == std::string::npos ? name : name.substr(dot + 1);
}

std::string ChannelPrefix(const std::string& name) {
  const size_t dot = name.rfind('.');
  return dot == std::string::npos ? std::string() : name.substr(0, dot);
}

// Value `i` (pixel index within the channel's plane) of a loaded channel as float.
float ChannelValue(const unsigned char* plane, int pixel_type, size_t i) {
  if (pixel_type == TINYEXR_PIXELTYPE_UINT) {
    return static_cast<float>(reinterpret_cast<const uint32_t*>(plane)[i]);
  }
  return reinterpret_cast<const float*>(plane)[i];
}

Status DecodeExr(const std::string& data, const std::string& path, Image* image) {
  const auto* bytes = reinterpret_cast<const unsigned char*>(data.data());
  EXRVersion version;
  if (ParseEXRVersionFromMemory(&version, bytes, data.size()) != TINYEXR_SUCCESS) {
    return PathError(path, "not a readable OpenEXR file");
  }
  if (version.multipart || version.non_image) {
    return PathError(path, "multi-part and deep OpenEXR files are not supported");
  }
  ExrHolder exr;
  const char* err = nullptr;
  // tinyexr may allocate channel tables before failing: the header is freed either way.
  exr.header_parsed = true;
  if (ParseEXRHeaderFromMemory(&exr.header, &version, bytes, data.size(), &err) !=
      TINYEXR_SUCCESS) {
    return PathError(path, "cannot read OpenEXR header (" + TakeExrError(err) + ")");
  }
  // tinyexr allocates every channel plane from the header's data window before it decodes a
  // pixel, so a few-kilobyte file can ask for tens of gigabytes (found by fuzz/exr_fuzzer).
  // Bounded here: each side at most kMaxExrSide, and the decoded planes (4-byte values per
  // channel) at most kMaxExrBytes.
  const int64_t exr_width =
      int64_t{exr.header.data_window.max_x} - exr.header.data_window.min_x + 1;
  const int64_t exr_height =
      int64_t{exr.header.data_window.max_y} - exr.header.data_window.min_y + 1;
  if (exr_width <= 0 || exr_height <= 0 || exr_width > kMaxExrSide || exr_height > kMaxExrSide ||
      exr_width * exr_height * std::max(exr.header.num_channels, 1) * 4 > kMaxExrBytes) {
    return PathError(
        path, "OpenEXR data window " + std::to_string(exr_width) + "x" +
                  std::to_string(exr_height) + " with " + std::to_string(exr.header.num_channels) +
                  " channels is empty or too large (at most " + std::to_string(kMaxExrSide) +
                  " pixels a side and " + std::to_string(kMaxExrBytes >> 30) + " GiB of pixels)");
  }
  for (int c = 0; c < exr.header.num_channels; ++c) {
    if (exr.header.pixel_types[c] == TINYEXR_PIXELTYPE_HALF) {
      exr.header.requested_pixel_types[c] = TINYEXR_PIXELTYPE_FLOAT;
    }
    if (exr.header.channels[c].x_sampling > 1 || exr.header.channels[c].y_sampling > 1) {
      return PathError(path, "subsampled OpenEXR channels are not supported");
    }
  }
  if (LoadEXRImageFromMemory(&exr.image, &exr.header, bytes, data.size(), &err) !=
      TINYEXR_SUCCESS) {
    return PathError(path, "cannot read OpenEXR pixels (" + TakeExrError(err) + ")");
  }
  exr.image_loaded = true;
  const int width = exr.image.width;
  const int height = exr.image.height;
  if (width <= 0 || height <= 0) return PathError(path, "OpenEXR image is empty");

  // Pick the channels of the unnamed layer if there is one, else those of the first layer
  // (renderers often write "ViewLayer.Combined.R" etc.).
  std::vector<int> candidates;
  for (int c = 0; c < exr.header.num_channels; ++c) {
    if (ChannelPrefix(exr.header.channels[c].name).empty()) candidates.push_back(c);
  }
  if (candidates.empty() && exr.header.num_channels > 0) {
    const std::string layer = ChannelPrefix(exr.header.channels[0].name);
    for (int c = 0; c < exr.header.num_channels; ++c) {
      if (ChannelPrefix(exr.header.channels[c].name) == layer) candidates.push_back(c);
    }
  }
  int r = -1, g = -1, b = -1, a = -1, y = -1;
  for (int c : candidates) {
    const std::string name = ChannelSuffix(exr.header.channels[c].name);
    if (name == "R") r = c;
    if (name == "G") g = c;
    if (name == "B") b = c;
    if (name == "A") a = c;
    if (name == "Y") y = c;
  }
  // Source channel per output channel.
  std::vector<int> sources;
  if (r >= 0 && g >= 0 && b >= 0) {
    sources = {r, g, b};
    if (a >= 0) sources.push_back(a);
  } else if (candidates.size() == 1) {
    sources = {candidates[0]};
  } else if (y >= 0 && a >= 0 && candidates.size() == 2) {
    sources = {y, y, y, a};
  } else {
    std::string names;
    for (int c = 0; c < exr.header.num_channels; ++c) {
      names += (c ? ", " : "") + std::string(exr.header.channels[c].name);
    }
    return PathError(path, "unsupported OpenEXR channels (" + names +
                               "); expected R, G, B [, A], or a single channel");
  }

  Image result(width, height, static_cast<int>(sources.size()));
  const int* types = exr.header.pixel_types;
  if (exr.header.tiled) {
    if (exr.image.tiles == nullptr) return PathError(path, "OpenEXR tiles missing");
    const int tile_w = exr.header.tile_size_x;
    const int tile_h = exr.header.tile_size_y;
    for (int t = 0; t < exr.image.num_tiles; ++t) {
      const EXRTile& tile = exr.image.tiles[t];
      if (tile.level_x != 0 || tile.level_y != 0) continue;  // only the full-resolution level.
      for (int j = 0; j < tile.height; ++j) {
        for (int i = 0; i < tile.width; ++i) {
          const int px = tile.offset_x * tile_w + i;
          const int py = tile.offset_y * tile_h + j;
          if (px >= width || py >= height) continue;
          const size_t src = static_cast<size_t>(j) * tile_w + i;
          for (size_t k = 0; k < sources.size(); ++k) {
            result.at(px, py, static_cast<int>(k)) =
                ChannelValue(tile.images[sources[k]], types[sources[k]], src);
          }
        }
      }
    }
  } else {
    if (exr.image.images == nullptr) return PathError(path, "OpenEXR pixels missing");
    const size_t n = static_cast<size_t>(width) * height;
    for (size_t k = 0; k < sources.size(); ++k) {
      const unsigned char* plane = exr.image.images[sources[k]];
      const int type = types[sources[k]];
      for (size_t i = 0; i < n; ++i) {
        result.data[i * sources.size() + k] = ChannelValue(plane, type, i);
      }
    }
  }
  *image = std::move(result);
  return Status::Ok();
}

// Lookup tables from 8- and 16-bit sRGB codes to linear values.
const std::vector<float>& SrgbTable(int bits) {
  static const std::vector<float> table8 = [] {
    std::vector<float> t(256);
    for (int i = 0; i < 256; ++i) t[i] = SrgbToLinear(i / 255.0f);
    return t;
  }();
  static const std::vector<float> table16 = [] {
    std::vector<float> t(65536);
    for (int i = 0; i < 65536; ++i) t[i] = SrgbToLinear(i / 65535.0f);
    return t;
  }();
  return bits == 8 ? table8 : table16;
}

Status DecodePng(const std::string& data, const std::string& path, Image* image, bool srgb) {
  cv::Mat mat;
  try {
    // imdecode needs a non-empty buffer; an empty file is simply not a PNG.
    if (data.empty()) return PathError(path, "cannot read PNG (empty file)");
    if (data.size() > static_cast<size_t>(std::numeric_limits<int>::max())) {
      return PathError(path, "cannot read PNG (file larger than 2 GiB)");
    }
    const cv::Mat buffer(1, static_cast<int>(data.size()), CV_8U, const_cast<char*>(data.data()));
    mat = cv::imdecode(buffer, cv::IMREAD_UNCHANGED);
  } catch (const cv::Exception& e) {
    return PathError(path, "cannot read PNG (" + std::string(e.what()) + ")");
  }
  if (mat.empty()) return PathError(path, "cannot read PNG (corrupt or unsupported file)");
  const int depth = mat.depth();
  if (depth != CV_8U && depth != CV_16U) {
    return PathError(path, "unsupported PNG bit depth (expected 8 or 16 bits)");
  }
  const int in_channels = mat.channels();
  if (in_channels < 1 || in_channels > 4) {
    return PathError(path, "unsupported PNG channel count " + std::to_string(in_channels));
  }
  const int bits = depth == CV_8U ? 8 : 16;
  const float scale = depth == CV_8U ? 1.0f / 255.0f : 1.0f / 65535.0f;
  const std::vector<float>& table = SrgbTable(bits);
  // Output channel k reads input channel map[k] (OpenCV's BGR(A) -> RGB(A); grey+alpha -> RGBA).
  std::vector<int> map;
  std::vector<bool> is_alpha;
  switch (in_channels) {
    case 1:
      map = {0};
      is_alpha = {false};
      break;
    case 2:
      map = {0, 0, 0, 1};
      is_alpha = {false, false, false, true};
      break;
    case 3:
      map = {2, 1, 0};
      is_alpha = {false, false, false};
      break;
    default:
      map = {2, 1, 0, 3};
      is_alpha = {false, false, false, true};
      break;
  }
  const int out_channels = static_cast<int>(map.size());
  Image result(mat.cols, mat.rows, out_channels);
  for (int yy = 0; yy < mat.rows; ++yy) {
    const uint8_t* row8 = mat.ptr<uint8_t>(yy);
    const uint16_t* row16 = mat.ptr<uint16_t>(yy);
    for (int xx = 0; xx < mat.cols; ++xx) {
      for (int k = 0; k < out_channels; ++k) {
        const size_t src = static_cast<size_t>(xx) * in_channels + map[k];
        const int code = bits == 8 ? row8[src] : row16[src];
        result.at(xx, yy, k) = (srgb && !is_alpha[k]) ? table[code] : code * scale;
      }
    }
  }
  *image = std::move(result);
  return Status::Ok();
}

Status CheckReadable(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) return PathError(path, "file not found");
  if (std::filesystem::is_directory(path, ec)) {
    return PathError(path, "is a directory, expected an image file");
  }
  return Status::Ok();
}

Status CheckWritable(const std::string& path, const Image& image) {
  if (image.width <= 0 || image.height <= 0) return PathError(path, "cannot write an empty image");
  if (image.channels != 1 && image.channels != 3 && image.channels != 4) {
    return PathError(path, "cannot write an image with " + std::to_string(image.channels) +
                               " channels (expected 1, 3 or 4)");
  }
  if (image.data.size() != static_cast<size_t>(image.width) * image.height * image.channels) {
    return PathError(path, "image data size does not match its dimensions");
  }
  return Status::Ok();
}

}  // namespace

float SrgbToLinear(float v) {
  if (!(v > 0.0f)) return 0.0f;  // also maps NaN to 0.
  if (v >= 1.0f) return 1.0f;
  return v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f);
}

float LinearToSrgb(float v) {
  if (!(v > 0.0f)) return 0.0f;
  if (v >= 1.0f) return 1.0f;
  return v <= 0.0031308f ? v * 12.92f : 1.055f * std::pow(v, 1.0f / 2.4f) - 0.055f;
}

Status ReadImage(const std::string& path, Image* image, bool srgb) {
  const std::string ext = FileExtension(path);
  if (ext != "exr" && ext != "png") {
    return PathError(path, "unsupported image extension \"" + ext + "\" (expected .exr or .png)");
  }
  SFT_RETURN_IF_ERROR(CheckReadable(path));
  std::string data;
  SFT_RETURN_IF_ERROR(ReadTextFile(path, &data));
  return DecodeImage(data, path, image, srgb);
}

Status DecodeImage(const std::string& data, const std::string& path, Image* image, bool srgb) {
  const std::string ext = FileExtension(path);
  if (ext != "exr" && ext != "png") {
    return PathError(path, "unsupported image extension \"" + ext + "\" (expected .exr or .png)");
  }
  return ext == "exr" ? DecodeExr(data, path, image) : DecodePng(data, path, image, srgb);
}

Status ReadMask(const std::string& path, Image* mask) {
  Image raw;
  SFT_RETURN_IF_ERROR(ReadImage(path, &raw, /*srgb=*/false));
  // "> 127 of 255", expressed on normalized values so 16-bit masks work too.
  constexpr float kThreshold = 127.5f / 255.0f;
  Image result(raw.width, raw.height, 1);
  for (int yy = 0; yy < raw.height; ++yy) {
    for (int xx = 0; xx < raw.width; ++xx) {
      result.at(xx, yy) = raw.at(xx, yy, 0) > kThreshold ? 1.0f : 0.0f;
    }
  }
  *mask = std::move(result);
  return Status::Ok();
}

Status WriteExr(const std::string& path, const Image& image) {
  SFT_RETURN_IF_ERROR(CheckWritable(path, image));
  // Channels are stored in alphabetical order as most readers expect; a 1-channel image is "Y".
  std::vector<std::string> names;
  std::vector<int> sources;
  switch (image.channels) {
    case 1:
      names = {"Y"};
      sources = {0};
      break;
    case 3:
      names = {"B", "G", "R"};
      sources = {2, 1, 0};
      break;
    default:
      names = {"A", "B", "G", "R"};
      sources = {3, 2, 1, 0};
      break;
  }
  const int num = static_cast<int>(names.size());
  const size_t n = static_cast<size_t>(image.width) * image.height;
  std::vector<std::vector<float>> planes(num, std::vector<float>(n));
  for (int k = 0; k < num; ++k) {
    for (size_t i = 0; i < n; ++i) planes[k][i] = image.data[i * image.channels + sources[k]];
  }
  std::vector<unsigned char*> plane_ptrs(num);
  for (int k = 0; k < num; ++k) plane_ptrs[k] = reinterpret_cast<unsigned char*>(planes[k].data());

  return WriteAtomically(path, [&](const std::string& tmp) {
    EXRImage exr_image;
    InitEXRImage(&exr_image);
    exr_image.num_channels = num;
    exr_image.images = plane_ptrs.data();
    exr_image.width = image.width;
    exr_image.height = image.height;

    std::vector<EXRChannelInfo> channels(num);
    std::vector<int> pixel_types(num, TINYEXR_PIXELTYPE_FLOAT);
    std::vector<int> requested_types(num, TINYEXR_PIXELTYPE_FLOAT);
    for (int k = 0; k < num; ++k) {
      std::memset(&channels[k], 0, sizeof(EXRChannelInfo));
      std::strncpy(channels[k].name, names[k].c_str(), sizeof(channels[k].name) - 1);
    }
    EXRHeader header;
    InitEXRHeader(&header);
    header.num_channels = num;
    header.channels = channels.data();
    header.pixel_types = pixel_types.data();
    header.requested_pixel_types = requested_types.data();
    // tinyexr's own SaveEXR leaves tiny images uncompressed; do the same.
    header.compression_type = (image.width < 16 && image.height < 16) ? TINYEXR_COMPRESSIONTYPE_NONE
                                                                      : TINYEXR_COMPRESSIONTYPE_ZIP;
    const char* err = nullptr;
    // header's arrays are owned by the vectors above: no FreeEXRHeader here.
    if (SaveEXRImageToFile(&exr_image, &header, tmp.c_str(), &err) != TINYEXR_SUCCESS) {
      return PathError(path, "cannot write OpenEXR (" + TakeExrError(err) + ")");
    }
    return Status::Ok();
  });
}

namespace {

// 8-bit OpenCV matrix (BGR(A) order) of `image`, sRGB-encoding colour channels when `srgb`.
cv::Mat ToPngMat(const Image& image, bool srgb) {
  const int channels = image.channels;
  cv::Mat mat(image.height, image.width, CV_8UC(channels));
  // Output channel k (OpenCV's BGR(A) order) reads image channel map[k].
  const std::array<int, 4> map =
      channels == 1 ? std::array<int, 4>{0, 0, 0, 0} : std::array<int, 4>{2, 1, 0, 3};
  for (int yy = 0; yy < image.height; ++yy) {
    uint8_t* row = mat.ptr<uint8_t>(yy);
    for (int xx = 0; xx < image.width; ++xx) {
      for (int k = 0; k < channels; ++k) {
        float v = image.at(xx, yy, map[k]);
        const bool alpha = channels == 4 && map[k] == 3;
        v = (srgb && !alpha) ? LinearToSrgb(v) : (v > 0.0f ? std::min(v, 1.0f) : 0.0f);
        row[static_cast<size_t>(xx) * channels + k] = static_cast<uint8_t>(std::lround(v * 255.0f));
      }
    }
  }
  return mat;
}

}  // namespace

Status EncodePng(const Image& image, bool srgb, std::string* bytes) {
  if (image.width <= 0 || image.height <= 0 ||
      (image.channels != 1 && image.channels != 3 && image.channels != 4) ||
      image.data.size() != static_cast<size_t>(image.width) * image.height * image.channels) {
    return Status::Error("cannot encode PNG: empty image or unsupported channel count");
  }
  std::vector<uint8_t> buffer;
  try {
    if (!cv::imencode(".png", ToPngMat(image, srgb), buffer)) {
      return Status::Error("cannot encode PNG");
    }
  } catch (const cv::Exception& e) {
    return Status::Error("cannot encode PNG (" + std::string(e.what()) + ")");
  }
  bytes->assign(buffer.begin(), buffer.end());
  return Status::Ok();
}

Status WritePng(const std::string& path, const Image& image, bool srgb) {
  SFT_RETURN_IF_ERROR(CheckWritable(path, image));
  const cv::Mat mat = ToPngMat(image, srgb);
  return WriteAtomically(path, [&](const std::string& tmp) {
    try {
      errno = 0;
      if (!cv::imwrite(tmp, mat)) {
        // errno right after the failing call (OpenCV's fopen/fwrite set it; 0 means no reason).
        const int error = errno;
        return PathError(path, error != 0 ? "cannot write PNG (" + ErrnoText(error) + ")"
                                          : std::string("cannot write PNG"));
      }
    } catch (const cv::Exception& e) {
      return PathError(path, "cannot write PNG (" + std::string(e.what()) + ")");
    }
    return Status::Ok();
  });
}

Status WriteImage(const std::string& path, const Image& image) {
  const std::string ext = FileExtension(path);
  if (ext == "exr") return WriteExr(path, image);
  if (ext == "png") return WritePng(path, image);
  return PathError(path, "unsupported image extension \"" + ext + "\" (expected .exr or .png)");
}

}  // namespace sft
