#!/usr/bin/env bash
# `make test-viewport`: the rendered viewport and material preview tests
# (tests/blender/viewport_ui.py) in Blender's real UI on an Xvfb display, under Blender 3.4
# (host) and Blender 4.3 (the Debian 13 chroot), each against the add-on installed the way
# users install it. A Blender that cannot start its UI fails the suite.
#
# Usage: scripts/test-viewport.sh [-k TEXT]...   (extra arguments go to viewport_ui.py)
# Prints "Blender X (viewport): N passed, M failed, 0 skipped" per Blender; exits 1 on any
# failure.
set -uo pipefail

repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$repo"
user_dir=build/blender-user-viewport
out=build/viewport-tests
started=$SECONDS

command -v blender >/dev/null || { echo "test-viewport: blender (Debian's 3.4) is not installed" >&2; exit 1; }
command -v xvfb-run >/dev/null || { echo "test-viewport: xvfb-run is not installed (apt-get install xvfb xauth)" >&2; exit 1; }
scripts/blender-chroot.sh create >/dev/null || { echo "test-viewport: the Blender 4.3 chroot could not be created" >&2; exit 1; }

rm -rf "$user_dir" "$out"
mkdir -p "$out"
if ! scripts/install-addon.sh --user-dir "$user_dir" >"$out/install.log" 2>&1; then
  cat "$out/install.log"
  echo "test-viewport: installing the add-on failed" >&2
  exit 1
fi
grep -E "^installed" "$out/install.log"

# A saved startup file on the command line: Blender then shows no splash screen.
blender -b --factory-startup --python-expr \
  "import bpy; bpy.ops.wm.save_as_mainfile(filepath='$repo/$out/start.blend')" >/dev/null 2>&1
[ -f "$out/start.blend" ] || { echo "test-viewport: could not save the start file" >&2; exit 1; }

status=0
summaries=()
# The window: its 3D view fills it (viewport_ui.py maximizes the area).
# Xvfb writes its screen to FB/Xvfb_screen0, where the tests read what the display shows.
ui() { echo "-screen 0 1280x800x24 -fbdir $1"; }
window=(-p 0 0 640 480)
mkdir -p "$out/fb-3.4" "$out/fb-4.3"

run_suite() {
  local label=$1; shift
  local log=$out/$label.log
  timeout 900 "$@" >"$log" 2>&1
  local rc=$?
  grep -E "^(PASS|FAIL|SKIP|RESULT|FAILED)" "$log"
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

run_suite viewport-3.4 env BLENDER_USER_RESOURCES="$repo/$user_dir/3.4" \
  GLSLPPM_XVFB_FBDIR="$repo/$out/fb-3.4" \
  xvfb-run -a -s "$(ui "$repo/$out/fb-3.4")" blender --factory-startup "${window[@]}" "$out/start.blend" \
  --python tests/blender/viewport_ui.py -- --module glslppm --out "$out/3.4" "$@"

run_suite viewport-4.3 scripts/blender-chroot.sh run env \
  BLENDER_USER_RESOURCES="/src/$user_dir/4.3" GLSLPPM_XVFB_FBDIR="/src/$out/fb-4.3" \
  xvfb-run -a -s "$(ui "/src/$out/fb-4.3")" blender --factory-startup "${window[@]}" "/src/$out/start.blend" \
  --python tests/blender/viewport_ui.py -- --module bl_ext.user_default.glslppm \
  --out "/src/$out/4.3" "$@"

echo "== viewport tests ($((SECONDS - started)) s) =="
for summary in "${summaries[@]}"; do
  echo "${summary#RESULT }"
done
exit $status
