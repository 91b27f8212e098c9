#include "src/io/video_frames.h"

#include <cmath>
#include <cstdio>
#include <opencv2/core/utils/logger.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>
#include <opencv2/videoio/registry.hpp>

#include "src/core/file_util.h"
#include "src/core/progress.h"

namespace sft {

bool FrameSelectionOptions::Check(std::string* why) const {
  if (frames < 2 || frames > 10000) {
    *why = "--frames: must be in [2, 10000], got " + std::to_string(frames);
    return false;
  }
  if (!(duplicate_threshold >= 0 && duplicate_threshold <= 1)) {
    *why = "--duplicate-threshold: must be in [0, 1]";
    return false;
  }
  return true;
}

FrameScore ScoreFrame(const cv::Mat& frame, int index) {
  cv::Mat gray;
  if (frame.channels() == 3) {
    cv::cvtColor(frame, gray, cv::COLOR_BGR2GRAY);
  } else if (frame.channels() == 4) {
    cv::cvtColor(frame, gray, cv::COLOR_BGRA2GRAY);
  } else {
    gray = frame;
  }
  cv::Mat laplacian;
  cv::Laplacian(gray, laplacian, CV_64F);
  cv::Scalar mean, stddev;
  cv::meanStdDev(laplacian, mean, stddev);
  FrameScore score;
  score.index = index;
  score.sharpness = stddev[0] * stddev[0];
  cv::Mat thumb;
  cv::resize(gray, thumb, cv::Size(kThumbnailSize, kThumbnailSize), 0, 0, cv::INTER_AREA);
  thumb.convertTo(thumb, CV_32F, 1.0 / 255.0);
  score.thumbnail.assign(thumb.begin<float>(), thumb.end<float>());
  return score;
}

namespace {

// Opens `video` with OpenCV's FFmpeg backend, then the other backends that read files, with
// OpenCV's own log silenced so that a file it cannot decode gives only our one error line. Not
// libgphoto2: given a path it enumerates the USB cameras attached (loading its ~60 camera
// driver modules), which a video file never needs.
bool OpenVideo(const std::string& video, cv::VideoCapture* capture) {
  const auto level = cv::utils::logging::getLogLevel();
  cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_SILENT);
  bool opened = capture->open(video, cv::CAP_FFMPEG) && capture->isOpened();
  for (const cv::VideoCaptureAPIs api : cv::videoio_registry::getStreamBackends()) {
    if (opened) break;
    if (api == cv::CAP_FFMPEG || api == cv::CAP_GPHOTO2) continue;
    opened = capture->open(video, api) && capture->isOpened();
  }
  cv::utils::logging::setLogLevel(level);
  return opened;
}

double ThumbnailDifference(const std::vector<float>& a, const std::vector<float>& b) {
  if (a.size() != b.size() || a.empty()) return 1.0;
  double sum = 0;
  for (size_t i = 0; i < a.size(); ++i) sum += std::abs(a[i] - b[i]);
  return sum / a.size();
}

}  // namespace

std::vector<int> SelectFrames(const std::vector<FrameScore>& scores,
                              const FrameSelectionOptions& options) {
  const int count = static_cast<int>(scores.size());
  const int segments = std::min(options.frames, count);
  std::vector<int> selected;
  for (int s = 0; s < segments; ++s) {
    const int begin = static_cast<int>(static_cast<int64_t>(s) * count / segments);
    const int end = static_cast<int>(static_cast<int64_t>(s + 1) * count / segments);
    int best = begin;
    for (int i = begin + 1; i < end; ++i) {
      if (scores[i].sharpness > scores[best].sharpness) best = i;
    }
    if (!selected.empty() &&
        ThumbnailDifference(scores[best].thumbnail, scores[selected.back()].thumbnail) <
            options.duplicate_threshold) {
      continue;
    }
    selected.push_back(best);
  }
  return selected;
}

std::string VideoFrameName(int index) {
  char name[32];
  std::snprintf(name, sizeof(name), "frame_%06d.png", index);
  return name;
}

Status ScoreVideoFrames(const std::string& video, std::vector<FrameScore>* scores, int* width,
                        int* height, bool progress_enabled) {
  scores->clear();
  if (!FileExists(video)) return Status::Error("--video: " + video + ": file not found");
  try {
    cv::VideoCapture capture;
    if (!OpenVideo(video, &capture)) {
      return Status::Error("--video: " + video + ": cannot open (not a video OpenCV can decode)");
    }
    const double reported = capture.get(cv::CAP_PROP_FRAME_COUNT);
    const int64_t total = reported > 0 && reported < 1e7 ? static_cast<int64_t>(reported) : 0;
    Progress progress("import video: frames", total, progress_enabled && total > 0);
    cv::Mat frame;
    while (capture.read(frame) && !frame.empty()) {
      if (scores->empty()) {
        *width = frame.cols;
        *height = frame.rows;
      } else if (frame.cols != *width || frame.rows != *height) {
        return Status::Error("--video: " + video + ": frame " + std::to_string(scores->size()) +
                             " changes size");
      }
      scores->push_back(ScoreFrame(frame, static_cast<int>(scores->size())));
      progress.Advance();
    }
    progress.Finish();
  } catch (const cv::Exception& e) {
    return Status::Error("--video: " + video + ": " + e.what());
  }
  if (scores->empty()) return Status::Error("--video: " + video + ": no frame could be decoded");
  return Status::Ok();
}

Status WriteVideoFrames(const std::string& video, const std::vector<int>& frame_numbers,
                        const std::string& dir, std::vector<std::string>* names) {
  names->clear();
  SFT_RETURN_IF_ERROR(MakeDirectories(dir));
  try {
    cv::VideoCapture capture;
    if (!OpenVideo(video, &capture)) return Status::Error("--video: " + video + ": cannot open");
    cv::Mat frame;
    size_t next = 0;
    for (int index = 0; next < frame_numbers.size() && capture.read(frame); ++index) {
      if (index != frame_numbers[next]) continue;
      const std::string name = VideoFrameName(index);
      if (!cv::imwrite(JoinPath(dir, name), frame)) {
        return Status::Error(JoinPath(dir, name) + ": cannot write");
      }
      names->push_back(name);
      ++next;
    }
    if (next != frame_numbers.size()) {
      return Status::Error("--video: " + video + ": decoded fewer frames on the second pass");
    }
  } catch (const cv::Exception& e) {
    return Status::Error("--video: " + video + ": " + e.what());
  }
  return Status::Ok();
}

}  // namespace sft
