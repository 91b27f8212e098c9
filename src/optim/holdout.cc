#include "src/optim/holdout.h"

#include <algorithm>

#include "src/io/scene_setup.h"

namespace sft {

bool ValidHoldout(int holdout) { return holdout == 0 || holdout >= 2; }

Status ChooseHeldOutViews(int holdout, const std::vector<int>& selection, int dataset_views,
                          std::vector<int>* held_out) {
  held_out->clear();
  if (!ValidHoldout(holdout)) {
    return Status::Error("--holdout: " + std::to_string(holdout) +
                         " is not 0 (off) or an integer >= 2");
  }
  if (holdout == 0) return Status::Ok();
  std::vector<int> selected;
  SFT_RETURN_IF_ERROR(SelectViews(selection, dataset_views, &selected));
  for (size_t i = 0; i < selected.size(); i += holdout) held_out->push_back(selected[i]);
  std::sort(held_out->begin(), held_out->end());
  held_out->erase(std::unique(held_out->begin(), held_out->end()), held_out->end());
  bool any_fitted = false;
  for (int v : selected) {
    any_fitted = any_fitted || !std::binary_search(held_out->begin(), held_out->end(), v);
  }
  if (!any_fitted) {
    return Status::Error("--holdout " + std::to_string(holdout) + ": holds out every one of the " +
                         std::to_string(selected.size()) + " selected views, leaving none to fit");
  }
  return Status::Ok();
}

Status ExcludeHeldOutViews(const std::vector<int>& held_out, int dataset_views,
                           std::vector<StageOptions>* stages) {
  if (held_out.empty()) return Status::Ok();
  for (StageOptions& stage : *stages) {
    std::vector<int> views;
    SFT_RETURN_IF_ERROR(
        SelectViews(stage.fit.views, dataset_views, &views).Prefixed("stage " + stage.name));
    std::vector<int> fitted;
    for (int v : views) {
      if (std::find(held_out.begin(), held_out.end(), v) == held_out.end()) fitted.push_back(v);
    }
    if (fitted.empty()) {
      return Status::Error("stage " + stage.name +
                           ": views: every view it names is held out (--holdout); give it "
                           "other views or a different --holdout");
    }
    stage.fit.views = fitted;
  }
  return Status::Ok();
}

Status ApplyHoldout(int holdout, const std::vector<int>& selection, int dataset_views,
                    std::vector<StageOptions>* stages, std::vector<int>* held_out) {
  SFT_RETURN_IF_ERROR(ChooseHeldOutViews(holdout, selection, dataset_views, held_out));
  return ExcludeHeldOutViews(*held_out, dataset_views, stages);
}

}  // namespace sft
