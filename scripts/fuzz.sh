#!/usr/bin/env bash
# Builds the libFuzzer targets (fuzz/, clang + AddressSanitizer + UBSan) and runs each for a fixed
# time on its seed corpus (fuzz/seeds/ and files from data/). Any crash, sanitizer report, leak,
# timeout (> 10 s per input) or out-of-memory (> 2 GB) fails the run; the input is saved under
# BUILD_DIR/fuzz-artifacts/. A summary line per target gives the executions and executions/s.
#
#   bash scripts/fuzz.sh [--time SECONDS] [--no-build] [--build-dir DIR] [TARGET...]
#
# Defaults: 60 s per target, build dir build-fuzz, every target. The ctest entry FuzzLong (label
# "long", in a build with -DSFT_BUILD_FUZZERS=ON) runs it with --no-build --time 20.
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)
seconds=60
build=1
build_dir=build-fuzz
targets=()
while [[ $# -gt 0 ]]; do
  case "$1" in
    --time) seconds="$2"; shift 2 ;;
    --no-build) build=0; shift ;;
    --build-dir) build_dir="$2"; shift 2 ;;
    -h|--help) sed -n 2,11p "$0"; exit 0 ;;
    *) targets+=("${1%_fuzzer}_fuzzer"); shift ;;
  esac
done
all=(colmap_text_fuzzer colmap_binary_fuzzer point_cloud_ply_fuzzer mesh_obj_fuzzer
     mesh_ply_fuzzer mesh_off_fuzzer material_json_fuzzer mesh_colors_fuzzer scene_json_fuzzer
     exr_fuzzer png_fuzzer nerf_transforms_fuzzer middlebury_par_fuzzer npy_fuzzer
     npz_fuzzer)
if [[ ${#targets[@]} -eq 0 ]]; then targets=("${all[@]}"); fi
[[ "$build_dir" = /* ]] || build_dir="$root/$build_dir"

if [[ $build -eq 1 ]]; then
  if [[ ! -f "$build_dir/CMakeCache.txt" ]]; then
    cmake -S . -B "$build_dir" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER=clang++ \
      -DSFT_BUILD_FUZZERS=ON -DSFT_SANITIZE=address,undefined -DSFT_BUILD_TESTS=OFF \
      -DSFT_BUILD_BENCHMARKS=OFF
  fi
  cmake --build "$build_dir" -j "$(nproc)" --target "${targets[@]}"
fi

# Seeds per target: folders under fuzz/seeds/ and small files from data/.
seeds_for() {
  case "$1" in
    colmap_text_fuzzer) echo fuzz/seeds/colmap_text data/colmap/spot/sparse_txt/cameras.txt ;;
    colmap_binary_fuzzer) echo fuzz/seeds/colmap_binary data/colmap/spot/sparse_bin/cameras.bin ;;
    point_cloud_ply_fuzzer) echo fuzz/seeds/point_cloud_ply ;;
    mesh_obj_fuzzer) echo data/meshes/quad_z0_2x2_2f.obj data/meshes/cube_2x2x2_12f.obj \
                          data/meshes/icosphere_r1_320f.obj ;;
    mesh_ply_fuzzer) echo fuzz/seeds/mesh_ply ;;
    mesh_off_fuzzer) echo fuzz/seeds/mesh_off ;;
    material_json_fuzzer) echo fuzz/seeds/material_json ;;
    mesh_colors_fuzzer) echo fuzz/seeds/mesh_colors ;;
    scene_json_fuzzer) echo data/cycles/*/scene.json ;;
    exr_fuzzer) echo data/cycles/bunny_point_ggx_gi/gt/roughness/001.exr \
                     data/cycles/sphere_env_studio/gt/albedo/006.exr ;;
    nerf_transforms_fuzzer) echo fuzz/seeds/nerf_transforms ;;
    middlebury_par_fuzzer) echo fuzz/seeds/middlebury_par ;;
    # Binary seeds are generated (scripts/npz_fuzz_seeds.py), not checked in.
    npy_fuzzer) echo "$build_dir/fuzz-seeds/npy" ;;
    npz_fuzzer) echo "$build_dir/fuzz-seeds/npz" ;;
    png_fuzzer) echo data/cycles/sphere_env_studio/masks/006.png \
                     data/cycles/bunny_point_diffuse/masks/000.png ;;
    *) echo "unknown fuzz target $1" >&2; return 1 ;;
  esac
}

mkdir -p "$build_dir/fuzz-artifacts" "$build_dir/fuzz-logs"
python3 scripts/npz_fuzz_seeds.py "$build_dir/fuzz-seeds"
failed=0
for t in "${targets[@]}"; do
  bin="$build_dir/fuzz/$t"
  [[ -x "$bin" ]] || { echo "$t: not built ($bin)" >&2; failed=1; continue; }
  corpus="$build_dir/fuzz-corpus/$t"
  mkdir -p "$corpus"
  # Inputs that once failed (data/fuzz_regressions/<target without _fuzzer>_*) are seeds too.
  for s in $(seeds_for "$t") data/fuzz_regressions/"${t%_fuzzer}"_*; do
    [[ -e "$s" ]] || continue
    if [[ -d "$s" ]]; then cp -n "$s"/* "$corpus"/; else cp -n "$s" "$corpus"/; fi
  done
  # An empty working folder holding only the material fuzzer's referenced mesh-colors file, so
  # that relative paths inside fuzzed JSON resolve to nothing else.
  work=$(mktemp -d)
  cp fuzz/seeds/mesh_colors/albedo.meshcolors "$work"/
  # tinyexr 1.0.1 leaks on most corrupt EXR inputs (scripts/lsan.supp), and libFuzzer then runs a
  # full leak scan after each of them (~25 exec/s instead of thousands): no leak checking for the
  # EXR target; our EXR code owns tinyexr's buffers through RAII (src/io/image_io.cc, ExrHolder).
  extra=()
  # Its largest allowed allocation is 2 GiB (kMaxExrBytes in src/io/image_io.cc): 6 GB of RSS.
  if [[ "$t" == exr_fuzzer ]]; then extra=(-detect_leaks=0 -rss_limit_mb=6144); fi
  # The EXR target also runs in 10 s rounds on the same corpus: the tinyexr leak accumulates
  # (~6 GB after 25 s at 7,700 exec/s), and each round starts a fresh process.
  chunk=$seconds
  if [[ "$t" == exr_fuzzer && $chunk -gt 10 ]]; then chunk=10; fi
  log="$build_dir/fuzz-logs/$t.log"
  : >"$log"
  status=0
  left=$seconds
  while [[ $left -gt 0 && $status -eq 0 ]]; do
    this=$(( left < chunk ? left : chunk ))
    (cd "$work" && ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
       LSAN_OPTIONS="suppressions=$root/scripts/lsan.supp" \
       "$bin" -max_total_time="$this" -timeout=10 -rss_limit_mb=2048 -max_len=65536 \
       -print_final_stats=1 ${extra[@]+"${extra[@]}"} \
       -artifact_prefix="$build_dir/fuzz-artifacts/$t-" "$corpus") >>"$log" 2>&1 || status=$?
    left=$(( left - this ))
  done
  rm -rf "$work"
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | awk '{n += $1} END {print n}')
  rate=$(( ${execs:-0} / seconds ))
  cov=$(grep -o 'cov: [0-9]*' "$log" | tail -1 || true)
  if [[ $status -ne 0 ]]; then
    echo "$t: FAILED (exit $status) after ${execs:-?} executions; see $log" >&2
    grep -m3 -E 'ERROR|runtime error|SUMMARY' "$log" >&2 || true
    failed=1
  else
    echo "$t: ${seconds} s, ${execs} executions, ${rate} exec/s, ${cov}, no finding"
  fi
done
exit $failed
