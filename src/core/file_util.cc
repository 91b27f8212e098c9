#include "src/core/file_util.h"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace sft {
namespace fs = std::filesystem;

std::string JoinPath(const std::string& base, const std::string& relative) {
  if (relative.empty()) return base;
  if (relative[0] == '/' || base.empty()) return relative;
  return (fs::path(base) / relative).string();
}

std::string FileExtension(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  if (!ext.empty() && ext[0] == '.') ext = ext.substr(1);
  std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
  return ext;
}

Status MakeDirectories(const std::string& path) {
  if (path.empty()) return Status::Ok();
  std::error_code ec;
  fs::create_directories(path, ec);
  if (ec) return Status::Error(path + ": cannot create directory (" + ec.message() + ")");
  return Status::Ok();
}

bool FileExists(const std::string& path) {
  std::error_code ec;
  return fs::exists(path, ec);
}

Status WriteAtomically(const std::string& path,
                       const std::function<Status(const std::string& tmp_path)>& write) {
  static std::atomic<int> counter{0};
  const fs::path target(path);
  SFT_RETURN_IF_ERROR(MakeDirectories(target.parent_path().string()));
  const std::string ext = target.extension().string();
  fs::path tmp = target;
  tmp.replace_filename("." + target.stem().string() + ".tmp" + std::to_string(getpid()) + "_" +
                       std::to_string(counter++) + ext);
  Status status = write(tmp.string());
  std::error_code ec;
  if (!status.ok()) {
    fs::remove(tmp, ec);
    return status;
  }
  fs::rename(tmp, target, ec);
  if (ec) {
    // The reason is taken before the clean-up, whose own error code would overwrite it (the
    // message used to read "cannot write (Success)").
    const std::string reason = ec.message();
    std::error_code ignored;
    fs::remove(tmp, ignored);
    return Status::Error(path + ": cannot write (" + reason + ")");
  }
  return Status::Ok();
}

Status WriteTextFile(const std::string& path, const std::string& contents) {
  return WriteAtomically(path, [&](const std::string& tmp) {
    errno = 0;
    std::ofstream out(tmp, std::ios::binary);
    if (!out) return Status::Error(path + ": cannot write (" + ErrnoText(errno) + ")");
    out << contents;
    out.close();
    if (!out) return Status::Error(path + ": cannot write (" + ErrnoText(errno) + ")");
    return Status::Ok();
  });
}

std::string ErrnoText(int error_number) {
  return error_number == 0 ? "unknown error" : std::strerror(error_number);
}

void StripUtf8Bom(std::string* text) {
  if (text->compare(0, 3, "\xEF\xBB\xBF") == 0) text->erase(0, 3);
}

Status ReadTextFile(const std::string& path, std::string* contents) {
  std::error_code ec;
  if (!fs::exists(path, ec)) return Status::Error(path + ": file not found");
  if (fs::is_directory(path, ec)) return Status::Error(path + ": is a directory, expected a file");
  std::ifstream in(path, std::ios::binary);
  if (!in) return Status::Error(path + ": cannot open");
  std::ostringstream ss;
  ss << in.rdbuf();
  *contents = ss.str();
  return Status::Ok();
}

bool IsContainedRelativePath(const std::string& path, std::string* why) {
  if (path.empty()) {
    *why = "empty path";
    return false;
  }
  const fs::path p(path);
  if (p.is_absolute() || p.has_root_name() || p.has_root_directory()) {
    *why = "absolute path \"" + path + "\" (must be relative to the dataset folder)";
    return false;
  }
  for (const fs::path& part : p) {
    if (part == "..") {
      *why = "path \"" + path + "\" has a '..' component (must stay inside the dataset folder)";
      return false;
    }
  }
  if (p.lexically_normal() == "." || p.filename().empty()) {
    *why = "path \"" + path + "\" names a folder, expected a file";
    return false;
  }
  return true;
}

namespace {

// `path` with symbolic links, "." and ".." resolved as far as it exists (absolute).
fs::path Resolved(const std::string& path) {
  std::error_code ec;
  fs::path resolved = fs::weakly_canonical(fs::absolute(path, ec), ec);
  if (ec) resolved = fs::absolute(path, ec).lexically_normal();
  // weakly_canonical keeps a trailing separator ("D/" -> "D/"): drop it so "D/" == "D".
  if (resolved.has_relative_path() && resolved.filename().empty()) {
    resolved = resolved.parent_path();
  }
  return resolved;
}

// Whether `inner` is `outer` or lies below it (both resolved).
bool IsWithin(const fs::path& inner, const fs::path& outer) {
  auto i = inner.begin();
  for (auto o = outer.begin(); o != outer.end(); ++o, ++i) {
    if (i == inner.end() || *i != *o) return false;
  }
  return true;
}

}  // namespace

Status CheckOutputDirectory(const std::string& out, const RunInputs& inputs,
                            const std::string& flag) {
  if (out.empty()) return Status::Error(flag + ": must not be empty");
  std::error_code ec;
  if (fs::exists(out, ec) && !fs::is_directory(out, ec)) {
    return Status::Error(flag + " " + out + ": exists and is not a directory");
  }
  const fs::path o = Resolved(out);
  for (const std::string& dir : inputs.directories) {
    if (dir.empty()) continue;
    const fs::path d = Resolved(dir);
    if (IsWithin(o, d)) {
      return Status::Error(flag + " " + out + ": is " + (o == d ? "" : "inside ") +
                           "the input folder " + dir +
                           "; outputs never go into an input (choose another folder)");
    }
    if (IsWithin(d, o)) {
      return Status::Error(flag + " " + out + ": holds the input folder " + dir +
                           "; outputs never go where inputs are (choose another folder)");
    }
  }
  for (const std::string& file : inputs.files) {
    if (file.empty()) continue;
    if (IsWithin(Resolved(file), o)) {
      return Status::Error(flag + " " + out + ": holds the input file " + file +
                           "; outputs never go where inputs are (choose another folder)");
    }
  }
  return Status::Ok();
}

Status CheckOutputFile(const std::string& file, const RunInputs& inputs, const std::string& flag) {
  if (file.empty()) return Status::Error(flag + ": must not be empty");
  std::error_code ec;
  if (fs::is_directory(file, ec)) return Status::Error(flag + " " + file + ": is a directory");
  const fs::path f = Resolved(file);
  for (const std::string& dir : inputs.directories) {
    if (!dir.empty() && IsWithin(f, Resolved(dir))) {
      return Status::Error(flag + " " + file + ": is inside the input folder " + dir +
                           "; outputs never go into an input");
    }
  }
  for (const std::string& input : inputs.files) {
    if (!input.empty() && f == Resolved(input)) {
      return Status::Error(flag + " " + file + ": is an input file of this run");
    }
  }
  return Status::Ok();
}

}  // namespace sft
