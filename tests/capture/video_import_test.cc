// `sft import video` without running COLMAP: the COLMAP stage plan (matcher choice, command
// lines), the --min-registered rule, and the CLI's error when a (stand-in) COLMAP registers too
// few frames.
#include "src/capture/video_import.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "tests/testing/temp_dir.h"

namespace sft {
namespace {
namespace fs = std::filesystem;

// Value of `flag` in `args` ("" when absent).
std::string Arg(const std::vector<std::string>& args, const std::string& flag) {
  const auto it = std::find(args.begin(), args.end(), flag);
  return it == args.end() || it + 1 == args.end() ? "" : *(it + 1);
}

TEST(VideoImportPlanTest, ExhaustiveUpToTheLimitSequentialBeyond) {
  VideoImportOptions options;
  ASSERT_EQ(options.exhaustive_limit, 150);
  for (int frames : {2, 40, 150}) {
    const std::vector<ColmapStage> stages = PlanColmapStages(options, "/w", frames);
    ASSERT_EQ(stages.size(), 3u);
    EXPECT_EQ(stages[1].name, "exhaustive_matcher") << frames;
    EXPECT_EQ(Arg(stages[1].args, "--ExhaustiveMatching.block_size"), "10");
  }
  for (int frames : {151, 1000}) {
    const std::vector<ColmapStage> stages = PlanColmapStages(options, "/w", frames);
    EXPECT_EQ(stages[1].name, "sequential_matcher") << frames;
    EXPECT_EQ(Arg(stages[1].args, "--ExhaustiveMatching.block_size"), "");
  }
  options.exhaustive_limit = 40;
  EXPECT_EQ(PlanColmapStages(options, "/w", 40)[1].name, "exhaustive_matcher");
  EXPECT_EQ(PlanColmapStages(options, "/w", 41)[1].name, "sequential_matcher");
}

TEST(VideoImportPlanTest, CommandLines) {
  VideoImportOptions options;
  options.camera_model = "OPENCV";
  const std::vector<ColmapStage> stages = PlanColmapStages(options, "/w", 20);
  ASSERT_EQ(stages.size(), 3u);
  EXPECT_EQ(stages[0].name, "feature_extractor");
  EXPECT_EQ(Arg(stages[0].args, "--database_path"), "/w/database.db");
  EXPECT_EQ(Arg(stages[0].args, "--image_path"), "/w/frames");
  EXPECT_EQ(Arg(stages[0].args, "--ImageReader.single_camera"), "1");
  EXPECT_EQ(Arg(stages[0].args, "--ImageReader.camera_model"), "OPENCV");
  EXPECT_EQ(Arg(stages[0].args, "--SiftExtraction.use_gpu"), "0");
  EXPECT_EQ(Arg(stages[1].args, "--database_path"), "/w/database.db");
  EXPECT_EQ(Arg(stages[1].args, "--SiftMatching.use_gpu"), "0");
  EXPECT_EQ(stages[2].name, "mapper");
  EXPECT_EQ(Arg(stages[2].args, "--database_path"), "/w/database.db");
  EXPECT_EQ(Arg(stages[2].args, "--image_path"), "/w/frames");
  EXPECT_EQ(Arg(stages[2].args, "--output_path"), "/w/sparse");
}

TEST(VideoImportRegisteredTest, FewerThanTheThresholdIsOneClearLine) {
  EXPECT_TRUE(CheckRegistered(32, 40, true, 0.8, "/w/log.txt").ok());
  EXPECT_TRUE(CheckRegistered(40, 40, true, 1.0, "/w/log.txt").ok());
  EXPECT_TRUE(CheckRegistered(1, 40, true, 0.0, "/w/log.txt").ok());
  const Status few = CheckRegistered(31, 40, true, 0.8, "/w/log.txt");
  ASSERT_FALSE(few.ok());
  const std::string m = few.message();
  EXPECT_NE(m.find("COLMAP registered 31 of 40 frames (78%, --min-registered 80%)"),
            std::string::npos)
      << m;
  EXPECT_NE(m.find("--frames"), std::string::npos) << m;
  EXPECT_NE(m.find("texture"), std::string::npos) << m;
  EXPECT_NE(m.find("/w/log.txt"), std::string::npos) << m;
  EXPECT_EQ(m.find('\n'), std::string::npos) << m;
  // No model at all (mapper found no initial pair) fails even with --min-registered 0.
  const Status none = CheckRegistered(0, 40, false, 0.0, "/w/log.txt");
  ASSERT_FALSE(none.ok());
  EXPECT_NE(none.message().find("registered 0 of 40"), std::string::npos) << none.message();
}

// A textured 8-bit frame panned by `shift` pixels.
cv::Mat PanFrame(int shift) {
  cv::Mat big(60, 200, CV_8UC3);
  cv::RNG rng(777);
  rng.fill(big, cv::RNG::UNIFORM, 0, 256);
  cv::resize(big, big, cv::Size(800, 240), 0, 0, cv::INTER_NEAREST);
  return big(cv::Rect(shift, 0, 160, 120)).clone();
}

// The CLI with a stand-in COLMAP whose mapper writes the 24-image fixture model: 24 of 30
// selected frames (80% < 90%) is one error line, a non-zero exit, and no output dataset.
TEST(VideoImportCliTest, TooFewRegisteredFramesIsOneErrorLine) {
  testing::TempDir tmp;
  const std::string video = tmp.Join("pan.avi");
  {
    cv::VideoWriter writer(video, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 10,
                           cv::Size(160, 120));
    ASSERT_TRUE(writer.isOpened());
    for (int i = 0; i < 30; ++i) writer.write(PanFrame(20 * i));
  }
  const std::string colmap = tmp.Join("fake_colmap.sh");
  testing::WriteTestFile(colmap,
                         "#!/bin/sh\n"
                         "stage=$1; shift; out=\n"
                         "while [ $# -gt 0 ]; do\n"
                         "  if [ \"$1\" = --output_path ]; then out=$2; fi; shift\n"
                         "done\n"
                         "echo \"stand-in $stage\"\n"
                         "if [ \"$stage\" = mapper ]; then\n"
                         "  mkdir -p \"$out/0\" && cp " +
                             testing::DataDir() + "/colmap/spot/sparse_bin/* \"$out/0/\"\n" +
                             "fi\n");
  fs::permissions(colmap, fs::perms::owner_all);
  std::string out;
  const int code = testing::RunSft("import video --quiet --video " + video +
                                       " --frames 30 --min-registered 0.9 --colmap " + colmap +
                                       " --out " + tmp.Join("d"),
                                   &out);
  EXPECT_NE(code, 0);
  EXPECT_EQ(testing::CountLines(out), 1) << out;
  EXPECT_NE(out.find("COLMAP registered 24 of 30 frames (80%, --min-registered 90%)"),
            std::string::npos)
      << out;
  EXPECT_FALSE(fs::exists(tmp.Join("d/scene.json")));
  // COLMAP's workspace is kept for inspection and named by the error.
  EXPECT_TRUE(fs::exists(tmp.Join("d.video-work/log.txt")));
  EXPECT_NE(out.find("d.video-work/log.txt"), std::string::npos) << out;
}

}  // namespace
}  // namespace sft
