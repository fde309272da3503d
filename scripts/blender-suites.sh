# Sourced by scripts/test-blender.sh and scripts/test-viewport.sh: what running a test suite
# in every Blender of the matrix against the installed add-on takes. The caller sets `name`
# (its name in messages), `user_dir` and `out` (folders under the repository), then calls
# these in order.
#
# The matrix, one Blender environment a word "VERSION:WHERE" (host: the machine's Debian 12
# Blender; a Debian release: scripts/blender-chroot.sh's chroot of it). GLSLPPM_BLENDERS
# narrows it ("5.2" or "4.3 5.2") while iterating; `make test` runs all of them.
BLENDER_MATRIX=(3.4:host 4.3:trixie 5.2:sid)
blenders=()
for entry in "${BLENDER_MATRIX[@]}"; do
  if [ -z "${GLSLPPM_BLENDERS:-}" ] || [[ " $GLSLPPM_BLENDERS " == *" ${entry%%:*} "* ]]; then
    blenders+=("$entry")
  fi
done

# Fails unless each Blender of the matrix is there: blender (Debian's 3.4) installed, each
# chroot made (created here when missing; reused when its stamp says it is ready).
require_blenders() {
  [ ${#blenders[@]} -gt 0 ] || { echo "$name: GLSLPPM_BLENDERS='$GLSLPPM_BLENDERS' names no Blender of ${BLENDER_MATRIX[*]}" >&2; exit 1; }
  local entry
  for entry in "${blenders[@]}"; do
    local where=${entry#*:}
    if [ "$where" = host ]; then
      command -v blender >/dev/null || { echo "$name: blender (Debian's ${entry%%:*}) is not installed" >&2; exit 1; }
    else
      scripts/blender-chroot.sh "$where" create >/dev/null ||
        { echo "$name: the Blender ${entry%%:*} chroot ($where) could not be created" >&2; exit 1; }
    fi
  done
}

# Sets `prefix` to what runs a command in a Blender environment $1 ("VERSION:WHERE"):
# nothing on the host, scripts/blender-chroot.sh in a chroot (where paths under the
# repository are /src/...). An array of words, not a function, so that timeout(1) can run it.
blender_env_prefix() {
  local where=${1#*:}
  prefix=()
  [ "$where" = host ] || prefix=(scripts/blender-chroot.sh "$where" run)
}

# Runs "$@" in the Blender environment $1.
in_blender_env() {
  blender_env_prefix "$1"; shift
  "${prefix[@]}" "$@"
}

# The repository's root as a Blender environment $1 sees it.
repo_in() { [ "${1#*:}" = host ] && echo "$repo" || echo /src; }

# The add-on's module name in Blender VERSION $1: 3.x add-ons by name, 4.2+ extensions.
addon_module() { case "$1" in 3.*) echo glslppm ;; *) echo bl_ext.user_default.glslppm ;; esac; }

# Installs the add-on the way users do (scripts/install-addon.sh) into a fresh $user_dir,
# with a fresh $out for the logs.
install_addon_for_suites() {
  rm -rf "$user_dir" "$out"
  mkdir -p "$out"
  local only=() entry
  for entry in "${blenders[@]}"; do only+=(--only "${entry%%:*}"); done
  if ! scripts/install-addon.sh --user-dir "$user_dir" "${only[@]}" >"$out/install.log" 2>&1; then
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
