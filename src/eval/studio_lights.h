// Lights for showing a reconstruction relit (the "Relit" rows of report.html): lights the fit never
// saw, defined in each view's camera frame so that they need no knowledge of the scene's size or
// of a true object, and scaled so that a diffuse surface of albedo a shows a radiance near a:
//   key      a directional light from the camera's upper right and behind it (travelling along
//            (-1, 1, 1)/sqrt(3) in the camera frame: x right, y down, z forward), irradiance
//            0.8·π W/m² on a surface facing it, plus a uniform environment of radiance 0.2 as
//            fill; a diffuse surface facing the light shows 0.8·a + 0.2·a·(visible sky).
//   ambient  a uniform white environment of radiance 1: an unoccluded diffuse surface shows its
//            albedo exactly (∫ a/π · 1 · cos dω = a), so the image reads as the albedo darkened by
//            ambient occlusion: what the fit baked into the texture shows here.
#ifndef SFT_EVAL_STUDIO_LIGHTS_H_
#define SFT_EVAL_STUDIO_LIGHTS_H_

#include <vector>

#include "src/eval/relight_eval.h"

namespace sft {

// Radiance of the key condition's fill environment, and the key light's share of 1.
constexpr double kStudioFill = 0.2;
constexpr double kStudioKey = 1.0 - kStudioFill;

// {key, ambient}: every view uses all of a condition's lights (view_lights empty).
std::vector<RelightCondition> StudioConditions();

}  // namespace sft

#endif  // SFT_EVAL_STUDIO_LIGHTS_H_
