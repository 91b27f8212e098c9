#include "src/optim/pyramid.h"

#include <glog/logging.h>

#include <algorithm>

namespace sft {
namespace {

// The taps of coarse index x along one axis of a fine level of size n: fine indices
// first, ..., first + count − 1 with weights summing to 1 (PyramidFilter's border rule).
struct AxisTaps {
  int first = 0;
  int count = 0;
  double weight[3] = {0.0, 0.0, 0.0};
};

// Unnormalised weights of the binomial filter's taps 2x − 1, 2x, 2x + 1.
constexpr double kBinomialTaps[3] = {1.0, 2.0, 1.0};

AxisTaps Taps(int x, int n, PyramidFilter filter) {
  const bool box = filter == PyramidFilter::kBox;
  const int first = box ? 2 * x : 2 * x - 1;  // the first candidate tap.
  const int size = box ? 2 : 3;
  AxisTaps taps;
  double sum = 0.0;
  for (int k = 0; k < size; ++k) {
    const int f = first + k;
    if (f < 0 || f >= n) continue;  // the border rule: drop, then renormalise.
    if (taps.count == 0) taps.first = f;
    const double w = box ? 1.0 : kBinomialTaps[k];
    taps.weight[taps.count++] = w;
    sum += w;
  }
  for (int k = 0; k < taps.count; ++k) taps.weight[k] /= sum;
  return taps;
}

// Calls f(fine_x, fine_y, weight) for the children of coarse pixel (x, y) inside a
// fine_w × fine_h level; the weights sum to 1.
template <typename F>
void ForChildren(int x, int y, int fine_w, int fine_h, PyramidFilter filter, F f) {
  const AxisTaps tx = Taps(x, fine_w, filter), ty = Taps(y, fine_h, filter);
  for (int j = 0; j < ty.count; ++j) {
    for (int i = 0; i < tx.count; ++i) f(tx.first + i, ty.first + j, tx.weight[i] * ty.weight[j]);
  }
}

}  // namespace

bool PyramidFilterFromName(const std::string& name, PyramidFilter* filter) {
  if (name == "box") {
    *filter = PyramidFilter::kBox;
  } else if (name == "binomial") {
    *filter = PyramidFilter::kBinomial;
  } else {
    return false;
  }
  return true;
}

const char* PyramidFilterName(PyramidFilter filter) {
  return filter == PyramidFilter::kBinomial ? "binomial" : "box";
}

Image DownsampleMean(const Image& fine, PyramidFilter filter) {
  Image coarse(CoarserSize(fine.width), CoarserSize(fine.height), fine.channels);
  for (int y = 0; y < coarse.height; ++y) {
    for (int x = 0; x < coarse.width; ++x) {
      for (int c = 0; c < fine.channels; ++c) {
        double sum = 0.0;
        ForChildren(x, y, fine.width, fine.height, filter,
                    [&](int fx, int fy, double w) { sum += w * fine.at(fx, fy, c); });
        coarse.at(x, y, c) = static_cast<float>(sum);
      }
    }
  }
  return coarse;
}

std::vector<Image> BuildPyramid(const Image& image, int levels, PyramidFilter filter) {
  CHECK_GE(levels, 1);
  std::vector<Image> pyramid = {image};
  while (static_cast<int>(pyramid.size()) < levels &&
         (pyramid.back().width > 1 || pyramid.back().height > 1)) {
    pyramid.push_back(DownsampleMean(pyramid.back(), filter));
  }
  return pyramid;
}

LevelRows RowsFromRenderer(const JacobianRows& rows) {
  LevelRows out;
  out.width = rows.width;
  out.height = rows.height;
  out.offsets.assign(rows.offsets.begin(), rows.offsets.end());
  if (out.offsets.empty()) out.offsets.assign(static_cast<size_t>(rows.width) * rows.height + 1, 0);
  out.entries.resize(rows.entries.size());
  for (size_t i = 0; i < rows.entries.size(); ++i) {
    const JacobianEntry& e = rows.entries[i];
    out.entries[i] = {e.param, {e.d[0], e.d[1], e.d[2]}};
  }
  return out;
}

LevelRows DownsampleRows(const LevelRows& fine, PyramidFilter filter) {
  LevelRows coarse;
  coarse.width = CoarserSize(fine.width);
  coarse.height = CoarserSize(fine.height);
  coarse.offsets.assign(static_cast<size_t>(coarse.width) * coarse.height + 1, 0);
  coarse.entries.reserve(fine.entries.size());
  std::vector<RowEntry> gathered;  // the children's entries, each times its child's weight.
  for (int y = 0; y < coarse.height; ++y) {
    for (int x = 0; x < coarse.width; ++x) {
      gathered.clear();
      ForChildren(x, y, fine.width, fine.height, filter, [&](int fx, int fy, double w) {
        const size_t p = static_cast<size_t>(fy) * fine.width + fx;
        for (uint64_t i = fine.offsets[p]; i < fine.offsets[p + 1]; ++i) {
          const RowEntry& e = fine.entries[i];
          gathered.push_back({e.param, {w * e.d[0], w * e.d[1], w * e.d[2]}});
        }
      });
      std::stable_sort(gathered.begin(), gathered.end(),
                       [](const RowEntry& a, const RowEntry& b) { return a.param < b.param; });
      for (size_t i = 0; i < gathered.size();) {
        RowEntry merged = {gathered[i].param, {0.0, 0.0, 0.0}};
        for (; i < gathered.size() && gathered[i].param == merged.param; ++i) {
          for (int c = 0; c < 3; ++c) merged.d[c] += gathered[i].d[c];
        }
        coarse.entries.push_back(merged);
      }
      coarse.offsets[static_cast<size_t>(y) * coarse.width + x + 1] = coarse.entries.size();
    }
  }
  return coarse;
}

Image DownsampleMeanAdjoint(const Image& coarse, int fine_width, int fine_height,
                            PyramidFilter filter) {
  CHECK_EQ(coarse.width, CoarserSize(fine_width));
  CHECK_EQ(coarse.height, CoarserSize(fine_height));
  // Accumulated in double: with the binomial filter a fine pixel feeds up to 2 × 2 coarse ones.
  std::vector<double> sum(static_cast<size_t>(fine_width) * fine_height * coarse.channels, 0.0);
  for (int y = 0; y < coarse.height; ++y) {
    for (int x = 0; x < coarse.width; ++x) {
      ForChildren(x, y, fine_width, fine_height, filter, [&](int fx, int fy, double w) {
        const size_t p = (static_cast<size_t>(fy) * fine_width + fx) * coarse.channels;
        for (int c = 0; c < coarse.channels; ++c) sum[p + c] += w * coarse.at(x, y, c);
      });
    }
  }
  Image fine(fine_width, fine_height, coarse.channels);
  for (size_t i = 0; i < sum.size(); ++i) fine.data[i] = static_cast<float>(sum[i]);
  return fine;
}

std::vector<std::vector<uint8_t>> MaskPyramid(const std::vector<uint8_t>& mask, int width,
                                              int height, int levels, PyramidFilter filter) {
  std::vector<std::vector<uint8_t>> pyramid = {mask};
  int w = width, h = height;
  while (static_cast<int>(pyramid.size()) < levels && (w > 1 || h > 1)) {
    const int cw = CoarserSize(w), ch = CoarserSize(h);
    std::vector<uint8_t> coarse(static_cast<size_t>(cw) * ch, 0);
    const std::vector<uint8_t>& fine = pyramid.back();
    for (int y = 0; y < ch; ++y) {
      for (int x = 0; x < cw; ++x) {
        ForChildren(x, y, w, h, filter, [&](int fx, int fy, double) {
          coarse[static_cast<size_t>(y) * cw + x] |= fine[static_cast<size_t>(fy) * w + fx];
        });
      }
    }
    pyramid.push_back(std::move(coarse));
    w = cw;
    h = ch;
  }
  return pyramid;
}

}  // namespace sft
