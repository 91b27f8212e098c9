// Counter-based random numbers. Every sample is a pure function of (seed, view, pixel, sample,
// dimension), so an image is bit-for-bit identical for any thread count or scheduling, and a
// derivative pass can replay exactly the paths of the forward pass.
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

inline uint32_t ReverseBits32(uint32_t v) {
  v = ((v >> 1) & 0x55555555u) | ((v & 0x55555555u) << 1);
  v = ((v >> 2) & 0x33333333u) | ((v & 0x33333333u) << 2);
  v = ((v >> 4) & 0x0F0F0F0Fu) | ((v & 0x0F0F0F0Fu) << 4);
  v = ((v >> 8) & 0x00FF00FFu) | ((v & 0x00FF00FFu) << 8);
  return (v >> 16) | (v << 16);
}

// The second Sobol dimension's generator matrix (direction numbers v_k = v_{k−1} ^ (v_{k−1} >> 1),
// v_0 = 2^31; primitive polynomial x + 1), applied to the index over GF(2) one byte at a time:
// table[b][x] is the XOR of the direction numbers of the set bits of byte value x at byte b.
struct SobolDimension1Table {
  uint32_t table[4][256];
  SobolDimension1Table() {
    uint32_t v[32];
    v[0] = 0x80000000u;
    for (int k = 1; k < 32; ++k) v[k] = v[k - 1] ^ (v[k - 1] >> 1);
    for (int b = 0; b < 4; ++b) {
      for (uint32_t x = 0; x < 256; ++x) {
        uint32_t result = 0;
        for (int bit = 0; bit < 8; ++bit) {
          if (x & (1u << bit)) result ^= v[8 * b + bit];
        }
        table[b][x] = result;
      }
    }
  }
};

// The first two dimensions of the Sobol sequence as 32-bit fractions: dimension 0 is the van der
// Corput sequence (bit reversal), dimension 1 the sequence of SobolDimension1Table. Together they
// form a (0, 2)-sequence: every power-of-two prefix is stratified in every elementary interval.
inline void Sobol2D(uint32_t index, uint32_t* x, uint32_t* y) {
  static const SobolDimension1Table kTable;
  *x = ReverseBits32(index);
  *y = kTable.table[0][index & 0xFFu] ^ kTable.table[1][(index >> 8) & 0xFFu] ^
       kTable.table[2][(index >> 16) & 0xFFu] ^ kTable.table[3][index >> 24];
}

// A nested uniform (Owen) scramble of a 32-bit fraction by a hash (Laine & Karras 2011, with
// Burley's 2020 constants): keeps the stratification of (0, 2)-sequences, randomizes the rest.
inline uint32_t OwenScramble(uint32_t v, uint32_t seed) {
  v = ReverseBits32(v);
  v ^= v * 0x3D20ADEAu;
  v += seed;
  v *= (seed >> 16) | 1u;
  v ^= v * 0x05526C56u;
  v ^= v * 0x53A22864u;
  return ReverseBits32(v);
}

// The random numbers of one Monte Carlo sample: sample `sample` of pixel `pixel` of view `view`.
// Next2D() draws stratified pairs: each pair of dimensions uses its own Owen-scrambled Sobol
// (0, 2)-sequence over the pixel's sample index, with the index shuffled per pair ("padded"
// sampling, a nested-uniform-scrambled index), so the samples of one pixel are stratified in every
// 2D projection the renderer uses (sub-pixel position, light sample, BSDF direction). Next1D()
// draws an independent hashed value. Both are pure functions of (seed, view, pixel, sample,
// dimension counter).
class Sampler {
 public:
  Sampler() = default;
  Sampler(uint64_t seed, uint64_t view, uint64_t pixel, uint64_t sample)
      : pixel_key_(Mix64(Mix64(Mix64(seed) ^ view) ^ pixel)), sample_(sample) {}

  double Next1D() {
    const uint64_t bits =
        Mix64(pixel_key_ ^ Mix64(sample_ + 0x5851F42D4C957F2Dull * (++dimension_)));
    return static_cast<double>(bits >> 11) * 0x1.0p-53;  // 53 random mantissa bits: < 1 always.
  }

  // An independent stream for the same sample (same sample index, so its Next2D pairs are
  // stratified over the pixel's samples too), told apart by `key`; leaves this one untouched.
  Sampler Fork(uint64_t key) const {
    Sampler fork;
    fork.pixel_key_ =
        Mix64(pixel_key_ ^ Mix64(key + (static_cast<uint64_t>(pair_) << 32) + dimension_));
    fork.sample_ = sample_;
    return fork;
  }

  void Next2D(double* u1, double* u2) {
    const uint64_t hash = Mix64(pixel_key_ + 0xD1B54A32D192ED03ull * (++pair_));
    // Shuffle the index per pair by a nested uniform scramble of its bits (Burley 2020, §4): a
    // random permutation within every aligned power-of-two block, so the first 2^m samples of a
    // pixel still form a (0, m, 2)-net in every pair. Not an XOR shift: the Sobol points are
    // linear in the index over GF(2), so index ^ k would make every pair an XOR-shifted copy of
    // every other and tie, e.g., the light sample to the sub-pixel position (which biases each
    // pixel along edges by a fixed, seed-dependent amount that more samples do not remove).
    const uint32_t index =
        OwenScramble(static_cast<uint32_t>(sample_), static_cast<uint32_t>(Mix64(hash)));
    uint32_t x, y;
    Sobol2D(index, &x, &y);
    x = OwenScramble(x, static_cast<uint32_t>(hash >> 16));
    y = OwenScramble(y, static_cast<uint32_t>(hash >> 40) * 0x9E3779B9u + 1u);
    // Centre of the 2^-32 cell: never exactly 0 or 1.
    *u1 = (static_cast<double>(x) + 0.5) * 0x1.0p-32;
    *u2 = (static_cast<double>(y) + 0.5) * 0x1.0p-32;
  }

 private:
  uint64_t pixel_key_ = 0;
  uint64_t sample_ = 0;
  uint32_t dimension_ = 0;
  uint32_t pair_ = 0;
};

}  // namespace sft

#endif  // SFT_CORE_RNG_H_
