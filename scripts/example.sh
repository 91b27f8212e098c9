#!/usr/bin/env bash
# Installs everything, builds, and runs the built-in example: synthesize a dataset of the bundled
# Stanford bunny (16 views, point light, 2-segment global illumination), then re-render it with
# the ground-truth mesh and material and compare. Outputs under out/example/.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
bash scripts/build.sh
out=out/example
mkdir -p "$out"
./build/sft synth --mesh data/meshes/bunny_watertight_5k.obj --up-axis y \
  --material '{"albedo": [0.7, 0.5, 0.3], "roughness": 0.35, "specular": 0.3}' \
  --cameras 8 --zooms 1,2 --res 128 --spp 128 --bounces 2 --seed 1 \
  --out "$out/dataset" --overwrite
./build/sft render --dataset "$out/dataset" --mesh "$out/dataset/gt/mesh.ply" \
  --material "$out/dataset/gt/material.json" --spp 64 --bounces 2 --seed 2 \
  --out "$out/render"
echo "example: dataset in $out/dataset, re-render in $out/render/images"
