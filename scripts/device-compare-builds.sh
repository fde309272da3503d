#!/usr/bin/env bash
# Passes/s of two builds of glslppm-bench on the GPU machine, alternated scene by scene so
# that drift hits both alike: .device/bin/glslppm-bench-before with .device/shaders-before
# (an earlier commit, bundled by hand) against .device/bin/glslppm-bench with shaders/, both
# at their default settings. One JSON object per line in $OUT/compare/builds.jsonl, tagged
# with "build", and a summary line per scene and size: after / before (median of rounds).
#
#   SCENES="cornell caustic million:1M cornell-glossy" SIZES="512x512 1920x1080" \
#     scripts/device-compare-builds.sh [ROUNDS]      (default 3)
set -uo pipefail
rounds=${1:-3}
scenes=${SCENES:-cornell caustic million:1M cornell-glossy}
sizes=${SIZES:-512x512 1920x1080}
OUT=${OUT:-$PWD/out/device-compare}
mkdir -p "$OUT/compare"
log=$OUT/compare/builds.jsonl
: > "$log"
run() {  # run TAG SHADERS PROGRAM ARGS...
  local tag=$1 shaders=$2 program=$3; shift 3
  local line
  line=$(GLSLPPM_SHADER_DIR=$shaders timeout 240 .device/run "$program" passes "$@" --json \
         2>>"$OUT/compare/errors.txt" | tr -d '\n')
  [ -n "$line" ] || { echo "FAILED: $tag $*" >&2; return; }
  echo "{\"build\": \"$tag\", \"args\": \"$*\", \"result\": $line}" >> "$log"
  echo "$tag $*: $(echo "$line" | grep -o '"passes_per_second": *[0-9.e+]*')"
}
for size in $sizes; do
  for scene in $scenes; do
    for r in $(seq "$rounds"); do
      common=(--scene "$scene" --width "${size%x*}" --height "${size#*x}" --photons 262144
              --passes "${PASSES:-300}" --warmup 20)
      run before "$PWD/.device/shaders-before" glslppm-bench-before "${common[@]}"
      run after "$PWD/shaders" glslppm-bench "${common[@]}"
    done
  done
done
python3 - "$log" <<'PY'
import json, statistics, sys
rows = [json.loads(line) for line in open(sys.argv[1])]
groups = {}
for row in rows:
    groups.setdefault(row["args"], {}).setdefault(row["build"], []).append(
        row["result"]["passes_per_second"])
for args, builds in groups.items():
    if "before" in builds and "after" in builds:
        before, after = statistics.median(builds["before"]), statistics.median(builds["after"])
        print(f"SUMMARY {args}: before {before:.2f} after {after:.2f} passes/s, "
              f"after/before {after / before:.4f}")
PY
