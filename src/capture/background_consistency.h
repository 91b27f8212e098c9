// Background consistency for the automatic masks (docs/import.md "Automatic masks"): a pixel
// whose colour agrees with what the other views see of the background behind it is background.
// The object stands in front of the background, so the other views see, at the background point
// behind an object pixel, the background itself; the object's colour matches it only by chance.
//
// For each view at a working resolution (2^-k of the image, the long side at most `max_side`),
// each pixel's ray is followed to two background hypotheses:
//   plane    the support plane (src/capture/support_plane.h), when one was found: the point X where
//            the ray meets it, projected into the other views that see X in front of the camera
//            and inside the image;
//   distant  the point at infinity along the ray (an environment far away, such as the probe a
//            capture is lit by): the ray's direction rotated into the other views.
// The per-channel median of the other views' colours there is the background the pixel would
// show; the pixel's distance is, over the hypotheses with at least `min_views` views, the smallest
// max_c |pixel_c − median_c| in display values (every view scaled by one common white, the
// dataset's median 99th luminance percentile, then the sRGB curve; [0, 1]). The median keeps the
// background's colour while fewer than half of the views see the object in front of X.
//
// Exact for a diffuse support under world-fixed lighting (its shadows lie where they lie in every
// view) and an environment at infinity. Parallax of a background at a finite distance (the walls
// of a room), specular supports, exposure changes between views and occlusion of X in most views
// make the background inconsistent, so a large distance does not prove the object: the masks take
// a small distance as background everywhere and a large one as object only near the seeds.
#ifndef SFT_CAPTURE_BACKGROUND_CONSISTENCY_H_
#define SFT_CAPTURE_BACKGROUND_CONSISTENCY_H_

#include <memory>
#include <string>
#include <vector>

#include "src/capture/support_plane.h"
#include "src/core/image.h"
#include "src/core/status.h"
#include "src/io/dataset.h"

namespace sft {

struct BackgroundConsistencyOptions {
  int max_side = 640;  // working resolution's longest side at most this, pixels, [16, 16384].
  int min_views = 4;   // fewest other views a hypothesis needs for a pixel, [1, 1000].
  int max_views = 48;  // other views compared at most (spread evenly over the dataset), [1, 1000].
  bool quiet = false;  // no progress line.

  bool Check(std::string* why) const;
};

// The working resolution's factor: the smallest k ≥ 0 with max(width, height) / 2^k ≤ max_side.
int BackgroundLog2Factor(int width, int height, int max_side);

// (*distances)[i]: view i's distance map (1 channel, at DownscaledCamera(camera, k) of the view's
// camera with k = BackgroundLog2Factor), NaN where no hypothesis has min_views views. `plane` is in
// the dataset's world frame; nullptr or not found = the distant hypothesis only. Errors name the
// unreadable image; a dataset of one view is an error (nothing to compare with).
Status BackgroundDistances(const Dataset& dataset, const SupportPlane* plane,
                           const BackgroundConsistencyOptions& options,
                           std::vector<Image>* distances);

// The same with visibility from earlier masks, one per view (any resolution, > 0.5 = object; an
// empty image = none): a sample that falls on another view's object is left out, because the
// object hides the background point from that view. This keeps the floor right beside an object,
// which the object hides from about half of the views, consistent.
Status BackgroundDistances(const Dataset& dataset, const SupportPlane* plane,
                           const std::vector<Image>* masks,
                           const BackgroundConsistencyOptions& options,
                           std::vector<Image>* distances);

struct BackgroundWorkView;

// The views at the working resolution, loaded once (each image is read twice: once for the
// common white, once for its display colours) and compared as often as the masks' passes ask.
class BackgroundViews {
 public:
  // Errors name the unreadable image; a dataset of one view is an error (nothing to compare with).
  static Status Load(const Dataset& dataset, const BackgroundConsistencyOptions& options,
                     std::unique_ptr<BackgroundViews>* out);
  ~BackgroundViews();

  // As BackgroundDistances above, with these views (`masks`: nullptr = no visibility).
  Status Distances(const SupportPlane* plane, const std::vector<Image>* masks,
                   std::vector<Image>* distances);

 private:
  BackgroundViews();
  BackgroundConsistencyOptions options_;
  std::vector<BackgroundWorkView> views_;
};

}  // namespace sft

#endif  // SFT_CAPTURE_BACKGROUND_CONSISTENCY_H_
