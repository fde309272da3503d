#!/usr/bin/env bash
# `make test-user-path`: the path every user takes first, in Blender's real UI on an Xvfb
# display with real key presses (tests/blender/user_path_ui.py): F12, Esc, F12 again, an
# edit, a file closed during a render, Ctrl+S, Ctrl+Q. Then the F12 / Esc / F12 / Ctrl+Q
# cycle ten times in a row, each in a fresh Blender. On every Blender of the matrix
# (scripts/blender-suites.sh; GLSLPPM_BLENDERS narrows it), each against the add-on installed
# the way users install it. A run
# passes when its steps pass AND Blender then quits by itself with status 0: a crash, a
# freeze (the run's timeout) or a lost Ctrl+Q fails it.
#
# Usage: [GLSLPPM_BLENDERS="3.4 5.2"] scripts/test-user-path.sh [CYCLES]   (default 10)
set -uo pipefail

repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$repo"
user_dir=build/blender-user-path
out=build/user-path-tests
cycles=${1:-10}
started=$SECONDS

source scripts/blender-suites.sh
name=test-user-path
require_blenders
for tool in xvfb-run xdotool; do
  command -v $tool >/dev/null || { echo "test-user-path: $tool is not installed" >&2; exit 1; }
done
install_addon_for_suites

# The start file of each Blender: GLSLPPM chosen (the add-on enabled as a user enables it),
# a 64 x 64 frame, 6 passes, float EXR for reading the result back.
start_script="
import bpy, addon_utils, sys
module = sys.argv[sys.argv.index('--') + 1]
addon_utils.enable(module, default_set=True)
s = bpy.context.scene
s.render.engine = 'GLSLPPM'
s.render.resolution_x = s.render.resolution_y = 64
s.render.resolution_percentage = 100
s.glslppm.passes = 6
if hasattr(s.render.image_settings, 'media_type'):  # 5.x
    s.render.image_settings.media_type = 'IMAGE'
s.render.image_settings.file_format = 'OPEN_EXR'
s.render.image_settings.color_depth = '32'
bpy.ops.wm.save_as_mainfile(filepath=sys.argv[-1])
"

# One run: $1 label, $2 the Blender environment ("VERSION:WHERE"), the rest
# user_path_ui.py's arguments. The run has 300 s; after its RESULT line Blender must exit by
# itself, with status 0.
run_once() {
  local label=$1 entry=$2; shift 2
  local version=${entry%%:*} root
  root=$(repo_in "$entry")
  local log=$out/$label.log copy=$out/$label.blend
  cp "$out/start-$version.blend" "$copy"
  blender_env_prefix "$entry"
  "${prefix[@]}" env BLENDER_USER_RESOURCES="$root/$user_dir/$version" timeout 300 \
    xvfb-run -a -s "-screen 0 1280x800x24" blender --factory-startup -p 0 0 800 600 \
    --addons "$(addon_module "$version")" "$root/$copy" \
    --python tests/blender/user_path_ui.py -- --out "$root/$out/$label" "$@" >"$log" 2>&1
  local rc=$?
  grep -E "^(PASS|FAIL|RESULT|  )" "$log" | sed "s/^/[$label] /"
  if ! grep -q "^RESULT.* 0 failed" "$log"; then
    awk '/^FAIL /{show=1} show' "$log" | head -40
    echo "FAIL $label: steps failed or did not finish (exit $rc; log $log)"
    return 1
  fi
  if [ $rc -ne 0 ]; then
    tail -20 "$log"
    echo "FAIL $label: Blender did not quit normally after Ctrl+Q (exit $rc; log $log)"
    return 1
  fi
  echo "PASS $label: quit with status 0"
}

suite() {
  local entry=$1 version=${1%%:*} passed=0 failed=0 root suite_started=$SECONDS
  root=$(repo_in "$entry")
  in_blender_env "$entry" env BLENDER_USER_RESOURCES="$root/$user_dir/$version" \
    blender -b --factory-startup --python-expr "$start_script" -- \
    "$(addon_module "$version")" "$root/$out/start-$version.blend" >"$out/start-$version.log" 2>&1
  if [ -f "$out/start-$version.blend" ]; then
    if run_once "full-$version" "$entry"; then passed=$((passed + 1)); else failed=$((failed + 1)); fi
    for i in $(seq 1 "$cycles"); do
      if run_once "cycle-$version-$i" "$entry" --only-cycle; then
        passed=$((passed + 1)); else failed=$((failed + 1)); fi
    done
  else
    cat "$out/start-$version.log"
    failed=1
  fi
  echo "RESULT Blender $version (user path): $passed passed, $failed failed, 0 skipped"
  echo "TIME user-path-$version $((SECONDS - suite_started)) s"
  summaries+=("Blender $version (user path): $passed runs passed, $failed failed")
  [ $failed -eq 0 ] || status=1
}

for entry in "${blenders[@]}"; do
  suite "$entry"
done

echo "== user path tests ($((SECONDS - started)) s) =="
for summary in "${summaries[@]}"; do echo "$summary"; done
exit $status
