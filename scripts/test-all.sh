#!/usr/bin/env bash
# `make test` after the build: every suite in turn, each logged to build/test-logs/, then
# one summary of what ran (scripts/test_summary.py). A suite that fails does not stop the
# others; the exit status is 1 when any failed, when a suite did not run, or when a
# comparison against Cycles was skipped.
#
# Usage: scripts/test-all.sh [SUITE...]   (default: every suite, in the order below)
set -uo pipefail

repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$repo"
logs=build/test-logs
suites=("$@")
[ ${#suites[@]} -gt 0 ] || suites=(native python bench blender viewport user-path extension sanitize fuzz-replay)
mkdir -p "$logs"

# The Blender chroots (Debian 13 and sid, downloaded and unpacked: mostly network) are made
# in the background while the native and Python suites run; the suites that need one wait
# for it (scripts/blender-chroot.sh create takes a lock). CI starts on a fresh machine, where
# this saves most of their 5-10 minutes.
case " ${suites[*]} " in
  *" blender "*|*" viewport "*|*" user-path "*|*" extension "*)
    (for release in trixie sid minimal; do scripts/blender-chroot.sh "$release" create; done) \
      >"$logs/chroots.log" 2>&1 </dev/null &
    ;;
esac

status=0
for suite in "${suites[@]}"; do
  log=$logs/$suite.log
  echo "== $suite =="
  started=$SECONDS
  make --no-print-directory "test-$suite" 2>&1 | tee "$log"
  rc=${PIPESTATUS[0]}
  echo "EXIT $rc $((SECONDS - started))" >>"$log"
  [ "$rc" -eq 0 ] || status=1
done

/usr/bin/python3 scripts/test_summary.py "$logs" "${suites[@]}" || status=1
exit $status
