// Counter-based random numbers. Every sample is a pure function of (seed, view, pixel, sample,
// dimension), so an image is bit-for-bit identical for any thread count or scheduling, and a
// derivative pass can replay exactly the paths of the forward pass (DESIGN.md §2.3).
#ifndef SFT_CORE_RNG_H_
#define SFT_CORE_RNG_H_

#include <cstdint>

namespace sft {

// SplitMix64 finalizer: a bijective 64-bit mix with good avalanche (Steele et al. 2014).
inline uint64_t Mix64(uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

// A stream of uniform numbers in [0, 1) for one (seed, view, pixel, sample) key. Next1D() draws
// the next dimension; the stream is stateless apart from its dimension counter.
class Sampler {
 public:
  Sampler(uint64_t seed, uint64_t view, uint64_t pixel, uint64_t sample)
      : key_(Mix64(Mix64(Mix64(seed) ^ view) ^ pixel) ^ Mix64(sample + 0x5851F42D4C957F2Dull)) {}

  double Next1D() {
    const uint64_t bits = Mix64(key_ + 0xD1B54A32D192ED03ull * (++dimension_));
    return static_cast<double>(bits >> 11) * 0x1.0p-53;  // 53 random mantissa bits: < 1 always.
  }
  uint32_t dimension() const { return dimension_; }

 private:
  uint64_t key_;
  uint32_t dimension_ = 0;
};

}  // namespace sft

#endif  // SFT_CORE_RNG_H_
