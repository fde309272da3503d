#!/usr/bin/env bash
# Passes/s of two builds of glslppm-bench on the GPU machine, alternated so that drift hits
# both alike: .device/bin/glslppm-bench-before with .device/shaders-before (an earlier
# commit, bundled by hand) against .device/bin/glslppm-bench with shaders/, and this build's
# two direct-light modes. One JSON object per line in $OUT/compare/passes.jsonl, each tagged
# with "build" and "direct".
#
#   scripts/device-compare.sh [ROUNDS]      (default 3)
set -uo pipefail
rounds=${1:-3}
OUT=${OUT:-$PWD/out/device-compare}
mkdir -p "$OUT/compare"
log=$OUT/compare/passes.jsonl
: > "$log"
run() {  # run TAG DIRECT SHADERS PROGRAM ARGS...
  local tag=$1 direct=$2 shaders=$3 program=$4; shift 4
  local line
  line=$(GLSLPPM_SHADER_DIR=$shaders timeout 240 .device/run "$program" passes "$@" --json \
         2>>"$OUT/compare/errors.txt" | tr -d '\n')
  [ -n "$line" ] || { echo "FAILED: $tag $direct $*" >&2; return; }
  echo "{\"build\": \"$tag\", \"direct\": \"$direct\", \"args\": \"$*\", \"result\": $line}" >> "$log"
  echo "$tag $direct $*: $(echo "$line" | grep -o '"passes_per_second": *[0-9.e+]*')"
}
for scene in cornell million:1M; do
  for r in $(seq "$rounds"); do
    common=(--scene "$scene" --width 512 --height 512 --photons 262144 --passes 400 --warmup 20)
    run before photons "$PWD/.device/shaders-before" glslppm-bench-before "${common[@]}"
    run after photons "$PWD/shaders" glslppm-bench "${common[@]}" --direct photons
    run after sampled "$PWD/shaders" glslppm-bench "${common[@]}" --direct sampled
  done
done
