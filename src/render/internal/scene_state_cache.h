// Internal to src/render: the last build of a structure derived from one mesh state, shared by
// every view of a pass and both passes of an evaluation.
#ifndef SFT_RENDER_INTERNAL_SCENE_STATE_CACHE_H_
#define SFT_RENDER_INTERNAL_SCENE_STATE_CACHE_H_

#include <cstdint>
#include <memory>
#include <mutex>

#include "src/render/scene.h"

namespace sft {
namespace render_internal {

// T(scene) for `scene`'s current state: built on first use, then returned while
// scene.state_id() is unchanged (one entry per T; a new state replaces it). Thread-safe; two
// threads asking for a new state at once may both build it, and the later build is kept.
template <typename T>
std::shared_ptr<const T> LastBuildFor(const RenderScene& scene) {
  static std::mutex mutex;
  static uint64_t cached_state = 0;
  static std::shared_ptr<const T> cached;
  {
    std::lock_guard<std::mutex> lock(mutex);
    if (cached != nullptr && cached_state == scene.state_id()) return cached;
  }
  auto built = std::make_shared<const T>(scene);
  std::lock_guard<std::mutex> lock(mutex);
  cached_state = scene.state_id();
  cached = built;
  return built;
}

}  // namespace render_internal
}  // namespace sft

#endif  // SFT_RENDER_INTERNAL_SCENE_STATE_CACHE_H_
