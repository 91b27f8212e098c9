// Internal to src/render: the floating-point mode of tracing threads.
#ifndef SFT_RENDER_INTERNAL_FP_MODE_H_
#define SFT_RENDER_INTERNAL_FP_MODE_H_

#include <pmmintrin.h>
#include <xmmintrin.h>

namespace sft {
namespace render_internal {

// Embree wants flush-to-zero / denormals-are-zero in every tracing thread. Set for the lifetime
// of this object (one parallel task) and restored after it, so that neither the caller's thread
// (which runs tasks of its own arena) nor TBB's workers keep a changed MXCSR.
class ScopedTracingFpMode {
 public:
  ScopedTracingFpMode() : saved_(_mm_getcsr()) {
    _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);
    _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
  }
  ~ScopedTracingFpMode() { _mm_setcsr(saved_); }
  ScopedTracingFpMode(const ScopedTracingFpMode&) = delete;
  ScopedTracingFpMode& operator=(const ScopedTracingFpMode&) = delete;

 private:
  unsigned int saved_;
};

}  // namespace render_internal
}  // namespace sft

#endif  // SFT_RENDER_INTERNAL_FP_MODE_H_
