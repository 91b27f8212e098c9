// NeRF transforms.json: the OpenGL-to-sft camera convention, intrinsics forms, and errors.
#include "src/io/nerf_transforms.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace sft {
namespace {

using ::testing::HasSubstr;

// A camera at (0, 0, 4) looking at the origin, +y up (OpenGL convention: it looks down −z).
constexpr char kScene[] = R"({
  "camera_angle_x": 0.6911112070083618,
  "frames": [
    {"file_path": "./train/r_0",
     "transform_matrix": [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 4], [0, 0, 0, 1]]},
    {"file_path": "images/b.jpg", "fl_x": 500, "cx": 100, "cy": 90, "w": 200, "h": 180,
     "k1": 0.01, "k2": 0, "p1": 0, "p2": 0.001,
     "transform_matrix": [[0, 0, 1, 4], [1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 0, 1]]}
  ]
})";

TEST(NerfTransformsTest, ConvertsOpenGlPosesToSft) {
  std::vector<NerfFrame> frames;
  const Status status = ParseNerfTransforms(kScene, "t.json", &frames);
  ASSERT_TRUE(status.ok()) << status.message();
  ASSERT_EQ(frames.size(), 2u);
  EXPECT_EQ(frames[0].file_path, "./train/r_0");
  Camera camera;
  ASSERT_TRUE(NerfCamera(frames[0].intrinsics, 800, 800, "frames[0]", &camera).ok());
  EXPECT_NEAR(camera.params[0], 1111.111, 1e-3);  // the Blender scenes' focal length.
  EXPECT_EQ(camera.params[2], 400);
  for (const NerfFrame& frame : frames) {
    Camera c;
    ASSERT_TRUE(NerfCamera(frame.intrinsics, frame.intrinsics.w.value_or(800),
                           frame.intrinsics.h.value_or(800), "f", &c)
                    .ok());
    // The origin is straight ahead, at the principal point.
    const Eigen::Vector3d origin = frame.cam_from_world * Eigen::Vector3d::Zero();
    EXPECT_NEAR(origin.z(), 4, 1e-12);
    EXPECT_LT((c.ImageFromCam(origin) - c.Principal()).norm(), 1e-9);
  }
  // Frame 0: world +y (up in OpenGL's camera) is up in the image (smaller row), +x to the right.
  const Eigen::Vector3d up = frames[0].cam_from_world * Eigen::Vector3d(0, 1, 0);
  const Eigen::Vector3d right = frames[0].cam_from_world * Eigen::Vector3d(1, 0, 0);
  EXPECT_LT(camera.ImageFromCam(up).y(), 400);
  EXPECT_GT(camera.ImageFromCam(right).x(), 400);
  // Frame 1: distortion and per-frame intrinsics make an OPENCV camera.
  Camera opencv;
  ASSERT_TRUE(NerfCamera(frames[1].intrinsics, 200, 180, "f", &opencv).ok());
  EXPECT_EQ(opencv.model, CameraModel::kOpenCV);
  EXPECT_THAT(opencv.params, ::testing::ElementsAre(500, 500, 100, 90, 0.01, 0, 0, 0.001));
  const Status mismatch = NerfCamera(frames[1].intrinsics, 180, 200, "t.json: frames[1]", &opencv);
  EXPECT_THAT(mismatch.message(),
              HasSubstr("t.json: frames[1]: the image is 180x200 but the intrinsics are for "
                        "w=200, h=180"));
}

std::string ParseError(const std::string& text) {
  std::vector<NerfFrame> frames;
  const Status status = ParseNerfTransforms(text, "t.json", &frames);
  EXPECT_FALSE(status.ok()) << text;
  return status.message();
}

TEST(NerfTransformsTest, OneLineErrors) {
  const std::string pose = R"("transform_matrix": [[1,0,0,0],[0,1,0,0],[0,0,1,4],[0,0,0,1]])";
  const std::string frame = R"({"file_path": "a.png", )" + pose + "}";
  EXPECT_THAT(ParseError("{"), HasSubstr("t.json: parse error"));
  EXPECT_THAT(ParseError("[]"), HasSubstr("t.json: expected a JSON object"));
  EXPECT_THAT(ParseError(R"({"frames": []})"), HasSubstr("frames: expected a non-empty array"));
  EXPECT_THAT(ParseError(R"({"frames": [{"file_path": "a.png",
                  "transform_matrix": [[1,0,0,0],[0,1,0,0],[0,0,1,4]]}]})"),
              HasSubstr("frames[0].transform_matrix: expected 4 rows of 4 finite numbers"));
  EXPECT_THAT(ParseError(R"({"frames": [{"file_path": "a.png",
                  "transform_matrix": [[2,0,0,0],[0,1,0,0],[0,0,1,4],[0,0,0,1]]}]})"),
              HasSubstr("frames[0].transform_matrix: rotation block: not a rotation"));
  EXPECT_THAT(ParseError(R"({"frames": [{"file_path": "a.png",
                  "transform_matrix": [[1,0,0,0],[0,1,0,0],[0,0,1,4],[0,0,1,1]]}]})"),
              HasSubstr("the last row must be 0 0 0 1"));
  EXPECT_THAT(ParseError(R"({"frames": [{"file_path": "/abs/a.png", )" + pose + "}]}"),
              HasSubstr("frames[0].file_path: \"/abs/a.png\""));
  EXPECT_THAT(ParseError(R"({"frames": [{)" + pose + "}]}"),
              HasSubstr("frames[0].file_path: expected a string"));
  EXPECT_THAT(ParseError(R"({"fl_x": "500", "frames": [)" + frame + "]}"),
              HasSubstr("t.json: fl_x: expected a finite number"));
  EXPECT_THAT(ParseError(R"({"w": 0, "frames": [)" + frame + "]}"),
              HasSubstr("t.json: w: expected a positive integer"));
  EXPECT_THAT(ParseError(R"({"k3": 0.1, "frames": [)" + frame + "]}"),
              HasSubstr("k3: radial distortion beyond k2 is not supported"));
  EXPECT_THAT(ParseError(R"({"camera_model": "OPENCV_FISHEYE", "frames": [)" + frame + "]}"),
              HasSubstr("camera_model: \"OPENCV_FISHEYE\" is not supported"));
  std::vector<NerfFrame> frames;
  ASSERT_TRUE(ParseNerfTransforms(R"({"frames": [)" + frame + "]}", "t.json", &frames).ok());
  Camera camera;
  EXPECT_THAT(NerfCamera(frames[0].intrinsics, 8, 8, "t.json: frames[0]", &camera).message(),
              HasSubstr("t.json: frames[0]: no focal length"));
}

}  // namespace
}  // namespace sft
