// AddGroundPlane's floor ring (`sft synth --ground-floor`): what a point on the object sees just
// below its horizon. Under a far-field probe the finite textured plane lets the probe's light below
// the horizon through past its edge; the floor closes that gap, which is what `--probe-ground`'s
// black lower hemisphere models (docs/dataset.md).
#include "src/io/synth_scene.h"

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <cmath>
#include <string>

#include "src/geometry/material.h"
#include "src/geometry/mesh.h"
#include "src/render/scene.h"

namespace sft {
namespace {

// A unit-ish tetrahedron standing on z = 0 (diagonal of its box: sqrt(3)).
TriMesh Tetrahedron() {
  TriMesh mesh;
  const auto a = mesh.add_vertex(TriMesh::Point(0, 0, 0));
  const auto b = mesh.add_vertex(TriMesh::Point(1, 0, 0));
  const auto c = mesh.add_vertex(TriMesh::Point(0, 1, 0));
  const auto d = mesh.add_vertex(TriMesh::Point(0, 0, 1));
  mesh.add_face(a, c, b);
  mesh.add_face(a, b, d);
  mesh.add_face(a, d, c);
  mesh.add_face(b, c, d);
  return mesh;
}

Material PlainMaterial(int faces) {
  Material material;
  material.albedo = MeshColors(faces, 1, 3, 0.5);
  material.roughness = MeshColors(faces, 1, 1, 0.6);
  return material;
}

// Casts a ray from height `height` above the plane's centre at `degrees` below the horizon.
RayHit CastBelowHorizon(const TriMesh& scene_mesh, double height, double degrees) {
  const RenderScene scene(scene_mesh);
  const double a = degrees * M_PI / 180;
  // From beside the object (x = -1), looking away from it (-x), so only the ground can be hit.
  const Eigen::Vector3d origin(-1.0, 0.5, height);
  return scene.Intersect(origin, Eigen::Vector3d(-std::cos(a), 0, -std::sin(a)), 1e-6, 1e9);
}

TEST(SynthSceneTest, FloorStopsRaysThatPassThePlanesEdge) {
  const TriMesh object = Tetrahedron();
  const Material material = PlainMaterial(static_cast<int>(object.n_faces()));
  const double diagonal = std::sqrt(3.0);
  GroundOptions options;
  options.cells = 4;
  options.gap = 0;
  options.half_size = 2;
  TriMesh plane_mesh, floor_mesh;
  Material plane_material, floor_material;
  ASSERT_TRUE(AddGroundPlane(object, material, options, &plane_mesh, &plane_material).ok());
  options.floor_half_size = 50;
  ASSERT_TRUE(AddGroundPlane(object, material, options, &floor_mesh, &floor_material).ok());
  const int plane_faces = 4 + 2 * 4 * 4;
  ASSERT_EQ(static_cast<int>(plane_mesh.n_faces()), plane_faces);
  ASSERT_EQ(static_cast<int>(floor_mesh.n_faces()), plane_faces + 8);
  ASSERT_EQ(floor_material.albedo.num_faces(), plane_faces + 8);

  // 3 degrees down from 0.5 above the plane: the plane ends 2 diagonals (3.46) from its centre
  // (x = 0.5), 1.96 from the origin, and the ray reaches z = 0 only 0.5 / tan(3°) = 9.54 away.
  const double height = 0.5, degrees = 3;
  EXPECT_FALSE(CastBelowHorizon(plane_mesh, height, degrees).hit);
  const RayHit hit = CastBelowHorizon(floor_mesh, height, degrees);
  ASSERT_TRUE(hit.hit);
  EXPECT_GE(hit.face, plane_faces);  // one of the floor's 8 faces.
  EXPECT_NEAR(hit.t, height / std::sin(degrees * M_PI / 180), 1e-6 * hit.t);
  // Steeper rays land on the textured plane with or without the floor, at the same point.
  const RayHit near_plane = CastBelowHorizon(plane_mesh, height, 30);
  const RayHit near_floor = CastBelowHorizon(floor_mesh, height, 30);
  ASSERT_TRUE(near_plane.hit && near_floor.hit);
  EXPECT_EQ(near_plane.face, near_floor.face);
  EXPECT_NEAR(near_floor.t, height / std::sin(30 * M_PI / 180), 1e-9);
  // The floor ends 50 diagonals from the plane's centre (x = 0.5), 85.1 from the origin: a ray
  // that reaches z = 0 just before that hits it, one that reaches it just after misses.
  const double edge = 50 * diagonal - 1.5;
  EXPECT_TRUE(
      CastBelowHorizon(floor_mesh, height, std::atan(height / (edge - 0.1)) * 180 / M_PI).hit);
  EXPECT_FALSE(
      CastBelowHorizon(floor_mesh, height, std::atan(height / (edge + 0.1)) * 180 / M_PI).hit);

  // The floor's texels are one plain colour; the plane's keep their noise.
  for (int f = plane_faces; f < plane_faces + 8; ++f) {
    const double* t = floor_material.albedo.texel(f * MeshColors::TexelsPerFace(1));
    EXPECT_DOUBLE_EQ(t[0], 0.35);
    EXPECT_DOUBLE_EQ(t[2], 0.25);
  }
}

TEST(SynthSceneTest, FloorMustBeWiderThanThePlane) {
  GroundOptions options;
  std::string why;
  EXPECT_TRUE(options.Check(&why));
  options.floor_half_size = options.half_size;
  EXPECT_FALSE(options.Check(&why));
  EXPECT_NE(why.find("--ground-floor"), std::string::npos);
  options.floor_half_size = 1e4;
  EXPECT_FALSE(options.Check(&why));
  options.floor_half_size = 50;
  EXPECT_TRUE(options.Check(&why)) << why;
}

}  // namespace
}  // namespace sft
