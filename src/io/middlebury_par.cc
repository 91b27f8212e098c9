#include "src/io/middlebury_par.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <sstream>

#include "src/core/file_util.h"

namespace sft {
namespace {

constexpr int kFields = 22;  // name, 9 of K, 9 of R, 3 of t.

// A finite number filling the whole token (strtod's syntax).
bool ParseNumber(const std::string& token, double* value) {
  errno = 0;
  char* end = nullptr;
  *value = std::strtod(token.c_str(), &end);
  return !token.empty() && end == token.c_str() + token.size() && std::isfinite(*value);
}

std::string Shorten(const std::string& token) {
  return token.size() > 32 ? token.substr(0, 29) + "..." : token;
}

std::vector<std::string> Tokens(const std::string& line) {
  std::istringstream in(line);
  std::vector<std::string> tokens;
  std::string token;
  while (in >> token) tokens.push_back(token);
  return tokens;
}

std::string EntryPrefix(const MiddleburyEntry& entry, const std::string& file) {
  return file + ": line " + std::to_string(entry.line) + " (" + entry.image + "): ";
}

}  // namespace

Status ParseMiddleburyPar(const std::string& text, const std::string& file,
                          std::vector<MiddleburyEntry>* entries) {
  entries->clear();
  std::istringstream in(text);
  std::string line;
  int line_number = 0;
  long long count = -1;
  auto error = [&](const std::string& message) {
    return Status::Error(file + ": line " + std::to_string(line_number) + ": " + message);
  };
  while (std::getline(in, line)) {
    ++line_number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line_number == 1) StripUtf8Bom(&line);
    const std::vector<std::string> tokens = Tokens(line);
    if (tokens.empty()) continue;
    if (count < 0) {
      char* end = nullptr;
      errno = 0;
      count = std::strtoll(tokens[0].c_str(), &end, 10);
      if (tokens.size() != 1 || errno != 0 || end != tokens[0].c_str() + tokens[0].size() ||
          count < 1 || count > kMaxMiddleburyEntries) {
        return error("expected the number of images (1 to " +
                     std::to_string(kMaxMiddleburyEntries) + ") alone on the first line, got \"" +
                     Shorten(line) + "\"");
      }
      continue;
    }
    if (static_cast<long long>(entries->size()) == count) {
      return error("more entries than the count on the first line (" + std::to_string(count) + ")");
    }
    if (tokens.size() != kFields) {
      return error("expected 22 fields (imgname k11..k33 r11..r33 t1 t2 t3), got " +
                   std::to_string(tokens.size()));
    }
    MiddleburyEntry entry;
    entry.line = line_number;
    entry.image = tokens[0];
    std::string why;
    if (!IsContainedRelativePath(entry.image, &why)) {
      return error("image name \"" + Shorten(entry.image) + "\": " + why);
    }
    double values[kFields - 1];
    for (int i = 0; i < kFields - 1; ++i) {
      if (!ParseNumber(tokens[1 + i], &values[i])) {
        static const char* const kNames[] = {"k11", "k12", "k13", "k21", "k22", "k23", "k31",
                                             "k32", "k33", "r11", "r12", "r13", "r21", "r22",
                                             "r23", "r31", "r32", "r33", "t1",  "t2",  "t3"};
        return error(std::string(kNames[i]) + ": expected a finite number, got \"" +
                     Shorten(tokens[1 + i]) + "\"");
      }
    }
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) {
        entry.intrinsics(r, c) = values[3 * r + c];
        entry.rotation(r, c) = values[9 + 3 * r + c];
      }
      entry.translation[r] = values[18 + r];
    }
    entries->push_back(std::move(entry));
  }
  if (count < 0) return Status::Error(file + ": empty (expected the number of images)");
  if (static_cast<long long>(entries->size()) != count) {
    return Status::Error(file + ": the first line announces " + std::to_string(count) +
                         " entries, the file has " + std::to_string(entries->size()));
  }
  return Status::Ok();
}

Status MiddleburyCamera(const MiddleburyEntry& entry, const std::string& file, int width,
                        int height, Camera* camera) {
  std::string why;
  if (!CameraFromIntrinsics(entry.intrinsics, width, height, 0.5, camera, &why)) {
    return Status::Error(EntryPrefix(entry, file) + "K: " + why);
  }
  return Status::Ok();
}

Status MiddleburyPose(const MiddleburyEntry& entry, const std::string& file,
                      Rigid3d* cam_from_world) {
  std::string why;
  if (!RotationFromMatrix(entry.rotation, &cam_from_world->rotation, &why)) {
    return Status::Error(EntryPrefix(entry, file) + "R: " + why);
  }
  cam_from_world->translation = entry.translation;
  return Status::Ok();
}

}  // namespace sft
