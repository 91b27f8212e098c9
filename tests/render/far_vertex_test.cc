// A few far-away vertices must not change what the rest of the mesh looks like: ray offsets,
// light-distance thresholds and edge tables are local to the surface (or to the referenced
// vertices), never scaled by the whole vertex array's extent. Scene: a unit icosphere resting on a
// large ground quad, a point light, two path segments (shadows, contact and interreflection are
// where a too large ray offset shows), seen from above so the ground fills the image.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "src/core/image.h"
#include "src/geometry/material.h"
#include "src/image/image_io.h"
#include "src/render/camera_rig.h"
#include "src/render/render.h"
#include "src/render/scene.h"
#include "tests/testing/meshes.h"
#include "tests/testing/temp_dir.h"
#include "tests/testing/views.h"

namespace sft {
namespace {

using testing::Triangles;

Triangles SphereOnGround() {
  Triangles scene;
  scene.positions = {{-30, -30, -1}, {30, -30, -1}, {30, 30, -1}, {-30, 30, -1}};
  scene.faces = {{0, 1, 2}, {0, 2, 3}};
  scene.Append(testing::ReadTestMesh("icosphere_r1_320f.obj"));
  return scene;
}

Image Render(const Triangles& mesh) {
  ViewSetup view = testing::LookAtView(Eigen::Vector3d(0.5, -3.5, 3.0), Eigen::Vector3d(0, 0, -0.6),
                                       48, OrbitFocal(48, 40.0));
  testing::AddPointLight(Eigen::Vector3d(1.5, -1.0, 3.0), 20.0, &view);
  const Material material = ConstantMaterial(static_cast<int>(mesh.faces.size()),
                                             Eigen::Vector3d(0.7, 0.6, 0.5), 0.4, 0.2);
  RenderOptions options;
  options.spp = 8;
  options.bounces = 2;
  Image image;
  RenderView(RenderScene(mesh.positions, mesh.faces), material, view, options, &image);
  return image;
}

// Number of pixels whose RGB differ from `base` by more than `relative`·|base| + `absolute`, and
// whether every value of `image` is finite.
int DifferentPixels(const Image& image, const Image& base, double relative, double absolute,
                    bool* finite) {
  int different = 0;
  *finite = true;
  for (int y = 0; y < base.height; ++y) {
    for (int x = 0; x < base.width; ++x) {
      bool differs = false;
      for (int c = 0; c < 4; ++c) {
        const double a = image.at(x, y, c), b = base.at(x, y, c);
        *finite &= std::isfinite(a);
        differs |= !(std::abs(a - b) <= relative * std::abs(b) + absolute);
      }
      different += differs;
    }
  }
  return different;
}

double Sum(const Image& image) {
  double sum = 0.0;
  for (float v : image.data) sum += v;
  return sum;
}

// An unreferenced vertex (no face uses it) is not part of the surface: the image is bit-identical
// to the one without it, at any distance (1e23 used to abort inside Embree, 1e5 to render black,
// 1e3 to change hundreds of pixels by > 5%).
TEST(FarVertexTest, UnreferencedVertexChangesNothing) {
  const Triangles scene = SphereOnGround();
  const Image base = Render(scene);
  ASSERT_GT(Sum(base), 0.0);
  for (const Eigen::Vector3d& far :
       {Eigen::Vector3d(1e3, 0, 0), Eigen::Vector3d(1e5, 1e5, 1e5), Eigen::Vector3d(1e23, 0, 0)}) {
    Triangles with_far = scene;
    with_far.positions.push_back(far);
    bool finite = false;
    EXPECT_EQ(DifferentPixels(Render(with_far), base, 0.0, 0.0, &finite), 0) << far.transpose();
    EXPECT_TRUE(finite) << far.transpose();
  }
}

// Far *referenced* vertices: a sliver triangle from under the ground plane reaching 1e5 away, and
// a huge triangle (size 1e5) 1e5 away. Neither is seen from the camera nor from any surface the
// camera sees (the sliver is below the ground, the huge triangle is lit by 1e-9 of the light), so
// the image must equal the one without them up to float noise: the rest of the mesh keeps its own
// ray offsets. (With offsets scaled by the mesh extent, 2e-5 × 1.7e5 ≈ 3.5 units, the sphere and
// its shadow were lost: 823 and 1705 of 2304 pixels changed.) Tolerance: 1e-4 relative + 1e-6
// absolute per value; measured: with the sliver the image is bit-identical, the huge triangle
// changes 64 pixels by less than that (the light it reflects is ~1e-10).
TEST(FarVertexTest, FarReferencedTrianglesLeaveTheRestUnchanged) {
  const Triangles scene = SphereOnGround();
  const Image base = Render(scene);
  Triangles sliver = scene;
  const int s = static_cast<int>(sliver.positions.size());
  sliver.positions.insert(sliver.positions.end(),
                          {{0, 0, -1.5}, {1e-3, 0, -1.5}, {3e4, 2e4, -1e5}});
  sliver.faces.emplace_back(s, s + 1, s + 2);
  Triangles huge = scene;
  const int h = static_cast<int>(huge.positions.size());
  huge.positions.insert(huge.positions.end(), {{-1e5, 1e5, -1e5}, {1e5, 1e5, -1e5}, {0, 1e5, 1e5}});
  huge.faces.emplace_back(h, h + 1, h + 2);
  for (const auto& [name, mesh] :
       {std::make_pair("sliver", sliver), std::make_pair("huge", huge)}) {
    const Image image = Render(mesh);
    bool finite = false;
    EXPECT_EQ(DifferentPixels(image, base, 1e-4, 1e-6, &finite), 0) << name;
    EXPECT_TRUE(finite) << name;
    EXPECT_NEAR(Sum(image), Sum(base), 1e-4 * Sum(base)) << name;
  }
}

// The same through the command line: `sft render` of an OBJ with an unreferenced `v 1e23 0 0`
// line exits 0 and writes the same (finite) images as for the mesh without it.
TEST(FarVertexTest, RenderCommandIgnoresUnreferencedFarVertex) {
  testing::TempDir tmp;
  const std::string sphere = testing::DataDir() + "/meshes/icosphere_r1_320f.obj";
  const std::string sft = testing::SftBinary();
  std::string out;
  ASSERT_EQ(testing::RunCommand(sft + " synth --quiet --no-normalize --mesh " + sphere + " --out " +
                                    tmp.Join("ds") + " --cameras 2 --zooms 1 --res 24 --spp 4",
                                &out),
            0)
      << out;
  Triangles far = testing::ReadTestMesh("icosphere_r1_320f.obj");
  testing::WriteObj(tmp.Join("plain.obj"), far);
  far.positions.emplace_back(1e23, 0, 0);
  testing::WriteObj(tmp.Join("far.obj"), far);
  for (const char* name : {"plain", "far"}) {
    ASSERT_EQ(testing::RunCommand(sft + " render --quiet --no-report --dataset " + tmp.Join("ds") +
                                      " --mesh " + tmp.Join(std::string(name) + ".obj") +
                                      " --spp 4 --out " + tmp.Join(std::string("r_") + name),
                                  &out),
              0)
        << name << ": " << out;
  }
  for (const char* file : {"000.exr", "001.exr"}) {
    Image plain, far_image;
    ASSERT_TRUE(ReadImage(tmp.Join(std::string("r_plain/images/") + file), &plain).ok());
    ASSERT_TRUE(ReadImage(tmp.Join(std::string("r_far/images/") + file), &far_image).ok());
    bool finite = false;
    EXPECT_EQ(DifferentPixels(far_image, plain, 0.0, 0.0, &finite), 0) << file;
    EXPECT_TRUE(finite) << file;
    EXPECT_GT(Sum(plain), 0.0) << file;
  }
}

}  // namespace
}  // namespace sft
