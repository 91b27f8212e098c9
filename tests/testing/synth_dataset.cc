#include "tests/testing/synth_dataset.h"

#include <cstdlib>
#include <filesystem>
#include <system_error>
#include <vector>

#include "src/core/file_util.h"
#include "src/geometry/material.h"
#include "src/geometry/mesh.h"
#include "src/image/image_io.h"
#include "src/io/dataset.h"
#include "src/io/scene_setup.h"
#include "src/render/render.h"
#include "src/render/scene.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace testing {

std::string SynthIcosphere(const std::string& dir, const std::string& args) {
  std::string output;
  const int code = RunCommand(SftBinary() + " synth --quiet --mesh " + DataDir() +
                                  "/meshes/icosphere_r1_320f.obj --out " + dir + " " + args,
                              &output);
  return code == 0 ? std::string() : "sft synth failed (" + std::to_string(code) + "): " + output;
}

std::string RelightDataset(const std::string& from, const std::string& to,
                           const std::function<void(Dataset*)>& relight) {
  Dataset dataset;
  TriMesh mesh;
  Material truth;
  Status status = ReadDataset(from, &dataset);
  if (status.ok()) status = ReadMesh(JoinPath(from, "gt/mesh.ply"), &mesh);
  if (status.ok()) status = LoadMaterial(JoinPath(from, "gt/material.json"), mesh, &truth);
  if (status.ok()) status = MakeDirectories(JoinPath(to, "images"));
  if (status.ok()) status = MakeDirectories(JoinPath(to, "masks"));
  if (!status.ok()) return status.message();
  std::error_code error;
  std::filesystem::copy(JoinPath(from, "gt"), JoinPath(to, "gt"),
                        std::filesystem::copy_options::recursive, error);
  if (error) return error.message();
  relight(&dataset);
  DatasetViews views;
  status = MakeDatasetViews(dataset, &views);
  if (!status.ok()) return status.message();
  std::vector<Eigen::Vector3d> positions;
  std::vector<Eigen::Vector3i> faces;
  MeshToArrays(mesh, &positions, &faces);
  const RenderScene scene(positions, faces);
  RenderOptions render;
  render.spp = 64;
  render.bounces = 1;
  render.shading = Shading::kFlat;
  for (size_t v = 0; v < dataset.views.size() && status.ok(); ++v) {
    Image image, mask;
    RenderView(scene, truth, views.views[v], render, &image);
    status = WriteImage(JoinPath(to, dataset.views[v].image), image);
    if (status.ok()) status = LoadViewMask(dataset, static_cast<int>(v), &mask);
    if (status.ok()) status = WritePng(JoinPath(to, dataset.views[v].mask), mask, /*srgb=*/false);
  }
  if (status.ok()) status = WriteSceneJson(dataset, to);
  return status.message();
}

std::string CorruptMask(const std::string& dir, int view, bool hole) {
  Dataset dataset;
  Image mask;
  Status status = ReadDataset(dir, &dataset);
  if (status.ok()) status = LoadViewMask(dataset, view, &mask);
  if (!status.ok()) return status.message();
  for (int y = 0; y < mask.height; ++y) {
    for (int x = 0; x < mask.width; ++x) {
      const bool centre = std::abs(2 * x - mask.width) < mask.width / 4 &&
                          std::abs(2 * y - mask.height) < mask.height / 4;
      if (!hole || centre) mask.at(x, y) = 0.f;
    }
  }
  status = WritePng(JoinPath(dataset.root, dataset.views[view].mask), mask, /*srgb=*/false);
  return status.ok() ? std::string() : status.message();
}

void RemoveLights(Dataset* dataset) {
  dataset->lights.clear();
  for (ViewSpec& view : dataset->views) {
    view.lights.clear();
    view.light_ids.clear();
  }
}

}  // namespace testing
}  // namespace sft
