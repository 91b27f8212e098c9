#include "src/optim/pyramid.h"

#include <glog/logging.h>

#include <algorithm>

namespace sft {
namespace {

// Calls f(fine_x, fine_y) for the children of coarse pixel (x, y) inside a fine_w × fine_h level
// and returns their count.
template <typename F>
int ForChildren(int x, int y, int fine_w, int fine_h, F f) {
  int n = 0;
  for (int dy = 0; dy < 2; ++dy) {
    for (int dx = 0; dx < 2; ++dx) {
      const int fx = 2 * x + dx, fy = 2 * y + dy;
      if (fx < fine_w && fy < fine_h) {
        f(fx, fy);
        ++n;
      }
    }
  }
  return n;
}

int ChildCount(int x, int y, int fine_w, int fine_h) {
  return ForChildren(x, y, fine_w, fine_h, [](int, int) {});
}

}  // namespace

Image DownsampleMean(const Image& fine) {
  Image coarse(CoarserSize(fine.width), CoarserSize(fine.height), fine.channels);
  for (int y = 0; y < coarse.height; ++y) {
    for (int x = 0; x < coarse.width; ++x) {
      for (int c = 0; c < fine.channels; ++c) {
        double sum = 0.0;
        const int n = ForChildren(x, y, fine.width, fine.height,
                                  [&](int fx, int fy) { sum += fine.at(fx, fy, c); });
        coarse.at(x, y, c) = static_cast<float>(sum / n);
      }
    }
  }
  return coarse;
}

std::vector<Image> BuildPyramid(const Image& image, int levels) {
  CHECK_GE(levels, 1);
  std::vector<Image> pyramid = {image};
  while (static_cast<int>(pyramid.size()) < levels &&
         (pyramid.back().width > 1 || pyramid.back().height > 1)) {
    pyramid.push_back(DownsampleMean(pyramid.back()));
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

LevelRows DownsampleRows(const LevelRows& fine) {
  LevelRows coarse;
  coarse.width = CoarserSize(fine.width);
  coarse.height = CoarserSize(fine.height);
  coarse.offsets.assign(static_cast<size_t>(coarse.width) * coarse.height + 1, 0);
  coarse.entries.reserve(fine.entries.size());
  std::vector<RowEntry> gathered;
  for (int y = 0; y < coarse.height; ++y) {
    for (int x = 0; x < coarse.width; ++x) {
      gathered.clear();
      const int n = ForChildren(x, y, fine.width, fine.height, [&](int fx, int fy) {
        const size_t p = static_cast<size_t>(fy) * fine.width + fx;
        gathered.insert(gathered.end(), fine.entries.begin() + fine.offsets[p],
                        fine.entries.begin() + fine.offsets[p + 1]);
      });
      std::sort(gathered.begin(), gathered.end(),
                [](const RowEntry& a, const RowEntry& b) { return a.param < b.param; });
      const double w = 1.0 / n;
      for (size_t i = 0; i < gathered.size();) {
        RowEntry merged = {gathered[i].param, {0.0, 0.0, 0.0}};
        for (; i < gathered.size() && gathered[i].param == merged.param; ++i) {
          for (int c = 0; c < 3; ++c) merged.d[c] += w * gathered[i].d[c];
        }
        coarse.entries.push_back(merged);
      }
      coarse.offsets[static_cast<size_t>(y) * coarse.width + x + 1] = coarse.entries.size();
    }
  }
  return coarse;
}

Image DownsampleMeanAdjoint(const Image& coarse, int fine_width, int fine_height) {
  CHECK_EQ(coarse.width, CoarserSize(fine_width));
  CHECK_EQ(coarse.height, CoarserSize(fine_height));
  Image fine(fine_width, fine_height, coarse.channels);
  for (int y = 0; y < coarse.height; ++y) {
    for (int x = 0; x < coarse.width; ++x) {
      const int n = ChildCount(x, y, fine_width, fine_height);
      for (int c = 0; c < coarse.channels; ++c) {
        const float share = coarse.at(x, y, c) / n;
        ForChildren(x, y, fine_width, fine_height,
                    [&](int fx, int fy) { fine.at(fx, fy, c) = share; });
      }
    }
  }
  return fine;
}

std::vector<std::vector<uint8_t>> MaskPyramid(const std::vector<uint8_t>& mask, int width,
                                              int height, int levels) {
  std::vector<std::vector<uint8_t>> pyramid = {mask};
  int w = width, h = height;
  while (static_cast<int>(pyramid.size()) < levels && (w > 1 || h > 1)) {
    const int cw = CoarserSize(w), ch = CoarserSize(h);
    std::vector<uint8_t> coarse(static_cast<size_t>(cw) * ch, 0);
    const std::vector<uint8_t>& fine = pyramid.back();
    for (int y = 0; y < ch; ++y) {
      for (int x = 0; x < cw; ++x) {
        ForChildren(x, y, w, h, [&](int fx, int fy) {
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
