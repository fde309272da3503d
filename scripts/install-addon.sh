#!/usr/bin/env bash
# `make install`: packages the add-on with the compiled module and shaders and installs
#   - into Blender 3.4 (host, Python 3.11) as the user add-on "glslppm",
#   - into Blender 4.3 (the Debian 13 chroot, Python 3.13) and Blender 5.2 (the Debian sid
#     chroot, Python 3.14) as the extension "glslppm" (bl_ext.user_default.glslppm),
#     built and validated with `blender --command extension build|validate`.
#
# Usage: scripts/install-addon.sh [--user-dir DIR] [--only 3.4|4.3|5.2]...
#   --user-dir DIR  install into DIR/3.4, DIR/4.3 and DIR/5.2 (BLENDER_USER_RESOURCES)
#                   instead of the user's own Blender configuration (the tests do this); DIR
#                   must lie inside the repository so the chroots see it.
#   --only V        only that Blender (repeatable)
# Packages are left in build/dist/: glslppm-blender-3.4.zip and glslppm-<version>-<V>.zip.
set -euo pipefail

repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
dist=$repo/build/dist
user_dir=
only=()
while [ $# -gt 0 ]; do
  case "$1" in
    --user-dir) user_dir=$(realpath -m "$2"); shift 2 ;;
    --only) only+=("$2"); shift 2 ;;
    *) echo "usage: $0 [--user-dir DIR] [--only 3.4|4.3|5.2]..." >&2; exit 2 ;;
  esac
done
[ ${#only[@]} -gt 0 ] || only=(3.4 4.3 5.2)
wanted() { [[ " ${only[*]} " == *" $1 "* ]]; }

# Copies the add-on package, one compiled module and the shaders into $1.
stage() {
  local dest=$1 module=$2
  rm -rf "$dest"
  mkdir -p "$dest"
  tar -C "$repo/addon" --exclude=__pycache__ --exclude='*.pyc' -cf - . | tar -C "$dest" -xf -
  cp "$module" "$dest/"
  cp -r "$repo/shaders" "$dest/shaders"
}

install_blender3() {
  local module
  module=$(ls "$repo"/build/_glslppm*.so 2>/dev/null | head -1)
  [ -n "$module" ] || { echo "install: build/_glslppm*.so missing: run make build" >&2; exit 1; }
  stage "$dist/blender-3.4/glslppm" "$module"
  local zip=$dist/glslppm-blender-3.4.zip
  rm -f "$zip"
  (cd "$dist/blender-3.4" && zip -qr "$zip" glslppm)
  local env=()
  [ -z "$user_dir" ] || { mkdir -p "$user_dir/3.4"; env=(BLENDER_USER_RESOURCES="$user_dir/3.4"); }
  env "${env[@]}" blender -b --python-exit-code 1 --python-expr "
import addon_utils, bpy
bpy.ops.preferences.addon_install(filepath='$zip', overwrite=True)
assert addon_utils.enable('glslppm', default_set=True, handle_error=None) is not None
bpy.ops.wm.save_userpref()
print('installed glslppm into Blender', bpy.app.version_string, 'at',
      bpy.utils.user_resource('SCRIPTS', path='addons'))
" 2>&1 | grep -E "installed|Error|rror:" || true
  env "${env[@]}" blender -b --python-exit-code 1 --python-expr \
    "import bpy; assert 'glslppm' in bpy.context.preferences.addons, 'not enabled'" >/dev/null
}

# $1: the Blender (4.3, 5.2), $2: its chroot's release (trixie, sid).
install_extension() {
  local blender=$1 release=$2
  "$repo/scripts/blender-chroot.sh" "$release" build >/dev/null
  local module
  module=$(ls "$repo"/build-$release/_glslppm*.so 2>/dev/null | head -1)
  [ -n "$module" ] || { echo "install: build-$release/_glslppm*.so was not built" >&2; exit 1; }
  local src=$dist/extension-$blender/glslppm
  stage "$src" "$module"
  cp "$repo/blender_manifest.toml" "$src/"
  local version
  version=$(sed -n 's/^version = "\(.*\)"/\1/p' "$repo/blender_manifest.toml")
  local zip=build/dist/glslppm-$version-$blender.zip
  rm -f "$repo/$zip"
  local user_env=
  if [ -n "$user_dir" ]; then
    mkdir -p "$user_dir/$blender"
    user_env="BLENDER_USER_RESOURCES=/src/${user_dir#"$repo"/}/$blender"
  fi
  "$repo/scripts/blender-chroot.sh" "$release" run /bin/bash -c "
set -e
blender --command extension build --source-dir build/dist/extension-$blender/glslppm \
  --output-filepath $zip
blender --command extension validate $zip
env $user_env blender --command extension install-file -r user_default -e $zip
env $user_env blender -b --python-exit-code 1 --python-expr \"import bpy; \
assert 'bl_ext.user_default.glslppm' in bpy.context.preferences.addons, 'not enabled'\" >/dev/null
echo installed extension glslppm into Blender \$(blender -v 2>/dev/null | head -1 | cut -d' ' -f2)
" 2>&1 | grep -v "^$"
}

# Each Blender on its own: one that fails (a locked apt, a chroot that cannot be made) does
# not undo or skip the other; the summary says which is installed.
results=()
status=0
install_one() {
  local label=$1; shift
  set +e
  (set -e; "$@")
  local rc=$?
  set -e
  if [ $rc -eq 0 ]; then
    results+=("$label: installed")
  else
    results+=("$label: FAILED (exit $rc; see above)")
    status=1
  fi
}
if wanted 3.4; then
  if command -v blender >/dev/null; then
    install_one "Blender 3.4 (host)" install_blender3
  else
    results+=("Blender 3.4 (host): not found, skipped (apt-get install blender)")
  fi
fi
! wanted 4.3 || install_one "Blender 4.3 (trixie chroot)" install_extension 4.3 trixie
! wanted 5.2 || install_one "Blender 5.2 (sid chroot)" install_extension 5.2 sid
printf 'install: %s\n' "${results[@]}"
exit $status
