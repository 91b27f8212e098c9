#include "tests/testing/light_fits.h"

#include "src/core/file_util.h"
#include "src/io/light_scales.h"
#include "tests/testing/synth_dataset.h"

namespace sft {
namespace testing {

std::string SynthLightFitIcosphere(const std::string& dir, const std::string& args) {
  return SynthIcosphere(dir,
                        "--cameras 6 --zooms 1 --res 32 --spp 64 --bounces 1 --shading flat "
                        "--material '{\"albedo\": [0.6, 0.5, 0.4], \"roughness\": 0.4, "
                        "\"specular\": 0.2}' " +
                            args);
}

std::string ReadLightFit(const std::string& dir, LightFit* fit) {
  Status status = ReadDataset(dir, &fit->dataset);
  if (status.ok()) status = ReadMesh(JoinPath(dir, "gt/mesh.ply"), &fit->mesh);
  if (status.ok()) {
    status = LoadMaterial(JoinPath(dir, "gt/material.json"), fit->mesh, &fit->material);
  }
  ReconstructOptions& options = fit->options;
  options.cache.render.spp = 8;
  options.cache.render.bounces = 1;
  options.cache.render.shading = Shading::kFlat;
  options.shading = "flat";
  options.cache.pyramid_levels = 3;
  options.phases = PhaseSchedule::kTexture;
  options.outer_iterations = 3;
  options.solver.steps = 5;
  options.regularizers.albedo_smoothness = 0.1;
  return status.message();
}

std::string RunLightFit(const LightFit& fit, const std::vector<Eigen::Vector3d>& positions,
                        const std::vector<Eigen::Vector3d>& directions,
                        std::unique_ptr<Reconstruction>* out) {
  Status status = Reconstruction::Create(fit.dataset, fit.mesh, fit.material, {}, fit.options, out,
                                         {}, Image(), positions, directions);
  for (int outer = 0; status.ok() && outer < fit.options.outer_iterations; ++outer) {
    status = (*out)->RunOuter(outer, nullptr);
  }
  return status.message();
}

std::string LightsFileError(const std::string& path, const Dataset& dataset,
                            const std::string& members) {
  const std::string entry = "{\"id\": \"" + dataset.lights.at(0).id + "\", \"scale\": 1" +
                            (members.empty() ? "" : ", " + members) + "}";
  const Status written =
      WriteTextFile(path, R"({"format": "sft-light-scales/1", "lights": [)" + entry + "]}");
  if (!written.ok()) return written.message();
  std::vector<double> scales;
  std::vector<Eigen::Vector3d> positions, directions;
  return ReadLightScales(path, dataset, &scales, &positions, &directions).message();
}

SceneParameters LayoutTestParameters() {
  const std::vector<Eigen::Vector3d> positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  const Material material =
      ConstantMaterial(1, Eigen::Vector3d::Constant(0.5), 0.5, 0.0, /*resolution=*/1);
  SceneParameters params(positions, material, /*num_lights=*/2, /*num_gain_views=*/2);
  params.values()[params.GainIndex(1, 2)] = 1.5;
  return params;
}

}  // namespace testing
}  // namespace sft
