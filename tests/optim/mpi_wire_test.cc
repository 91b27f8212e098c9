// The byte format of the messages between MPI ranks (src/optim/mpi_wire.h): every part of a
// render state, the fitted environment's texels and parameter layout among them, reads back as
// written, and a state whose texels alone changed differs from the last one in that part only
// (only changed parts are sent).
#include "src/optim/mpi_wire.h"

#include <gtest/gtest.h>

#include <vector>

namespace sft {
namespace {

RenderState SomeState() {
  RenderState s;
  s.scene_id = 7;
  s.build_positions = {{0.0, 0.0, 0.0}, {1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}};
  s.faces = {{0, 1, 2}};
  s.positions = {{0.0, 0.0, 0.1}, {1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}};
  s.material.albedo = MeshColors(1, 1, 3);
  s.material.albedo.values().assign(s.material.albedo.values().size(), 0.25);
  s.material.roughness = MeshColors(1, 1, 1);
  s.material.roughness.values().assign(s.material.roughness.values().size(), 0.5);
  s.material.specular = 0.3;
  s.light_scales = {1.0, 2.5};
  s.render.spp = 8;
  s.render.bounces = 2;
  s.render.seed = 99;
  s.request.params.vertices = true;
  s.request.primary_edge_ratio = 0.25;
  s.layout.num_vertices = 3;
  s.layout.num_albedo_texels = s.material.NumAlbedoTexels();
  s.layout.num_roughness_texels = s.material.NumRoughnessTexels();
  s.layout.num_lights = 2;
  s.layout.num_environment_texels = 4 * 2;
  s.layout.environment_light = 1;
  s.image_scale_log2 = 1;
  s.view_indices = {0, 2, 3};
  s.environment = Image(4, 2, 3);
  for (size_t k = 0; k < s.environment.data.size(); ++k) s.environment.data[k] = 0.1f * k;
  s.environment_frame = LightFrame::kCamera;
  return s;
}

RenderState ReadBack(const RenderState& s) {
  const std::vector<std::vector<char> > parts = StateParts(s);
  EXPECT_EQ(parts.size(), static_cast<size_t>(kNumParts));
  RenderState read;
  for (int p = 0; p < kNumParts; ++p) ApplyStatePart(p, parts[p], &read);
  return read;
}

TEST(MpiWireTest, StateReadsBackAsWritten) {
  const RenderState s = SomeState();
  const RenderState r = ReadBack(s);
  EXPECT_EQ(r.scene_id, s.scene_id);
  EXPECT_EQ(r.build_positions, s.build_positions);
  EXPECT_EQ(r.faces, s.faces);
  EXPECT_EQ(r.positions, s.positions);
  EXPECT_EQ(r.material.albedo.values(), s.material.albedo.values());
  EXPECT_EQ(r.material.roughness.values(), s.material.roughness.values());
  EXPECT_EQ(r.material.specular, s.material.specular);
  EXPECT_EQ(r.light_scales, s.light_scales);
  EXPECT_EQ(r.render.spp, s.render.spp);
  EXPECT_EQ(r.render.bounces, s.render.bounces);
  EXPECT_EQ(r.render.seed, s.render.seed);
  EXPECT_TRUE(r.request.params.vertices);
  EXPECT_EQ(r.request.primary_edge_ratio, s.request.primary_edge_ratio);
  EXPECT_EQ(r.layout.num_vertices, s.layout.num_vertices);
  EXPECT_EQ(r.layout.num_albedo_texels, s.layout.num_albedo_texels);
  EXPECT_EQ(r.layout.num_roughness_texels, s.layout.num_roughness_texels);
  EXPECT_EQ(r.layout.num_lights, 2);
  EXPECT_EQ(r.layout.num_environment_texels, 8);
  EXPECT_EQ(r.layout.environment_light, 1);
  EXPECT_EQ(r.layout.size(), s.layout.size());
  EXPECT_EQ(r.image_scale_log2, 1);
  EXPECT_EQ(r.view_indices, s.view_indices);
  EXPECT_EQ(r.environment.width, 4);
  EXPECT_EQ(r.environment.height, 2);
  EXPECT_EQ(r.environment.channels, 3);
  EXPECT_EQ(r.environment.data, s.environment.data);
  EXPECT_EQ(r.environment_frame, LightFrame::kCamera);
}

TEST(MpiWireTest, StateWithoutEnvironmentReadsBackEmpty) {
  RenderState s = SomeState();
  s.environment = Image();
  s.layout.num_environment_texels = 0;
  s.layout.environment_light = -1;
  RenderState stale = SomeState();  // a worker's state from an earlier fit with an environment.
  const std::vector<std::vector<char> > parts = StateParts(s);
  for (int p = 0; p < kNumParts; ++p) ApplyStatePart(p, parts[p], &stale);
  EXPECT_TRUE(stale.environment.empty());
  EXPECT_EQ(stale.layout.num_environment_texels, 0);
}

TEST(MpiWireTest, NewTexelsChangeTheEnvironmentPartOnly) {
  const RenderState s = SomeState();
  RenderState t = s;
  t.environment.data[5] += 1.0f;
  const std::vector<std::vector<char> > a = StateParts(s), b = StateParts(t);
  for (int p = 0; p < kNumParts; ++p) {
    EXPECT_EQ(a[p] == b[p], p != kEnvironmentPart) << "part " << p;
  }
  RenderState worker = ReadBack(s);
  ApplyStatePart(kEnvironmentPart, b[kEnvironmentPart], &worker);
  EXPECT_EQ(worker.environment.data, t.environment.data);
}

}  // namespace
}  // namespace sft
