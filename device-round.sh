#!/usr/bin/env bash
# One device call: passes/s before (session start, 58a8dc4) vs after on the old scenes, the
# glossy scene, the glossy-threshold trade, and the viewport's restart times.
set -uo pipefail
OUT=${OUT:-$PWD/out}
mkdir -p "$OUT"
nvidia-smi --query-gpu=name --format=csv,noheader > "$OUT/gpu.txt" 2>&1
bash scripts/device-compare.sh 3 > "$OUT/compare.txt" 2>&1
for d in sampled photons; do
  timeout 120 .device/run glslppm-bench passes --scene cornell-glossy --width 512 --height 512 --photons 262144 --passes 400 --warmup 20 --direct $d --json > "$OUT/glossy_$d.json" 2>&1
done
timeout 100 .device/run glslppm-bench restart --scene million --width 1920 --height 1080 --photons 65536 --moves 20 --json > "$OUT/restart_million.json" 2>&1
timeout 240 .device/run glslppm-bench converge --scene cornell-glossy --size 256 --passes 256 --photons 262144 --glossy-threshold 0,0.2,0.35,0.5,0.75,1 --reference-passes 2048 --reference-photons 1048576 --json > "$OUT/converge_glossy_threshold.json" 2>"$OUT/converge_err.txt"
ls -la "$OUT"
