#!/usr/bin/env bash
# `make extension`: the one extension zip a Blender user downloads and installs with
# Preferences > Get Extensions > Install from Disk (Blender 4.2+), or
# `blender --command extension install-file -r user_default -e ZIP`:
#
#   build/dist/glslppm-<version>-linux-x64.zip
#     glslppm/_glslppm.cpython-311-x86_64-linux-gnu.so   host (Debian 12) build: official 4.2-5.0
#     glslppm/_glslppm.cpython-313-x86_64-linux-gnu.so   trixie build: official 5.1+, Debian 13
#     glslppm/_glslppm.cpython-314-x86_64-linux-gnu.so   sid build: Debian sid's Blender 5.2
#     glslppm/libs/cp3XX/*.so*   every shared library each module needs beyond glibc,
#                                libstdc++, libgcc_s and the GL/EGL loaders, found through the
#                                module's DT_RPATH $ORIGIN/libs/cp3XX (CMakeLists.txt)
#     glslppm/shaders/, the add-on's Python files, blender_manifest.toml
#
# Python picks the module of its own ABI by file name (addon/native_module.py names the
# Pythons a zip holds when none matches). Each module is built in its Debian: it needs that
# release's glibc (2.36 / 2.41 / sid's) or newer.
#
# Usage: scripts/make-extension.sh
set -euo pipefail

repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$repo"
version=$(sed -n 's/^version = "\(.*\)"/\1/p' blender_manifest.toml)
zip=build/dist/glslppm-$version-linux-x64.zip
stage=build/dist/extension-linux-x64/glslppm
# What Blender's process already has or every Linux system provides: not bundled.
system_libs='^(linux-vdso|ld-linux-x86-64|libc|libm|libdl|libpthread|librt|libstdc\+\+|libgcc_s|libEGL|libGL|libOpenGL|libGLX|libGLdispatch)\.so'

# The module of each environment: "WHERE:BUILD_DIR" (host: the machine's own Python).
builds=(host:build trixie:build-trixie sid:build-sid)

module_of() { ls "$1"/_glslppm.cpython-*-x86_64-linux-gnu.so 2>/dev/null | head -1; }

# Prints "soname path" for every shared library the module $2 loads, as ldd resolves it in
# environment $1 (the module's own rpath folder does not exist there yet).
needed() {
  local where=$1 module=$2
  if [ "$where" = host ]; then
    ldd "$module"
  else
    scripts/blender-chroot.sh "$where" run ldd "/src/$module"
  fi | awk '$2 == "=>" && $3 ~ /^\// {print $1, $3}'
}

rm -rf "$stage" "$zip"
mkdir -p "$stage"
tar -C addon --exclude=__pycache__ --exclude='*.pyc' -cf - . | tar -C "$stage" -xf -
cp -r shaders "$stage/shaders"
cp blender_manifest.toml "$stage/"

for entry in "${builds[@]}"; do
  where=${entry%%:*} dir=${entry#*:}
  if [ "$where" = host ]; then
    make --no-print-directory build >/dev/null
  else
    scripts/blender-chroot.sh "$where" build >/dev/null
  fi
  module=$(module_of "$dir")
  [ -n "$module" ] || { echo "extension: $dir/_glslppm*.so was not built" >&2; exit 1; }
  tag=$(basename "$module" | sed -n 's/^_glslppm\.cpython-\([0-9]*\)-.*/cp\1/p')
  rpath=$(readelf -d "$module" | sed -n 's/.*(RPATH).*\[\(.*\)\]/\1/p')
  [ "$rpath" = "\$ORIGIN/libs/$tag" ] ||
    { echo "extension: $module has RPATH '$rpath', not \$ORIGIN/libs/$tag (rebuild it)" >&2; exit 1; }
  cp "$module" "$stage/"
  mkdir -p "$stage/libs/$tag"
  # A chroot's files are copied through its root folder on this machine.
  root=
  [ "$where" = host ] || root=$(scripts/blender-chroot.sh "$where" root)
  bundled=()
  while read -r soname path; do
    [[ "$soname" =~ $system_libs ]] && continue
    cp -L "$root$path" "$stage/libs/$tag/$soname"
    bundled+=("$soname")
  done < <(needed "$where" "$module")
  echo "extension: $tag from $where: $(basename "$module") + ${bundled[*]:-nothing}"
done

# Blender's own packer validates the manifest and writes the zip.
scripts/blender-chroot.sh sid run blender --command extension build \
  --source-dir "/src/$stage" --output-filepath "/src/$zip" >/dev/null
scripts/blender-chroot.sh sid run blender --command extension validate "/src/$zip" >/dev/null
echo "extension: $zip ($(du -k "$zip" | cut -f1) KiB; modules for $(ls "$stage" | sed -n 's/^_glslppm\.cpython-\([0-9]\)\([0-9]*\)-.*/\1.\2/p' | tr '\n' ' '))"
