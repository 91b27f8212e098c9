// Held-out views (`sft reconstruct --holdout K`, config key "holdout"; docs/reconstruct.md,
// "Held-out views"): every K-th of the run's selected views (the flat "views" list, else every
// dataset view), at positions 0, K, 2K, … of that list, is kept out of the fit — no stage fits
// it and a carved start ignores its mask — so that `sft eval --held-out` can score the
// reconstruction on photographs it never saw. state.json records the set ("held_out_views") and
// a resumed run keeps it.
#ifndef SFT_OPTIM_HOLDOUT_H_
#define SFT_OPTIM_HOLDOUT_H_

#include <string>
#include <vector>

#include "src/core/status.h"
#include "src/optim/schedule.h"

namespace sft {

// Whether `holdout` is a valid K: 0 (off) or at least 2 (K = 1 would hold out every view).
bool ValidHoldout(int holdout);

// The views held out by `holdout` (0 = none) among `selection` (dataset view indices; empty = all
// `dataset_views` views). Errors (one line, naming --holdout): an invalid K, or a K that leaves no
// view to fit.
Status ChooseHeldOutViews(int holdout, const std::vector<int>& selection, int dataset_views,
                          std::vector<int>* held_out);

// Removes the held-out views from every stage's `views` (an empty list, all views, becomes the
// explicit list of the others). A stage left without views is an error naming it.
Status ExcludeHeldOutViews(const std::vector<int>& held_out, int dataset_views,
                           std::vector<StageOptions>* stages);

// ChooseHeldOutViews, then ExcludeHeldOutViews from `stages`.
Status ApplyHoldout(int holdout, const std::vector<int>& selection, int dataset_views,
                    std::vector<StageOptions>* stages, std::vector<int>* held_out);

}  // namespace sft

#endif  // SFT_OPTIM_HOLDOUT_H_
