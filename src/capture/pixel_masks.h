// Object masks computed from a photograph's own pixels, for captures without masks or sparse
// points (`--masks threshold` and `--masks alpha` of the calibrated importers, docs/import.md):
//
// threshold: the object is brighter than the background (a black cloth, as in the Middlebury
//   sets). A pixel is object when its brightest colour channel, as stored (sRGB-encoded values
//   of PNG/JPEG scaled to [0, 1]; EXR values as they are), exceeds `threshold`; the result is
//   dilated by `dilate` pixels, then eroded by `erode` pixels (discs), which closes dark shadows
//   and gaps on the object and, with dilate > erode, leaves the mask conservatively larger. The
//   Middlebury sets' README gives this recipe with 0.19, 10 and 7, the defaults here. Then, unless
//   `fill_holes` is off, background regions that do not reach the image border are filled: dark
//   shading inside the silhouette would otherwise carve tunnels through the visual hull (a real
//   hole through the object, such as a handle, is lost with it).
// alpha: the image's alpha channel > half of full scale is object (the NeRF Blender scenes are
//   RGBA with a transparent background).
#ifndef SFT_CAPTURE_PIXEL_MASKS_H_
#define SFT_CAPTURE_PIXEL_MASKS_H_

#include <opencv2/core.hpp>
#include <string>

#include "src/core/status.h"

namespace sft {

struct ThresholdMaskOptions {
  double threshold = 0.19;  // brightest channel above this is object, [0, 1).
  int dilate = 10;          // dilation radius, pixels, [0, 1000].
  int erode = 7;            // erosion radius after the dilation, pixels, [0, 1000].
  bool fill_holes = true;   // fill background regions enclosed by the object.

  // Errors name the flags (--threshold, --dilate, --erode).
  bool Check(std::string* why) const;
};

// The threshold mask of `image` (as decoded by OpenCV: 1, 3 or 4 channels, BGR(A), 8U, 16U or
// 32F; alpha is not a colour): 8-bit, 0 or 255, the image's size.
cv::Mat ThresholdMask(const cv::Mat& image, const ThresholdMaskOptions& options);

// The alpha mask of `image` (4 channels, 8U, 16U or 32F with alpha in [0, 1]): 8-bit 0/255.
// Error naming `name` when the image has no alpha channel.
Status AlphaMask(const cv::Mat& image, const std::string& name, cv::Mat* mask);

}  // namespace sft

#endif  // SFT_CAPTURE_PIXEL_MASKS_H_
