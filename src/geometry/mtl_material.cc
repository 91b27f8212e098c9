#include "src/geometry/mtl_material.h"

#include <glog/logging.h>

#include <cmath>
#include <set>
#include <sstream>
#include <vector>

namespace sft {
namespace {

struct Line {
  int number = 0;
  std::vector<std::string> tokens;
  std::string rest;  // the text after the keyword, trimmed (file names may contain spaces).
};

std::string Trim(const std::string& s) {
  const size_t first = s.find_first_not_of(" \t\r");
  if (first == std::string::npos) return "";
  return s.substr(first, s.find_last_not_of(" \t\r") - first + 1);
}

Status LineError(const std::string& path, const Line& line, const std::string& what) {
  return Status::Error(path + ":" + std::to_string(line.number) + ": \"" + line.tokens[0] +
                       "\": " + what);
}

// `count` finite numbers after the keyword.
Status Numbers(const std::string& path, const Line& line, size_t count, std::vector<double>* out) {
  out->clear();
  if (line.tokens.size() != count + 1) {
    return LineError(path, line, "expected " + std::to_string(count) + " number(s)");
  }
  for (size_t k = 1; k <= count; ++k) {
    char* end = nullptr;
    const double v = std::strtod(line.tokens[k].c_str(), &end);
    if (end == line.tokens[k].c_str() || *end != '\0' || !std::isfinite(v)) {
      return LineError(path, line, "\"" + line.tokens[k] + "\" is not a finite number");
    }
    out->push_back(v);
  }
  return Status::Ok();
}

// The file name of a map statement (no texture options).
Status MapFile(const std::string& path, const Line& line, std::string* file) {
  if (line.rest.empty()) return LineError(path, line, "expected a file name");
  if (line.rest[0] == '-') {
    return LineError(path, line, "texture options (" + line.tokens[1] + ") are not supported");
  }
  *file = line.rest;
  return Status::Ok();
}

std::vector<Line> SplitLines(const std::string& text) {
  std::vector<Line> lines;
  std::istringstream in(text);
  std::string raw;
  int number = 0;
  while (std::getline(in, raw)) {
    ++number;
    const size_t hash = raw.find('#');
    if (hash != std::string::npos) raw.resize(hash);
    Line line;
    line.number = number;
    std::istringstream words(raw);
    std::string word;
    while (words >> word) line.tokens.push_back(word);
    if (line.tokens.empty()) continue;
    line.rest = Trim(Trim(raw).substr(line.tokens[0].size()));
    lines.push_back(std::move(line));
  }
  return lines;
}

}  // namespace

Status ParseMtl(const std::string& text, const std::string& path, MtlMaterial* material) {
  static const std::set<std::string> kIgnored = {"Ns", "illum", "Ka", "Ke", "Ni", "d", "Tr"};
  nlohmann::json json = nlohmann::json::object();
  std::map<std::string, std::string> statement;
  std::vector<double> kd, pr, numbers;
  const Line* kd_line = nullptr;
  const Line* pr_line = nullptr;
  std::set<std::string> unknown;
  int materials = 0;
  const std::vector<Line> lines = SplitLines(text);
  for (const Line& line : lines) {
    const std::string& key = line.tokens[0];
    if (key == "newmtl") {
      if (++materials > 1) {
        return LineError(path, line, "a second material; only one material is supported");
      }
    } else if (key == "map_Kd" || key == "map_Pr") {
      std::string file;
      SFT_RETURN_IF_ERROR(MapFile(path, line, &file));
      const char* field = key == "map_Kd" ? "uv_albedo" : "uv_roughness";
      json[field] = file;
      statement[field] = key;
      if (key == "map_Kd") json["colorspace"] = "srgb";
    } else if (key == "Kd") {
      SFT_RETURN_IF_ERROR(Numbers(path, line, 3, &kd));
      kd_line = &line;
    } else if (key == "Pr") {
      SFT_RETURN_IF_ERROR(Numbers(path, line, 1, &pr));
      pr_line = &line;
    } else if (key == "Ks") {
      SFT_RETURN_IF_ERROR(Numbers(path, line, 3, &numbers));
      if (numbers[0] != numbers[1] || numbers[1] != numbers[2]) {
        return LineError(path, line, "expected three equal numbers (sft's specular is grey)");
      }
      json["specular"] = numbers[0];
      statement["specular"] = "Ks";
    } else if (key == "Pm") {
      SFT_RETURN_IF_ERROR(Numbers(path, line, 1, &numbers));
      if (numbers[0] != 0.0) return LineError(path, line, "must be 0 (no metallic lobe)");
    } else if (kIgnored.count(key) == 0) {
      unknown.insert(key);
    }
  }
  if (kd_line != nullptr) {
    if (json.contains("uv_albedo")) {
      if (kd[0] != 1.0 || kd[1] != 1.0 || kd[2] != 1.0) {
        return LineError(path, *kd_line, "must be 1 1 1 with map_Kd (MTL multiplies the map)");
      }
    } else {
      json["albedo"] = kd;
      statement["albedo"] = "Kd";
    }
  }
  if (pr_line != nullptr) {
    if (json.contains("uv_roughness")) {
      if (pr[0] != 1.0) return LineError(path, *pr_line, "must be 1 with map_Pr");
    } else {
      json["roughness"] = pr[0];
      statement["roughness"] = "Pr";
    }
  }
  if (!unknown.empty()) {
    std::string list;
    for (const std::string& key : unknown) list += (list.empty() ? "" : ", ") + key;
    LOG(WARNING) << path << ": ignored MTL statements: " << list;
  }
  material->json = std::move(json);
  material->statement_of_field = std::move(statement);
  return Status::Ok();
}

}  // namespace sft
