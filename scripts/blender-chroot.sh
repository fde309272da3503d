#!/usr/bin/env bash
# The Debian chroots that run the newer Blenders beside the host's Debian 12 Blender 3.4:
#   trixie (Debian 13): Blender 4.3 (Python 3.13)   the default
#   sid (unstable):     Blender 5.2 (Python 3.14)   sid floats: whatever 5.2.x sid has today
#   minimal:            Debian 13 with Blender alone, nothing the project builds with (no
#                       -dev packages): where the extension zip must install and render
#
#   scripts/blender-chroot.sh [RELEASE] create          debootstrap it once (a stamp file makes this idempotent)
#   scripts/blender-chroot.sh [RELEASE] build           build _glslppm for its Python into build-RELEASE/
#   scripts/blender-chroot.sh [RELEASE] run CMD [ARG..] run a command inside, the repository mounted at /src
#   scripts/blender-chroot.sh [RELEASE] shell           an interactive shell inside
#   scripts/blender-chroot.sh [RELEASE] root            print where its root folder is
#
# RELEASE (trixie or sid) may also come from GLSLPPM_CHROOT_RELEASE; default trixie.
# Where each lives: GLSLPPM_CHROOT_TRIXIE / GLSLPPM_CHROOT_SID, else (trixie only, as before)
# GLSLPPM_CHROOT, else build/RELEASE in the repository. Point several worktrees at one
# chroot to make it once per machine.
#
# Mounts (/proc, /dev, the repository) live in a private mount namespace made by
# unshare(1): they vanish with the command, even when it is killed, so nothing is
# left mounted and several commands can use the chroot at once.
set -euo pipefail

repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
source "$repo/scripts/apt-wait.sh"
release=${GLSLPPM_CHROOT_RELEASE:-trixie}
case "${1:-}" in trixie|sid|minimal) release=$1; shift ;; esac
suite=$release
case "$release" in
  trixie) root=${GLSLPPM_CHROOT_TRIXIE:-${GLSLPPM_CHROOT:-$repo/build/trixie}} ;;
  sid) root=${GLSLPPM_CHROOT_SID:-$repo/build/sid} ;;
  minimal) root=${GLSLPPM_CHROOT_MINIMAL:-$repo/build/minimal}; suite=trixie ;;
  *) echo "blender-chroot: unknown release '$release' (trixie, sid or minimal)" >&2; exit 2 ;;
esac
stamp=$root/.glslppm-ready
mirror=${DEBIAN_MIRROR:-http://deb.debian.org/debian}
packages=(blender g++ cmake ninja-build pkg-config python3-dev python3-numpy pybind11-dev
          libepoxy-dev libopenexr-dev libglm-dev libegl-dev libegl-mesa0 libgl1-mesa-dri
          libtinygltf-dev nlohmann-json3-dev libtinyobjloader-dev libstb-dev
          zip ca-certificates xvfb xauth xdotool)
# sid's Blender starts its extension manager, which imports these (Debian does not pull
# them in; without them every start prints a traceback).
[ "$release" = sid ] && packages+=(python3-cattr python3-requests)
# A user's machine: Blender, the numpy official builds ship (Debian only recommends it),
# the EGL loader and Mesa's EGL for the renderer, unzip.
[ "$release" = minimal ] && packages=(blender python3-numpy libegl1 libegl-mesa0 libgl1-mesa-dri unzip)
# Debian 13's own Mesa (25.0, LLVM 19) runs llvmpipe's shaders 2-4x slower than sid's or
# trixie-backports' 26.x: the same three caustic tests took 58 s under Blender 4.3 with
# 26.1.6 from backports against 50 s under 5.2 on sid, where with 25.0.7 the 4.3 suite's
# renders took 2.4x 5.2's (651 s against 174 s in the full run of session 16). The test
# chroot takes Mesa from trixie-backports; the minimal one (a user's plain Debian 13) keeps
# the release's.
backports=()
[ "$release" = trixie ] && backports=(libgl1-mesa-dri libegl-mesa0 mesa-libgallium)
# sid's Release file may be past its Valid-Until on a mirror snapshot.
apt_release_options="-o Acquire::Check-Valid-Until=false"

need_root() {
  if [ "$(id -u)" -ne 0 ]; then
    exec sudo -E "$0" "$@"
  fi
}

# Runs "$@" in the chroot inside a fresh private mount namespace.
in_chroot() {
  local workdir=${CHROOT_WORKDIR:-/src}
  unshare --mount --propagation private -- /bin/bash -s -- "$root" "$repo" "$workdir" "$@" <<'EOF'
set -e
root=$1 repo=$2 workdir=$3; shift 3
mkdir -p "$root/proc" "$root/dev" "$root/sys" "$root/src" "$root/tmp"
mount --rbind /dev "$root/dev"
mount -t proc proc "$root/proc" 2>/dev/null || mount --rbind /proc "$root/proc"
mount --rbind /sys "$root/sys" 2>/dev/null || true
mount --bind "$repo" "$root/src"
cp -L /etc/resolv.conf "$root/etc/resolv.conf" 2>/dev/null || true
[ -e "$root/etc/mtab" ] || ln -s /proc/self/mounts "$root/etc/mtab"
exec chroot "$root" /usr/bin/env -i HOME=/root LANG=C.UTF-8 TERM="${TERM:-dumb}" \
  PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin \
  DEBIAN_FRONTEND=noninteractive \
  GLSLPPM_MODULE_DIR="${GLSLPPM_MODULE_DIR:-}" GLSLPPM_TEST_ARGS="${GLSLPPM_TEST_ARGS:-}" \
  /bin/bash -c 'cd "$0" && exec "$@"' "$workdir" "$@"
EOF
}

create() {
  # One creator at a time (scripts/test-all.sh starts the chroots in the background while
  # the first suites run; a suite that needs one waits here for it).
  mkdir -p "$(dirname "$root")"
  exec 9>"$root.lock"
  flock 9
  # The stamp holds the package list, so a chroot made for an older list gets the rest.
  local wanted="${packages[*]}"
  [ ${#backports[@]} -eq 0 ] || wanted+=" backports: ${backports[*]}"
  if [ -f "$stamp" ] && [ "$(cat "$stamp")" = "$wanted" ]; then
    echo "chroot: $root is ready (remove $stamp to recreate)"
    return 0
  fi
  local t0=$SECONDS
  if [ ! -x "$root/usr/bin/apt-get" ]; then
    command -v debootstrap >/dev/null || {
      echo "installing debootstrap"
      wait_for_apt
      DEBIAN_FRONTEND=noninteractive apt-get "${APT_LOCK_OPTIONS[@]}" install -y -qq \
        debootstrap >/dev/null
    }
    rm -rf "$root"
    mkdir -p "$(dirname "$root")"
    echo "chroot: debootstrap $suite into $root"
    debootstrap --variant=minbase "$suite" "$root" "$mirror" >"$root.debootstrap.log" 2>&1 || {
      tail -20 "$root.debootstrap.log"
      echo "chroot: debootstrap failed (log: $root.debootstrap.log)" >&2
      exit 1
    }
  fi
  echo "chroot: installing ${packages[*]}"
  # No daemons may start inside the chroot.
  printf '#!/bin/sh\nexit 101\n' >"$root/usr/sbin/policy-rc.d"
  chmod +x "$root/usr/sbin/policy-rc.d"
  # The chroot's apt has its own locks (another user of this chroot may hold them).
  wait_for_apt "$root"
  local apt="apt-get ${APT_LOCK_OPTIONS[*]} $apt_release_options"
  local from_backports=true
  if [ ${#backports[@]} -gt 0 ]; then
    echo "deb $mirror $suite-backports main" >"$root/etc/apt/sources.list.d/backports.list"
    from_backports="$apt install -y -qq --no-install-recommends -t $suite-backports ${backports[*]} >/dev/null"
  fi
  CHROOT_WORKDIR=/ in_chroot /bin/bash -c \
    "$apt update -qq && $apt install -y -qq --no-install-recommends ${packages[*]} >/dev/null && $from_backports && $apt clean"
  echo "$wanted" >"$stamp"
  echo "chroot: ready in $((SECONDS - t0)) s"
}

build() {
  create
  in_chroot /bin/bash -c \
    "cmake -S . -B build-$release -G Ninja -DPython3_EXECUTABLE=/usr/bin/python3 -DGLSLPPM_TESTS=OFF >/dev/null &&
     cmake --build build-$release -j \"\$(nproc)\" --target _glslppm"
}

cmd=${1:-create}
shift || true
need_root "$release" "$cmd" "$@"
case "$cmd" in
  create) create ;;
  build) build ;;
  run) [ -f "$stamp" ] || create; in_chroot "$@" ;;
  shell) [ -f "$stamp" ] || create; in_chroot /bin/bash ;;
  root) echo "$root" ;;
  *) echo "usage: $0 [trixie|sid|minimal] create|build|run CMD...|shell" >&2; exit 2 ;;
esac
