#!/usr/bin/env bash
# Installs the Debian packages the build, the tests and the demo need, only those missing.
# Usage: scripts/install-deps.sh [build|test|demo|bench]
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/apt-wait.sh"
what=${1:-build}
pkgs=(cmake ninja-build g++ pkg-config python3-dev python3-numpy pybind11-dev
      libepoxy-dev libopenexr-dev libglm-dev libegl-dev libegl-mesa0 libgl1-mesa-dri
      libgtest-dev
      libtinygltf-dev nlohmann-json3-dev libtinyobjloader-dev libstb-dev)
case "$what" in
  # clang + libclang-rt-14-dev (libFuzzer, clang's ASan/UBSan runtimes): make test-fuzz-replay
  # xvfb + xauth: the rendered viewport tests run Blender's UI on a virtual display
  # zip, unzip: the add-on and extension zips (scripts/install-addon.sh, test-extension.sh)
  test) pkgs+=(python3-pytest dieharder blender debootstrap clang libclang-rt-14-dev xvfb xauth xdotool
              zip unzip) ;;
  demo) pkgs+=(blender) ;;
  bench) pkgs+=(python3-matplotlib) ;;  # scripts/plot_performance.py
esac
missing=()
for p in "${pkgs[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed' || missing+=("$p")
done
[ ${#missing[@]} -eq 0 ] && exit 0
echo "installing: ${missing[*]}"
sudo=; [ "$(id -u)" -eq 0 ] || sudo=sudo
export DEBIAN_FRONTEND=noninteractive
wait_for_apt
$sudo apt-get "${APT_LOCK_OPTIONS[@]}" update -qq
wait_for_apt
$sudo apt-get "${APT_LOCK_OPTIONS[@]}" install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
