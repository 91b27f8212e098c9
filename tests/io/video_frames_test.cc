// Frame selection of `sft import video` (src/io/video_frames.h) on synthetic frames, and a small
// MJPG video round trip through OpenCV.
#include "src/io/video_frames.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

// A textured 8-bit frame: random blocks shifted by `shift` pixels (a panning camera).
cv::Mat TexturedFrame(int shift) {
  cv::Mat big(96, 160, CV_8UC3);
  cv::RNG rng(12345);
  rng.fill(big, cv::RNG::UNIFORM, 0, 256);
  cv::resize(big, big, cv::Size(640, 384), 0, 0, cv::INTER_NEAREST);
  return big(cv::Rect(shift, 0, 320, 240)).clone();
}

cv::Mat Blurred(const cv::Mat& frame) {
  cv::Mat out;
  cv::GaussianBlur(frame, out, cv::Size(0, 0), 3.0);
  return out;
}

TEST(VideoFramesTest, SharpnessOrdersBlur) {
  const cv::Mat sharp = TexturedFrame(0);
  EXPECT_GT(ScoreFrame(sharp, 0).sharpness, 10 * ScoreFrame(Blurred(sharp), 1).sharpness);
  EXPECT_EQ(ScoreFrame(sharp, 0).thumbnail.size(),
            static_cast<size_t>(kThumbnailSize * kThumbnailSize));
}

// 20 frames of a pan, 4 segments of 5: in each segment one frame is sharp and the others are
// blurred, so the sharp ones are picked.
TEST(VideoFramesTest, PicksTheSharpestFramePerSegment) {
  std::vector<FrameScore> scores;
  const std::vector<int> sharp = {3, 5, 12, 19};
  for (int i = 0; i < 20; ++i) {
    const cv::Mat frame = TexturedFrame(8 * i);
    const bool is_sharp = std::find(sharp.begin(), sharp.end(), i) != sharp.end();
    scores.push_back(ScoreFrame(is_sharp ? frame : Blurred(frame), i));
  }
  FrameSelectionOptions options;
  options.frames = 4;
  const std::vector<int> picked = SelectFrames(scores, options);
  EXPECT_EQ(picked, sharp);
}

// A camera that stops: frames 5..14 are identical; only one of them survives. Without the
// duplicate rule (threshold 0) every segment gives a frame.
TEST(VideoFramesTest, DropsNearDuplicates) {
  std::vector<FrameScore> scores;
  for (int i = 0; i < 20; ++i) {
    const int position = i < 5 ? i : (i < 15 ? 5 : i - 9);
    scores.push_back(ScoreFrame(TexturedFrame(24 * position), i));
  }
  FrameSelectionOptions options;
  options.frames = 10;
  const std::vector<int> picked = SelectFrames(scores, options);
  int in_pause = 0;
  for (int i : picked) in_pause += (i >= 5 && i < 15);
  EXPECT_EQ(in_pause, 1);
  EXPECT_EQ(picked.size(), 6u);
  options.duplicate_threshold = 0;
  EXPECT_EQ(SelectFrames(scores, options).size(), 10u);
}

TEST(VideoFramesTest, FewerFramesThanWantedKeepsAll) {
  std::vector<FrameScore> scores;
  for (int i = 0; i < 3; ++i) scores.push_back(ScoreFrame(TexturedFrame(40 * i), i));
  FrameSelectionOptions options;
  options.frames = 50;
  EXPECT_EQ(SelectFrames(scores, options), (std::vector<int>{0, 1, 2}));
}

TEST(VideoFramesTest, OptionsCheck) {
  FrameSelectionOptions options;
  std::string why;
  EXPECT_TRUE(options.Check(&why));
  options.frames = 1;
  EXPECT_FALSE(options.Check(&why));
  EXPECT_NE(why.find("--frames"), std::string::npos);
}

// MJPG in AVI is written and read back by OpenCV; the selected frames come out as PNG files named
// by their frame number.
TEST(VideoFramesTest, VideoRoundTrip) {
  testing::TempDir tmp;
  const std::string video = tmp.Join("v.avi");
  {
    cv::VideoWriter writer(video, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 10,
                           cv::Size(320, 240));
    ASSERT_TRUE(writer.isOpened());
    for (int i = 0; i < 12; ++i) writer.write(TexturedFrame(16 * i));
  }
  std::vector<FrameScore> scores;
  int width = 0, height = 0;
  ASSERT_TRUE(ScoreVideoFrames(video, &scores, &width, &height, false).ok());
  EXPECT_EQ(scores.size(), 12u);
  EXPECT_EQ(width, 320);
  EXPECT_EQ(height, 240);
  std::vector<std::string> names;
  ASSERT_TRUE(WriteVideoFrames(video, {2, 7}, tmp.Join("frames"), &names).ok());
  ASSERT_EQ(names, (std::vector<std::string>{"frame_000002.png", "frame_000007.png"}));
  const cv::Mat frame = cv::imread(tmp.Join("frames/frame_000007.png"));
  EXPECT_EQ(frame.cols, 320);

  std::ofstream(tmp.Join("garbage.avi")) << "not a video";
  const Status bad = ScoreVideoFrames(tmp.Join("garbage.avi"), &scores, &width, &height, false);
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.message().find("garbage.avi"), std::string::npos) << bad.message();
}

}  // namespace
}  // namespace sft
