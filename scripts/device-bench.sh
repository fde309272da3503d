#!/usr/bin/env bash
# The benchmark runs for the GPU machine (docs/performance.md), one mode per call:
#
#   scripts/device-bench.sh rays|passes|converge|scaling|instances|all
#
# Run from the repository root of a copy whose binaries are bundled under .device/ (the
# lead's `device` tool: `.device/run glslppm-bench ...`); elsewhere set BENCH, e.g.
# BENCH=build/glslppm-bench OUT=/tmp/bench scripts/device-bench.sh rays. Each run writes
# one JSON object per file under $OUT/<mode>/ (passes and scaling: one per line, .jsonl),
# read by scripts/plot_performance.py. Estimated times on one H200 (from its 1,000 passes/s
# at 512^2 with 262k photons, docs/performance.md): rays 1-2 min, passes 1 min, scaling
# 2-3 min, converge 5-6 min; `all` runs the four in turn (about 10 min: over the device
# tool's per-call limit, so call the modes one by one there).
set -uo pipefail
mode=${1:-}
case "$mode" in rays|passes|converge|scaling|instances|all) ;; *)
  echo "usage: scripts/device-bench.sh rays|passes|converge|scaling|instances|all" >&2; exit 2 ;;
esac
BENCH=${BENCH:-.device/run glslppm-bench}
OUT=${OUT:-$PWD/out/device-bench}
export GLSLPPM_SHADER_DIR=${GLSLPPM_SHADER_DIR:-$PWD/shaders}
failures=0
child=
trap '[ -n "$child" ] && kill "$child" 2>/dev/null; exit 143' TERM INT

# bench FILE TIMEOUT ARGS...: one run; its JSON appended to FILE, its stderr to FILE.err.
bench() {
  local file=$1 limit=$2; shift 2
  mkdir -p "$(dirname "$file")"
  local start=$SECONDS
  # In the background and waited for, so that the trap below can stop it when this script is
  # stopped (timeout passes the signal on to the benchmark).
  timeout "$limit" $BENCH "$@" --json >> "$file" 2>> "$file.err" &
  child=$!
  if ! wait "$child"; then
    echo "FAILED ($((SECONDS - start)) s): glslppm-bench $*" | tee -a "$OUT/failures.txt" >&2
    failures=$((failures + 1))
  else
    echo "$((SECONDS - start)) s: glslppm-bench $*"
  fi
}

describe() {
  mkdir -p "$OUT"
  { date -u +%FT%TZ; nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv 2>&1;
    nproc; git rev-parse HEAD 2>/dev/null; } > "$OUT/machine.txt"
}

run_rays() {
  # 4M rays per batch, 8 batches per kind: dispatch overhead is far below 1% at 1e9 rays/s.
  bench "$OUT/rays/rays.json" 420 rays --rays 4M --batches 8 \
    --scenes cornell,million:100k,million:1M --leaf 1,2,4,8
  bench "$OUT/rays/rays_caustic.json" 120 rays --rays 4M --batches 8 --scenes caustic --leaf 4
}

run_passes() {
  local d=$OUT/passes
  for photons in 65536 262144 1048576 4194304; do
    bench "$d/cornell_512.jsonl" 120 passes --scene cornell --width 512 --height 512 \
      --photons $photons --passes 200
  done
  bench "$d/cornell_512_exact.jsonl" 120 passes --width 512 --height 512 --photons 262144 \
    --passes 200 --hash exact
  bench "$d/cornell_512_paper.jsonl" 120 passes --width 512 --height 512 --photons 262144 \
    --passes 200 --rng paper
  for scene in caustic million:1M; do
    bench "$d/scenes_512.jsonl" 180 passes --scene $scene --width 512 --height 512 \
      --photons 262144 --passes 200
  done
}

run_scaling() {
  local d=$OUT/scaling
  for n in 1k 10k 100k 1M 4M; do
    bench "$d/triangles.jsonl" 180 passes --scene million:$n --width 512 --height 512 \
      --photons 262144 --passes 100 --warmup 4
  done
  for size in 128 256 512 1024 2048; do
    bench "$d/resolution.jsonl" 120 passes --width $size --height $size --photons 262144 \
      --passes 100 --warmup 4
  done
  for photons in 65536 262144 1048576 4194304; do
    bench "$d/photons.jsonl" 120 passes --width 512 --height 512 --photons $photons \
      --passes 100 --warmup 4
  done
}

run_instances() {
  # docs/instancing.md: 10,000 instances of a 100k-triangle mesh (1 G instanced triangles)
  # against the mesh once, both paths; then the flattening rule's crossover (both paths at
  # 1M to 100M instanced triangles, where the flattened copy still fits).
  local d=$OUT/instances
  for mode in flattened two-level; do
    bench "$d/mesh_once.jsonl" 120 passes --scene instances:1x100k --instancing $mode \
      --width 1024 --height 1024 --photons 1048576 --passes 200
  done
  bench "$d/instances_10000.jsonl" 300 passes --scene instances:10000x100k \
    --width 1024 --height 1024 --photons 1048576 --passes 200
  for scene in instances:64x1k instances:256x4k instances:100x100k instances:1000x100k; do
    for mode in flattened two-level; do
      bench "$d/rule.jsonl" 180 passes --scene $scene --instancing $mode \
        --width 1024 --height 1024 --photons 1048576 --passes 100
    done
  done
}

run_converge() {
  local d=$OUT/converge refs=$OUT/converge/references
  # Cornell box, 512^2: a 100k-pass exact-hash reference (about 100 s), then 4,096 passes of
  # each setting, error measured at 1, 2, 4, ... passes, the slope fitted from 64 passes on
  # (past the variance-dominated start, towards the asymptote theory predicts).
  local c="--scene cornell --size 512 --passes 4096 --fit-from 64 --reference $refs/cornell_512.exr
           --reference-passes 100k --reference-photons 262144"
  bench "$d/cornell_alpha.json" 400 converge $c --photons 262144 --alpha 0.5,2/3,0.7,0.9
  bench "$d/cornell_photons.json" 300 converge $c --photons 65536,262144,1048576,4194304
  bench "$d/cornell_radius.json" 200 converge $c --photons 262144 --radius-scale 0.25,0.5,1,2,4
  bench "$d/cornell_hash_rng.json" 200 converge $c --photons 262144 --hash stochastic,exact \
    --rng paper,pcg
  # The caustic scene: stochastic against exact hashing in the same wall time.
  bench "$d/caustic_hash.json" 200 converge --scene caustic --size 512 --passes 4096 --fit-from 64 \
    --reference "$refs/caustic_512.exr" --reference-passes 50k --reference-photons 262144 \
    --photons 262144 --hash stochastic,exact
}

describe
case "$mode" in
  rays) run_rays ;;
  passes) run_passes ;;
  scaling) run_scaling ;;
  converge) run_converge ;;
  instances) run_instances ;;
  all) run_rays; run_passes; run_scaling; run_converge ;;
esac
echo "device-bench $mode: $failures failed runs; results under $OUT"
[ "$failures" -eq 0 ]
