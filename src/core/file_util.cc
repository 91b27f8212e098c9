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

}  // namespace sft
