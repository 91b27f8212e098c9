// A successful `sft import video` end to end in seconds: a tiny OpenCV-written video and a stand-in
// COLMAP (a shell script given by --colmap) whose mapper writes a text model registering every
// frame, with cameras on a circle around a ball of sparse points. Checks the dataset: one view per
// frame, the frames' pixels, the cameras mapped back onto the model's by source_from_world
// (docs/import.md "Normalisation": rotations kept, centres (C − c)/d), the normalisation's box,
// frames.json, the COLMAP log, the stages run, and the removed workspace. The real COLMAP road
// is video_import_long_test.cc.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "src/io/dataset.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

constexpr int kFrames = 12;
constexpr int kWidth = 160;
constexpr int kHeight = 120;
constexpr double kFocal = 150;  // SIMPLE_RADIAL f, pixels (k = 0).
constexpr int kPoints = 80;
constexpr double kBallRadius = 0.5;   // sparse points: uniform in a ball around kObjectCentre.
constexpr double kOrbitRadius = 4.0;  // camera centres' distance from it.
const Eigen::Vector3d kObjectCentre(1.0, -2.0, 0.5);

// Frame `i` of the video: a window panned over a fixed random-block texture, so that consecutive
// frames differ (frame selection keeps them all) and are sharp.
cv::Mat PannedFrame(int i) {
  static const cv::Mat texture = [] {
    cv::Mat blocks(kHeight / 8, 75, CV_8UC3);
    cv::RNG rng(2026);
    rng.fill(blocks, cv::RNG::UNIFORM, 0, 256);
    cv::Mat big;
    cv::resize(blocks, big, cv::Size(75 * 8, kHeight), 0, 0, cv::INTER_NEAREST);
    return big;
  }();
  return texture(cv::Rect(24 * i, 0, kWidth, kHeight)).clone();
}

// The stand-in COLMAP's model: camera centres on a circle around the object at alternating
// elevations (±15°), each looking at the object's centre; points in a ball around it, seen by
// every image (their projections as the images' 2D points). Poses are cam_from_world.
struct FakeModel {
  std::vector<Eigen::Quaterniond> rotations;
  std::vector<Eigen::Vector3d> translations;
  std::vector<Eigen::Vector3d> centres;
  std::vector<Eigen::Vector3d> points;

  FakeModel() {
    for (int i = 0; i < kFrames; ++i) {
      const double azimuth = 2 * M_PI * i / kFrames;
      const double elevation = (i % 2 == 0 ? 15.0 : -15.0) * M_PI / 180;
      const Eigen::Vector3d centre =
          kObjectCentre + kOrbitRadius * Eigen::Vector3d(std::cos(elevation) * std::cos(azimuth),
                                                         std::cos(elevation) * std::sin(azimuth),
                                                         std::sin(elevation));
      // Camera axes (x right, y down, z forward) as the rows of cam_from_world's rotation.
      const Eigen::Vector3d z = (kObjectCentre - centre).normalized();
      const Eigen::Vector3d x = z.cross(Eigen::Vector3d::UnitZ()).normalized();
      const Eigen::Vector3d y = z.cross(x);
      Eigen::Matrix3d r;
      r.row(0) = x;
      r.row(1) = y;
      r.row(2) = z;
      rotations.emplace_back(r);
      translations.push_back(-(r * centre));
      centres.push_back(centre);
    }
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    while (static_cast<int>(points.size()) < kPoints) {
      const Eigen::Vector3d p(u(rng), u(rng), u(rng));
      if (p.norm() <= 1.0) points.push_back(kObjectCentre + kBallRadius * p);
    }
  }

  // Writes cameras.txt, images.txt and points3D.txt (COLMAP's text format) into `dir`.
  void Write(const std::string& dir) const {
    fs::create_directories(dir);
    char line[512];
    std::string cameras = "# CAMERA_ID MODEL WIDTH HEIGHT PARAMS[]\n";
    std::snprintf(line, sizeof(line), "1 SIMPLE_RADIAL %d %d %.17g %.17g %.17g 0\n", kWidth,
                  kHeight, kFocal, kWidth / 2.0, kHeight / 2.0);
    cameras += line;
    std::string images = "# IMAGE_ID QW QX QY QZ TX TY TZ CAMERA_ID NAME, then POINTS2D\n";
    for (int i = 0; i < kFrames; ++i) {
      const Eigen::Quaterniond& q = rotations[i];
      const Eigen::Vector3d& t = translations[i];
      std::snprintf(line, sizeof(line),
                    "%d %.17g %.17g %.17g %.17g %.17g %.17g %.17g 1 frame_%06d.png\n", i + 1, q.w(),
                    q.x(), q.y(), q.z(), t.x(), t.y(), t.z(), i);
      images += line;
      for (int p = 0; p < kPoints; ++p) {
        const Eigen::Vector3d c = q * points[p] + t;
        std::snprintf(line, sizeof(line), "%s%.9g %.9g %d", p > 0 ? " " : "",
                      kFocal * c.x() / c.z() + kWidth / 2.0, kFocal * c.y() / c.z() + kHeight / 2.0,
                      p + 1);
        images += line;
      }
      images += "\n";
    }
    std::string points3d = "# POINT3D_ID X Y Z R G B ERROR TRACK[] as (IMAGE_ID, POINT2D_IDX)\n";
    for (int p = 0; p < kPoints; ++p) {
      std::snprintf(line, sizeof(line), "%d %.17g %.17g %.17g 128 128 128 0.25", p + 1,
                    points[p].x(), points[p].y(), points[p].z());
      points3d += line;
      for (int i = 0; i < kFrames; ++i)
        points3d += " " + std::to_string(i + 1) + " " + std::to_string(p);
      points3d += "\n";
    }
    testing::WriteTestFile(dir + "/cameras.txt", cameras);
    testing::WriteTestFile(dir + "/images.txt", images);
    testing::WriteTestFile(dir + "/points3D.txt", points3d);
  }
};

// Writes the stand-in COLMAP to `path`: it appends each stage's name to `calls`, and its mapper
// checks that every frame the model names is in --image_path (sft wrote them there) before
// copying the model in `model` to OUTPUT_PATH/0, where COLMAP's mapper writes its first model.
void WriteFakeColmap(const std::string& path, const std::string& model, const std::string& calls) {
  std::string names;
  for (int i = 0; i < kFrames; ++i) {
    char name[32];
    std::snprintf(name, sizeof(name), " frame_%06d.png", i);
    names += name;
  }
  testing::WriteTestFile(path,
                         "#!/bin/sh\n"
                         "stage=$1; shift; images=; out=\n"
                         "while [ $# -gt 0 ]; do\n"
                         "  case \"$1\" in\n"
                         "    --image_path) images=$2 ;;\n"
                         "    --output_path) out=$2 ;;\n"
                         "  esac\n"
                         "  shift\n"
                         "done\n"
                         "echo \"$stage\" >> '" +
                             calls +
                             "'\n"
                             "echo \"stand-in colmap: $stage\"\n"
                             "case \"$stage\" in\n"
                             "  feature_extractor|exhaustive_matcher|sequential_matcher) ;;\n"
                             "  mapper)\n"
                             "    for name in" +
                             names +
                             "; do\n"
                             "      [ -f \"$images/$name\" ] || { echo \"no frame $name\"; exit 3; "
                             "}\n"
                             "    done\n"
                             "    mkdir -p \"$out/0\" && cp '" +
                             model + "'/*.txt \"$out/0/\" ;;\n" +
                             "  *) echo \"unknown stage $stage\"; exit 2 ;;\n"
                             "esac\n");
  fs::permissions(path, fs::perms::owner_all);
}

TEST(VideoImportFakeColmapTest, EveryFrameRegisteredBecomesAViewWithTheModelsPose) {
  testing::TempDir tmp;
  const std::string video = tmp.Join("pan.avi");
  {
    cv::VideoWriter writer(video, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 10,
                           cv::Size(kWidth, kHeight));
    ASSERT_TRUE(writer.isOpened());
    for (int i = 0; i < kFrames; ++i) writer.write(PannedFrame(i));
  }
  const FakeModel model;
  model.Write(tmp.Join("model"));
  const std::string colmap = tmp.Join("fake colmap.sh");  // a space: the path is quoted.
  WriteFakeColmap(colmap, tmp.Join("model"), tmp.Join("calls.txt"));

  const std::string out_dir = tmp.Join("ds");
  std::string out;
  ASSERT_EQ(
      testing::RunSft("import video --quiet --video " + video + " --frames " +
                          std::to_string(kFrames) + " --colmap '" + colmap + "' --out " + out_dir,
                      &out),
      0)
      << out;
  EXPECT_EQ(out, "");
  EXPECT_EQ(testing::ReadTestFile(tmp.Join("calls.txt")),
            "feature_extractor\nexhaustive_matcher\nmapper\n");
  EXPECT_FALSE(fs::exists(out_dir + ".video-work")) << "the COLMAP workspace is left behind";

  Dataset dataset;
  ASSERT_TRUE(ReadDataset(out_dir, &dataset).ok());
  EXPECT_TRUE(CheckDatasetFiles(dataset).ok());
  ASSERT_EQ(dataset.views.size(), static_cast<size_t>(kFrames));
  ASSERT_EQ(dataset.cameras.size(), 1u);
  EXPECT_EQ(dataset.cameras[0].width, kWidth);
  EXPECT_EQ(dataset.cameras[0].height, kHeight);
  EXPECT_EQ(dataset.cameras[0].params[0], kFocal);
  EXPECT_EQ(dataset.lighting, "unknown");

  // The normalisation: identity rotation, the object's box centre and diagonal. The box is the
  // 2nd–98th percentile per axis of the ball's points (no support plane among points spread
  // through a ball), so it is a little smaller than the ball's bounding cube.
  ASSERT_TRUE(dataset.has_source_from_world);
  const Similarity3d& s = dataset.source_from_world;
  EXPECT_LT(s.rotation.angularDistance(Eigen::Quaterniond::Identity()), 1e-12);
  EXPECT_LT((s.translation - kObjectCentre).norm(), 0.1 * kBallRadius) << s.translation;
  const double cube_diagonal = 2 * kBallRadius * std::sqrt(3.0);
  EXPECT_GT(s.scale, 0.6 * cube_diagonal);
  EXPECT_LE(s.scale, cube_diagonal);
  EXPECT_EQ(dataset.extra["import"]["normalization"]["method"], "optical_axes");
  EXPECT_EQ(dataset.extra["import"]["normalization"]["points_total"], kPoints);

  // Views in image-id order = frame order; poses are the model's moved into the normalised world;
  // images are the video's frames, pixel for pixel.
  cv::VideoCapture capture(video);
  ASSERT_TRUE(capture.isOpened());
  for (int i = 0; i < kFrames; ++i) {
    SCOPED_TRACE(i);
    const ViewSpec& view = dataset.views[i];
    char name[64];
    std::snprintf(name, sizeof(name), "images/frame_%06d.png", i);
    EXPECT_EQ(view.image, name);
    EXPECT_TRUE(view.mask.empty());
    EXPECT_LT(view.cam_from_world.rotation.angularDistance(model.rotations[i]), 1e-9);
    const Eigen::Vector3d expected_translation =
        (model.translations[i] + model.rotations[i] * s.translation) / s.scale;
    EXPECT_LT((view.cam_from_world.translation - expected_translation).norm(), 1e-9);
    EXPECT_LT((s * view.cam_from_world.Inverse().translation - model.centres[i]).norm(), 1e-9);
    cv::Mat decoded;
    ASSERT_TRUE(capture.read(decoded));
    const cv::Mat imported = cv::imread(out_dir + "/" + view.image, cv::IMREAD_COLOR);
    ASSERT_FALSE(imported.empty()) << view.image;
    ASSERT_EQ(imported.size(), decoded.size());
    EXPECT_EQ(cv::norm(imported, decoded, cv::NORM_INF), 0.0) << view.image;
  }

  // OUT/colmap: the selection record and COLMAP's log (the stand-in's lines).
  const nlohmann::json frames =
      nlohmann::json::parse(testing::ReadTestFile(out_dir + "/colmap/frames.json"), nullptr, false);
  ASSERT_TRUE(frames.is_object());
  EXPECT_EQ(frames["frames_decoded"], kFrames);
  EXPECT_EQ(frames["selected"].size(), static_cast<size_t>(kFrames));
  EXPECT_EQ(frames["registered"], kFrames);
  EXPECT_EQ(frames["matcher"], "exhaustive_matcher");
  EXPECT_EQ(frames["width"], kWidth);
  EXPECT_EQ(frames["height"], kHeight);
  const std::string log = testing::ReadTestFile(out_dir + "/colmap/log.txt");
  for (const char* stage : {"feature_extractor", "exhaustive_matcher", "mapper"}) {
    EXPECT_THAT(log, HasSubstr(std::string("stand-in colmap: ") + stage));
  }
}

}  // namespace
}  // namespace sft
