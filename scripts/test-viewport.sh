#!/usr/bin/env bash
# `make test-viewport`: the rendered viewport and material preview tests
# (tests/blender/viewport_ui.py) in Blender's real UI on an Xvfb display, under every Blender
# of the matrix (scripts/blender-suites.sh: 3.4 on the host, 4.3 and 5.2 in Debian chroots),
# each against the add-on installed the way users install it. A Blender that cannot start
# its UI fails the suite.
#
# Usage: scripts/test-viewport.sh [-k TEXT]...   (extra arguments go to viewport_ui.py)
#        GLSLPPM_BLENDERS="5.2" scripts/test-viewport.sh   (one Blender, while iterating)
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

# A saved startup file on the command line: Blender then shows no splash screen. Saved by
# the oldest Blender of the matrix, which every newer one opens.
in_blender_env "${blenders[0]}" blender -b --factory-startup --python-expr \
  "import bpy; bpy.ops.wm.save_as_mainfile(filepath='$(repo_in "${blenders[0]}")/$out/start.blend')" >/dev/null 2>&1
[ -f "$out/start.blend" ] || { echo "test-viewport: could not save the start file" >&2; exit 1; }

# The window: its 3D view fills it (viewport_ui.py maximizes the area).
# Xvfb writes its screen to FB/Xvfb_screen0, where the tests read what the display shows.
ui() { echo "-screen 0 1280x800x24 -fbdir $1"; }
window=(-p 0 0 640 480)

suite_timeout=900

for entry in "${blenders[@]}"; do
  version=${entry%%:*}
  root=$(repo_in "$entry")
  mkdir -p "$out/fb-$version"
  suite_started=$SECONDS
  blender_env_prefix "$entry"
  run_suite "viewport-$version" "${prefix[@]}" env \
    BLENDER_USER_RESOURCES="$root/$user_dir/$version" GLSLPPM_XVFB_FBDIR="$root/$out/fb-$version" \
    xvfb-run -a -s "$(ui "$root/$out/fb-$version")" blender --factory-startup "${window[@]}" \
    "$root/$out/start.blend" --python tests/blender/viewport_ui.py -- \
    --module "$(addon_module "$version")" --out "$root/$out/$version" "$@"
  echo "TIME viewport-$version $((SECONDS - suite_started)) s"
done

finish_suites "viewport tests"
