// The benchmarks' scene: the 5k-face bunny (data/meshes), a grey material (albedo 0.7, roughness
// 0.5, no gloss) and ThroughputView's oblique camera with its light, at a given resolution.
#ifndef SFT_BENCHMARKS_BUNNY_SCENE_H_
#define SFT_BENCHMARKS_BUNNY_SCENE_H_

#include <glog/logging.h>

#include <memory>

#include "src/eval/throughput.h"
#include "src/geometry/material.h"
#include "src/geometry/mesh.h"
#include "src/render/render.h"
#include "src/render/scene.h"

namespace sft {

struct BunnyScene {
  std::unique_ptr<RenderScene> scene;
  Material material;
  ViewSetup view;
};

inline void MakeBunnyScene(int resolution, BunnyScene* out) {
  TriMesh mesh;
  const Status status = ReadMesh(SFT_DATA_DIR "/meshes/bunny_watertight_5k.obj", &mesh);
  CHECK(status.ok()) << status.message();
  out->scene = std::make_unique<RenderScene>(mesh);
  out->material =
      ConstantMaterial(static_cast<int>(mesh.n_faces()), Eigen::Vector3d::Constant(0.7), 0.5, 0.0);
  out->view = ThroughputView(*out->scene, resolution);
}

}  // namespace sft

#endif  // SFT_BENCHMARKS_BUNNY_SCENE_H_
