#!/usr/bin/env bash
# `make demo`: installs the add-on, builds the showcase scene (a tumbler of tea, a gold
# ring's cardioid, a blue glass ball, a rough copper ball and a frosted glass cube under one
# small lamp; demo/showcase.py) and renders it with `blender -b` and the GLSLPPM engine into
# out/demo.png and out/demo.exr, printing progress, and saves it as out/demo.blend.
#
# Environment: DEMO_BLENDER=3.4|4.3|5.2 (default 3.4; 4.3 runs in the Debian 13 chroot,
# 5.2 in the Debian sid chroot),
# DEMO_SIZE (pixels, default 512), DEMO_PASSES (at most, default 4096), DEMO_TIME_LIMIT
# (seconds, default 120; 0 = none), DEMO_PHOTONS (per pass, default 65536).
set -euo pipefail

repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$repo"
blender_version=${DEMO_BLENDER:-3.4}
args=(--out out/demo --size "${DEMO_SIZE:-512}" --passes "${DEMO_PASSES:-4096}"
      --time-limit "${DEMO_TIME_LIMIT:-120}" --photons "${DEMO_PHOTONS:-65536}"
      --save out/demo.blend)
mkdir -p out

scripts/install-addon.sh --only "$blender_version"
started=$SECONDS
chroot=()
case "$blender_version" in
  4.3) chroot=(scripts/blender-chroot.sh trixie run) ;;
  5.2) chroot=(scripts/blender-chroot.sh sid run) ;;
esac
if [ ${#chroot[@]} -gt 0 ]; then
  "${chroot[@]}" blender -b --factory-startup --python demo/showcase.py -- "${args[@]}"
else
  blender -b --factory-startup --python demo/showcase.py -- "${args[@]}"
fi 2>&1 | grep --line-buffered -vE "^$|^Blender quit"
[ -s out/demo.png ] && [ -s out/demo.exr ] || { echo "demo: no image was written" >&2; exit 1; }
echo "demo: out/demo.png and out/demo.exr in $((SECONDS - started)) s"
echo "demo: to open the scene in Blender's UI with the GLSLPPM engine chosen:"
echo "        blender $repo/out/demo.blend    (then F12 renders it, Esc stops)"
