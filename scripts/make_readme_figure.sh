#!/usr/bin/env bash
# Makes docs/images/example_result.png, the README's picture, from the outputs of
# scripts/example.sh (run that first): one view of the example dataset as four panels — target,
# a 256-spp render of the reconstruction, |render − target| ×4, normals of the reconstructed mesh.
# Needs ImageMagick (apt-get install imagemagick) and the DejaVu fonts; the normal pass (an EXR
# with negative values, which ImageMagick's Q16 build clamps) is mapped to (n + 1)/2 by a small
# tinyexr program compiled into build/. Update the README's caption with the example's printout.
#
#   bash scripts/make_readme_figure.sh [VIEW]      (default view 10)
set -euo pipefail
cd "$(dirname "$0")/.."
view=$(printf '%03d' "${1:-10}")
example=out/example
[[ -d "$example/reconstruction" ]] || { echo "run scripts/example.sh first" >&2; exit 1; }
work=out/readme_figure
rm -rf "$work"
mkdir -p "$work" build/tools

tool=build/tools/normals_to_ppm
if [[ ! -x "$tool" ]]; then
  cat > build/tools/normals_to_ppm.cc <<'EOF'
// Normal pass EXR (RGB = normal × coverage, A = coverage) -> 8-bit PPM of (n + 1)/2 on black.
#include <tinyexr.h>
#include <cmath>
#include <cstdio>
int main(int argc, char** argv) {
  if (argc != 3) return 2;
  float* rgba = nullptr;
  int w = 0, h = 0;
  const char* err = nullptr;
  if (LoadEXR(&rgba, &w, &h, argv[1], &err) != 0) {
    std::fprintf(stderr, "%s: %s\n", argv[1], err ? err : "unreadable");
    return 1;
  }
  FILE* f = std::fopen(argv[2], "wb");
  if (f == nullptr) return 1;
  std::fprintf(f, "P6\n%d %d\n255\n", w, h);
  for (int i = 0; i < w * h; ++i) {
    const float a = rgba[4 * i + 3];
    for (int c = 0; c < 3; ++c) {
      const float n = a > 1e-6f ? rgba[4 * i + c] / a : 0.f;
      float v = a * 0.5f * (n + 1.f);
      v = v < 0.f ? 0.f : (v > 1.f ? 1.f : v);
      std::fputc(static_cast<int>(std::lround(v * 255.f)), f);
    }
  }
  std::fclose(f);
  return 0;
}
EOF
  g++ -O1 build/tools/normals_to_ppm.cc -o "$tool" -ltinyexr
fi

r="$example/reconstruction"
./build/sft render --dataset "$example/dataset" --mesh "$r/mesh.ply" --material "$r/material.json" \
  --lights "$r/lights.json" --views "$((10#$view))" --spp 256 --bounces 1 --quiet \
  --out "$work/color" > /dev/null
./build/sft render --dataset "$example/dataset" --mesh "$r/mesh.ply" --material "$r/material.json" \
  --views "$((10#$view))" --spp 64 --bounces 1 --pass normal --no-report --quiet \
  --out "$work/normal" > /dev/null
"$tool" "$work/normal/images/$view.exr" "$work/normal.ppm"

files="$work/color/report_files/view_${view}"
font=$(fc-list | grep -o '/[^:]*DejaVuSans.ttf' | head -n 1)
for panel in target render difference; do
  convert "${files}_${panel}.png" -resize 200% "$work/$panel.png"
done
convert "$work/normal.ppm" -resize 200% "$work/normal.png"
montage -background black -fill white -font "$font" -pointsize 14 \
  -label "target image (view $((10#$view)))" "$work/target.png" \
  -label "sft's render of the result" "$work/render.png" \
  -label "|render - target| x4" "$work/difference.png" \
  -label "normals of the result" "$work/normal.png" \
  -tile 4x -geometry +4+4 "$work/panels.png"
mkdir -p docs/images
convert "$work/panels.png" -strip -depth 8 -define png:compression-level=9 \
  docs/images/example_result.png
echo "wrote docs/images/example_result.png ($(stat -c %s docs/images/example_result.png) bytes)"
