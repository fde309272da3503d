#!/usr/bin/env bash
# dieharder on the GPU streams of both generators of shaders/common/rng.glsl (docs/rng.md).
#
# Usage: scripts/dieharder.sh [paper|pcg ...]        (default: both)
# Environment:
#   BENCH    the benchmark binary (default build/glslppm-bench)
#   TESTS    "all" for dieharder -a (default); "subset": every test of -a, with the same
#            ntuples, except rgb_lagged_sum beyond lag 8 (that test alone takes over half of
#            -a's time here); or a list of test numbers, "N" or "N:FIRST-LAST" for ntuples,
#            e.g. "0 15 200:1-12"
#   THREADS  threads per pass (default 262144: a 512x512 image)
#   DRAWS    numbers per thread per pass (default 16)
#   FORMAT   u24 (default: the 24 bits a float in [0,1) carries, packed), u16 (top 16
#            bits only) or u32 (floor(x * 2^32): low bits always 0, unfair to both)
#   OUT      where logs go (default out/dieharder)
# The stream interleaves threads as a renderer uses them: number k of threads 0..T-1, then
# number k+1; the paper's states carry over between passes, PCG gets a seed per pass. It is
# piped, never rewound (dieharder re-reads a file from the start when it runs out).
set -euo pipefail
cd "$(dirname "$0")/.."

BENCH=${BENCH:-build/glslppm-bench}
TESTS=${TESTS:-all}
THREADS=${THREADS:-262144}
DRAWS=${DRAWS:-16}
FORMAT=${FORMAT:-u24}
OUT=${OUT:-out/dieharder}
generators=("$@")
[ ${#generators[@]} -eq 0 ] && generators=(paper pcg)

if ! command -v dieharder >/dev/null; then
    sudo=; [ "$(id -u)" -eq 0 ] || sudo=sudo
    $sudo apt-get install -y dieharder
fi
if ! "$BENCH" rng --generator pcg --threads 64 --per-thread 1 >/dev/null; then
    echo "dieharder.sh: $BENCH cannot run 'rng' (build glslppm-bench first)" >&2
    exit 1
fi
mkdir -p "$OUT"

stream() {  # the endless stream of generator $1, seed $2
    "$BENCH" rng --generator "$1" --threads "$THREADS" --per-thread "$DRAWS" --passes 0 \
        --seed "$2" --format "$FORMAT" --out - 2>/dev/null
}

for gen in "${generators[@]}"; do
    log="$OUT/$gen-$FORMAT.log"
    : >"$log"
    echo "# $(date -u +%Y-%m-%dT%H:%M:%SZ) generator=$gen threads=$THREADS draws=$DRAWS" \
         "format=$FORMAT tests=$TESTS" >>"$log"
    start=$(date +%s)
    if [ "$TESTS" = all ]; then
        # set +o pipefail: the stream ends on SIGPIPE/EPIPE when dieharder is done.
        (set +o pipefail; stream "$gen" 1 | dieharder -g 200 -a >>"$log" 2>&1)
    else
        list=$TESTS
        [ "$list" = subset ] && list="0 1 2 3 4 5 6 7 8 9 10 11 12 13 15 16 17 100 101 102
            200:1-12 201:2-5 202:2-5 203:0-8 204 205 206 207 208 209"
        for entry in $list; do
            t=${entry%%:*}
            ntuples=("")
            if [ "$entry" != "$t" ]; then
                range=${entry#*:}
                ntuples=($(seq "${range%-*}" "${range#*-}"))
            fi
            for n in "${ntuples[@]}"; do
                (set +o pipefail; stream "$gen" $((t + 1)) |
                    dieharder -g 200 -d "$t" ${n:+-n "$n"} >>"$log" 2>&1)
            done
        done
    fi
    seconds=$(( $(date +%s) - start ))
    passed=$(grep -c '|  PASSED' "$log" || true)
    weak=$(grep -c '|   WEAK' "$log" || true)
    failed=$(grep -c '|  FAILED' "$log" || true)
    echo "$gen ($FORMAT): PASSED $passed, WEAK $weak, FAILED $failed in ${seconds}s; log $log"
    grep -E '\|  FAILED|\|   WEAK' "$log" | sed 's/^/    /' || true
done
