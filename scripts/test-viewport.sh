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

source scripts/blender-suites.sh
name=test-viewport
require_blenders
command -v xvfb-run >/dev/null || { echo "test-viewport: xvfb-run is not installed (apt-get install xvfb xauth)" >&2; exit 1; }
install_addon_for_suites

# A saved startup file on the command line: Blender then shows no splash screen.
blender -b --factory-startup --python-expr \
  "import bpy; bpy.ops.wm.save_as_mainfile(filepath='$repo/$out/start.blend')" >/dev/null 2>&1
[ -f "$out/start.blend" ] || { echo "test-viewport: could not save the start file" >&2; exit 1; }

# The window: its 3D view fills it (viewport_ui.py maximizes the area).
# Xvfb writes its screen to FB/Xvfb_screen0, where the tests read what the display shows.
ui() { echo "-screen 0 1280x800x24 -fbdir $1"; }
window=(-p 0 0 640 480)
mkdir -p "$out/fb-3.4" "$out/fb-4.3"

suite_timeout=900

run_suite viewport-3.4 env BLENDER_USER_RESOURCES="$repo/$user_dir/3.4" \
  GLSLPPM_XVFB_FBDIR="$repo/$out/fb-3.4" \
  xvfb-run -a -s "$(ui "$repo/$out/fb-3.4")" blender --factory-startup "${window[@]}" "$out/start.blend" \
  --python tests/blender/viewport_ui.py -- --module glslppm --out "$out/3.4" "$@"

run_suite viewport-4.3 scripts/blender-chroot.sh run env \
  BLENDER_USER_RESOURCES="/src/$user_dir/4.3" GLSLPPM_XVFB_FBDIR="/src/$out/fb-4.3" \
  xvfb-run -a -s "$(ui "/src/$out/fb-4.3")" blender --factory-startup "${window[@]}" "/src/$out/start.blend" \
  --python tests/blender/viewport_ui.py -- --module bl_ext.user_default.glslppm \
  --out "/src/$out/4.3" "$@"

finish_suites "viewport tests"
