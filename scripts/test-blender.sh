#!/usr/bin/env bash
# `make test-blender`: the Blender tests under Blender 3.4 (host) and Blender 4.3 (the
# Debian 13 chroot, created here when missing), each against the add-on installed the
# way users install it (scripts/install-addon.sh into a private user directory).
#
# Usage: scripts/test-blender.sh [-k TEXT]...   (extra arguments go to tests/blender/run.py)
# Prints "Blender X: N passed, M failed, K skipped" per Blender; exits 1 on any failure.
set -uo pipefail

repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$repo"
user_dir=build/blender-user
out=build/blender-tests
started=$SECONDS

command -v blender >/dev/null || { echo "test-blender: blender (Debian's 3.4) is not installed" >&2; exit 1; }
scripts/blender-chroot.sh create || { echo "test-blender: the Blender 4.3 chroot could not be created" >&2; exit 1; }

rm -rf "$user_dir" "$out"
mkdir -p "$out"
if ! scripts/install-addon.sh --user-dir "$user_dir" >"$out/install.log" 2>&1; then
  cat "$out/install.log"
  echo "test-blender: installing the add-on failed" >&2
  exit 1
fi
grep -E "^installed" "$out/install.log"

status=0
summaries=()

# Runs the suite in one Blender; $1 is a label, the rest the command prefix.
run_suite() {
  local label=$1; shift
  local log=$out/$label.log
  "$@" >"$log" 2>&1
  local rc=$?
  grep -E "^(PASS|FAIL|SKIP|RESULT|FAILED|BENCH)" "$log"
  local summary
  summary=$(grep -E "^RESULT" "$log" | tail -1)
  if [ -z "$summary" ]; then
    summary="RESULT $label: did not finish (exit $rc; log $log)"
    tail -30 "$log"
    status=1
  elif [ $rc -ne 0 ]; then
    status=1
  fi
  summaries+=("$summary")
}

run_suite blender-3.4 env BLENDER_USER_RESOURCES="$repo/$user_dir/3.4" \
  blender -b --factory-startup --python tests/blender/run.py -- \
  --module glslppm --out "$out/3.4" "$@"

run_suite blender-4.3 scripts/blender-chroot.sh run env \
  BLENDER_USER_RESOURCES="/src/$user_dir/4.3" \
  blender -b --factory-startup --python tests/blender/run.py -- \
  --module bl_ext.user_default.glslppm --out "/src/$out/4.3" "$@"

# The export benchmark (1,000,000 triangles, target < 2 s): a figure, not a pass/fail gate,
# since other work on the machine moves it.
blender -b --factory-startup --python tests/blender/bench_export.py -- --source addon 2>&1 |
  grep "^BENCH" | tee -a "$out/bench.log"
scripts/blender-chroot.sh run blender -b --factory-startup --python tests/blender/bench_export.py \
  -- --source addon 2>&1 | grep "^BENCH" | tee -a "$out/bench.log"

echo "== Blender tests ($((SECONDS - started)) s) =="
for summary in "${summaries[@]}"; do
  echo "${summary#RESULT }"
done
exit $status
