#!/usr/bin/env bash
# Installs everything, builds, and runs the built-in example: a reconstruction. It synthesizes a
# dataset of the bundled Stanford bunny (16 views, camera flash), displaces the true mesh by a
# smooth random field (1% of the object's size) as the starting mesh, refines geometry and
# albedo with sft reconstruct (material by Levenberg–Marquardt over path-traced Jacobians, geometry
# by Adam on the large-steps parameterisation, alternating), and prints how
# far the start and the result are from the truth. Outputs under out/example/.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
bash scripts/build.sh
out=out/example
mkdir -p "$out"
rm -rf "$out/reconstruction"
./build/sft synth --quiet --mesh data/meshes/bunny_watertight_5k.obj --up-axis y \
  --material '{"albedo": [0.7, 0.5, 0.3], "roughness": 0.5, "specular": 0.0}' \
  --cameras 8 --zooms 1,2 --res 96 --spp 64 --bounces 1 --seed 1 \
  --out "$out/dataset" --overwrite
./build/sft perturb --mesh "$out/dataset/gt/mesh.ply" --out "$out/start.ply" \
  --amplitude 0.01 --seed 7
./build/sft reconstruct --dataset "$out/dataset" --init "$out/start.ply" \
  --material '{"albedo": [0.5, 0.5, 0.5], "roughness": 0.5, "resolution": 1}' \
  --config data/example/reconstruct.json --reference "$out/dataset/gt/mesh.ply" \
  --out "$out/reconstruction"
echo "== start mesh against the truth (F1 at 0.5% of the size, Chamfer) =="
./build/sft eval --reference "$out/dataset/gt/mesh.ply" --mesh "$out/start.ply" \
  --tolerance 0.005 --samples 200000 | grep -E '"(f1|chamfer)"'
echo "== reconstructed mesh against the truth =="
./build/sft eval --reference "$out/dataset/gt/mesh.ply" --mesh "$out/reconstruction/mesh.ply" \
  --tolerance 0.005 --samples 200000 | grep -E '"(f1|chamfer)"'
echo "== re-renders of the reconstruction against the images and the true albedo (PSNR dB and SSIM of the sRGB display images; linear PSNR) =="
./build/sft eval --dataset "$out/dataset" --reconstruction "$out/reconstruction" --spp 32 \
  --bounces 1 --json "$out/eval.json" > /dev/null
grep -E '^ "(full|albedo|roughness)"|^  "(psnr_srgb|ssim_srgb|psnr_linear)"' "$out/eval.json"
echo "example: report in $out/reconstruction/report.html (its 3D view needs a browser with WebGL)"
echo "example: asset in $out/reconstruction/export/ (model.glb, model.obj + model.mtl + PNGs; docs/export.md)"
