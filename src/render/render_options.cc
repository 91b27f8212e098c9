#include <string>

#include "src/render/render.h"

namespace sft {

std::string Effects::ToString() const {
  std::string s;
  auto add = [&s](bool on, const char* name) {
    if (!on) return;
    if (!s.empty()) s += ",";
    s += name;
  };
  add(direct, "direct");
  add(shadows, "shadows");
  add(bounces, "bounces");
  add(specular, "specular");
  add(environment, "environment");
  return s.empty() ? "none" : s;
}

bool Effects::Parse(const std::string& list, Effects* effects, std::string* why) {
  Effects parsed;
  parsed.direct = parsed.shadows = parsed.bounces = parsed.specular = parsed.environment = false;
  size_t start = 0;
  while (start <= list.size()) {
    size_t end = list.find(',', start);
    if (end == std::string::npos) end = list.size();
    const std::string name = list.substr(start, end - start);
    if (name == "direct")
      parsed.direct = true;
    else if (name == "shadows")
      parsed.shadows = true;
    else if (name == "bounces")
      parsed.bounces = true;
    else if (name == "specular")
      parsed.specular = true;
    else if (name == "environment")
      parsed.environment = true;
    else if (name == "all")
      parsed = Effects();
    else if (name == "none" || name.empty()) {
    } else {
      *why = "effects: unknown effect '" + name +
             "' (known: direct, shadows, bounces, specular, environment, all, none)";
      return false;
    }
    start = end + 1;
  }
  *effects = parsed;
  return true;
}

bool RenderPassFromName(const std::string& name, RenderPass* pass) {
  if (name == "color")
    *pass = RenderPass::kColor;
  else if (name == "albedo")
    *pass = RenderPass::kAlbedo;
  else if (name == "roughness")
    *pass = RenderPass::kRoughness;
  else if (name == "normal")
    *pass = RenderPass::kNormal;
  else if (name == "depth")
    *pass = RenderPass::kDepth;
  else
    return false;
  return true;
}

bool ShadingFromName(const std::string& name, Shading* shading) {
  if (name == "flat")
    *shading = Shading::kFlat;
  else if (name == "smooth")
    *shading = Shading::kSmooth;
  else
    return false;
  return true;
}

const char* ShadingName(Shading shading) { return shading == Shading::kSmooth ? "smooth" : "flat"; }

bool RenderOptions::Check(std::string* why) const {
  if (spp < 1 || spp > (1 << 20)) {
    *why = "spp: must be in [1, 1048576], got " + std::to_string(spp);
    return false;
  }
  if (bounces < 1 || bounces > 16) {
    *why = "bounces: must be in [1, 16] (1 = direct light only), got " + std::to_string(bounces);
    return false;
  }
  if (threads < 0) {
    *why = "threads: must be >= 0 (0 = all cores), got " + std::to_string(threads);
    return false;
  }
  return true;
}

}  // namespace sft
