// Frame selection for `sft import video` (docs/import.md "Video"): N sharp, well-spread frames.
//
// Rule. Each decoded frame gets a sharpness, the variance of the Laplacian of its grayscale image
// (larger = sharper; motion blur and defocus lower it), and a thumbnail: the grayscale frame
// resized to 32×32 (area averaging), values in [0, 1]. The frame range is split into N segments of
// equal length; from each, its sharpest frame is the candidate. Candidates are taken in order and
// one is dropped as a near-duplicate when the mean absolute difference between its thumbnail and
// the last kept frame's is below `duplicate_threshold` (the camera did not move), so a video with
// pauses gives fewer than N frames. Fewer than N frames in the video: every non-duplicate frame.
#ifndef SFT_IO_VIDEO_FRAMES_H_
#define SFT_IO_VIDEO_FRAMES_H_

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "src/core/status.h"

namespace sft {

struct FrameSelectionOptions {
  int frames = 60;                     // frames wanted, [2, 10000].
  double duplicate_threshold = 0.004;  // mean |thumbnail difference| below which a frame is a
                                       // near-duplicate of the last kept one, [0, 1].

  bool Check(std::string* why) const;
};

// What frame selection needs from one decoded frame.
struct FrameScore {
  int index = 0;                 // frame number in the video, from 0.
  double sharpness = 0;          // variance of the Laplacian of the grayscale frame (8-bit scale).
  std::vector<float> thumbnail;  // 32×32 grayscale, [0, 1], row-major.
};

static constexpr int kThumbnailSize = 32;

// Scores one frame (8-bit BGR or grayscale).
FrameScore ScoreFrame(const cv::Mat& frame, int index);

// Indices into `scores` (not frame numbers) of the selected frames, in video order (rule above).
std::vector<int> SelectFrames(const std::vector<FrameScore>& scores,
                              const FrameSelectionOptions& options);

// Decodes `video` with OpenCV's VideoCapture and scores every frame; `width`/`height` receive the
// frame size. Errors name the file: cannot open, no frame decoded, frames of changing size.
Status ScoreVideoFrames(const std::string& video, std::vector<FrameScore>* scores, int* width,
                        int* height, bool progress);

// Decodes `video` again and writes the frames numbered `frame_numbers` (increasing) as lossless
// PNG files `dir`/frame_NNNNNN.png (NNNNNN = frame number); `names` receives the file names.
Status WriteVideoFrames(const std::string& video, const std::vector<int>& frame_numbers,
                        const std::string& dir, std::vector<std::string>* names);

// "frame_NNNNNN.png" for frame number `index`.
std::string VideoFrameName(int index);

}  // namespace sft

#endif  // SFT_IO_VIDEO_FRAMES_H_
