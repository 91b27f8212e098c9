#!/usr/bin/env bash
# Installs every Debian 12 package sft needs to build, test and run. Idempotent: re-running it
# only re-checks the packages. Needs root (or sudo). Set SFT_SKIP_APT=1 to skip (e.g. when the
# packages are known to be present and the network is unavailable).
#
# Optional clients, for checks outside the default suite:
#   --with-blender   Blender 3.4 and NumPy (the Blender round trip of `sft export`, whose test
#                    skips without them; docs/export.md)
#   --with-chromium  headless Chromium (screenshots of report.html and its 3D view;
#                    scripts/check_report_viewer.sh)
set -euo pipefail

PACKAGES=(
  # toolchain
  build-essential cmake git pkg-config ca-certificates
  # numerics and solver
  libeigen3-dev libceres-dev libgoogle-glog-dev libgflags-dev libsuitesparse-dev
  # ray tracing and parallelism
  libembree-dev libtbb-dev
  # images (PNG via OpenCV, EXR via tinyexr; SSIM from opencv contrib's quality module)
  libopencv-dev libopencv-contrib-dev libtinyexr-dev
  # meshes
  libopenmesh-dev
  # nearest neighbours (sft eval)
  libnanoflann-dev
  # real captures: COLMAP's CLI (sft import video), volumes and surfaces (sft init)
  colmap libopenvdb-dev libcgal-dev
  # clang and its runtime (libFuzzer, sanitizers) for the fuzz targets
  clang libclang-rt-14-dev
  # CLI, JSON, zip archives (NumPy .npz camera files of sft import idr)
  libcli11-dev nlohmann-json3-dev libzip-dev
  # glTF 2.0 writer (sft export)
  libtinygltf-dev
  # MPI: `mpirun -np N sft reconstruct` spreads the views over ranks (CMake option SFT_MPI)
  libopenmpi-dev openmpi-bin
  # tests and benchmarks
  libgtest-dev libgmock-dev libbenchmark-dev
  # three.js (report.html's 3D view of the result, copied beside the report)
  libjs-three
)
for arg in "$@"; do
  case "$arg" in
    --with-blender) PACKAGES+=(blender python3-numpy) ;;
    --with-chromium) PACKAGES+=(chromium) ;;
    *) echo "setup: unknown option $arg (use --with-blender, --with-chromium)" >&2; exit 2 ;;
  esac
done

if [[ "${SFT_SKIP_APT:-0}" == "1" ]]; then
  echo "setup: SFT_SKIP_APT=1, not installing packages"
  exit 0
fi

SUDO=""
if [[ "$(id -u)" != "0" ]]; then SUDO="sudo"; fi

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [[ ${#missing[@]} -eq 0 ]]; then
  echo "setup: all ${#PACKAGES[@]} packages already installed"
  exit 0
fi

echo "setup: installing ${#missing[@]} packages: ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -q
$SUDO apt-get install -y -q --no-install-recommends "${missing[@]}"
echo "setup: done"
