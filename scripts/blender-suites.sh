# Sourced by scripts/test-blender.sh and scripts/test-viewport.sh: what running a test suite
# in both Blenders (3.4 on the host, 4.3 in the Debian 13 chroot) against the installed
# add-on takes. The caller sets `name` (its name in messages), `user_dir` and `out` (folders
# under the repository), then calls these in order.

# Fails unless blender (Debian's 3.4) is installed and the Blender 4.3 chroot exists (it is
# created when missing).
require_blenders() {
  command -v blender >/dev/null || { echo "$name: blender (Debian's 3.4) is not installed" >&2; exit 1; }
  scripts/blender-chroot.sh create >/dev/null ||
    { echo "$name: the Blender 4.3 chroot could not be created" >&2; exit 1; }
}

# Installs the add-on the way users do (scripts/install-addon.sh) into a fresh $user_dir,
# with a fresh $out for the logs.
install_addon_for_suites() {
  rm -rf "$user_dir" "$out"
  mkdir -p "$out"
  if ! scripts/install-addon.sh --user-dir "$user_dir" >"$out/install.log" 2>&1; then
    cat "$out/install.log"
    echo "$name: installing the add-on failed" >&2
    exit 1
  fi
  grep -E "^installed" "$out/install.log"
}

status=0
summaries=()
suite_timeout=0  # seconds a suite may run; 0: no limit

# Runs one suite: $1 is a label (its log is $out/$1.log), the rest the command. Shows the
# result lines, keeps the RESULT line for print_summaries, and sets status 1 on a failure or
# a suite that did not finish.
run_suite() {
  local label=$1; shift
  local log=$out/$label.log
  if [ "$suite_timeout" -gt 0 ]; then
    timeout "$suite_timeout" "$@" >"$log" 2>&1
  else
    "$@" >"$log" 2>&1
  fi
  local rc=$?
  grep -E "^(PASS|FAIL|SKIP|RESULT|FAILED|BENCH)" "$log"
  # Each failure's traceback (the test's stderr, kept in the log, which the next run of the
  # suite replaces), so that a CI log says why.
  awk '/^FAIL / {show = 1; print "---- " $0; next}
       /^(PASS|FAIL|SKIP|RESULT|FAILED)/ {show = 0}
       show {print "    " $0}' "$log"
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

# "== $1 (N s) ==" and each suite's summary, then exits with the suites' status.
finish_suites() {
  echo "== $1 ($((SECONDS - started)) s) =="
  for summary in "${summaries[@]}"; do
    echo "${summary#RESULT }"
  done
  exit $status
}
