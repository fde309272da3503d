#!/usr/bin/env bash
# `make test-extension`: the extension zip (scripts/make-extension.sh) as a user gets it.
#   1. Each module in it needs nothing of the machine beyond glibc, libstdc++, libgcc_s and
#      the GL/EGL loaders: ldd, run where the module was built, resolves every other library
#      into the zip's own libs/cpXY/ folder (readelf lists what it needs).
#   2. The one zip installs with `blender --command extension install-file` into a fresh
#      user folder of each extension Blender of the matrix (4.3, 5.2) and renders a sun on a
#      white floor within 1% of its closed form (tests/blender/extension_render.py).
#   3. The same on a machine with Blender and nothing the project builds with: the minimal
#      chroot (scripts/blender-chroot.sh minimal: Debian 13, Blender and Mesa's EGL, no -dev
#      package), where ldd must find every library but the system's in the zip too.
#   4. The demo (demo/showcase.py), small, rendered from the zip in each of them:
#      pixel for pixel (to float rounding) the image of the module the other suites tested.
# Prints PASS/FAIL lines and "RESULT extension: N passed, M failed"; exits 1 on a failure.
set -uo pipefail

repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$repo"
out=build/extension-test
source scripts/blender-suites.sh
name=test-extension
passed=0 failed=0
pass() { echo "PASS $1"; passed=$((passed + 1)); }
fail() { echo "FAIL $1"; failed=$((failed + 1)); }

rm -rf "$out"
mkdir -p "$out/unzipped"
if ! scripts/make-extension.sh | tee "$out/make.log"; then
  echo "RESULT extension: 0 passed, 1 failed (make-extension.sh failed)"
  exit 1
fi
zip=$(ls build/dist/glslppm-*-linux-x64.zip | head -1)
unzip -q "$zip" -d "$out/unzipped"
system_libs='^(linux-vdso|ld-linux-x86-64|libc|libm|libdl|libpthread|librt|libstdc\+\+|libgcc_s|libEGL|libGL|libOpenGL|libGLX|libGLdispatch)\.so'

# 1. ldd of each module where it was built: every library outside the system list from the zip.
scripts/blender-chroot.sh minimal create >"$out/minimal-chroot.log" 2>&1 ||
  { tail -20 "$out/minimal-chroot.log"; fail "the minimal chroot could not be made"; }
# None of what the module builds with (scripts/install-deps.sh's build list); numpy's own
# python3-numpy-dev, which Debian 13's python3-numpy depends on, is Blender's numpy.
devs=$(scripts/blender-chroot.sh minimal run bash -c \
  "dpkg-query -W -f='\${Package}\n' | grep -xE 'g\\+\\+|cmake|pkg-config|python3-dev|pybind11-dev|lib(epoxy|openexr|glm|egl|tinygltf|tinyobjloader|stb)-dev|nlohmann-json3-dev' | tr '\n' ' '" 2>&1)
if [ -z "$devs" ]; then pass "minimal chroot: Blender without the project's build packages"
else fail "minimal chroot has the project's build packages: $devs"; fi

for entry in 311:host 313:trixie 314:sid 313:minimal; do
  abi=${entry%%:*} where=${entry#*:}
  module=$(ls "$out"/unzipped/_glslppm.cpython-$abi-*.so 2>/dev/null | head -1)
  [ -n "$module" ] || { fail "ldd cp$abi: no module for Python ${abi:0:1}.${abi:1} in $zip"; continue; }
  root=$(repo_in "$entry")
  blender_env_prefix "$entry"
  lines=$("${prefix[@]}" ldd "$root/$module" 2>&1)
  from_zip=() outside=()
  while read -r soname arrow path _; do
    [ "$arrow" = "=>" ] || continue
    [[ "$soname" =~ $system_libs ]] && continue
    if [[ "$path" == "$root/$out/unzipped/libs/cp$abi/"* ]]; then from_zip+=("$soname")
    else outside+=("$soname => $path"); fi
  done <<<"$lines"
  needed=$(readelf -d "$module" | sed -n 's/.*(NEEDED).*\[\(.*\)\]/\1/p' | tr '\n' ' ')
  # The oldest system it loads on: the newest glibc and libstdc++ symbol versions that the
  # module and its bundled libraries ask for.
  newest() { objdump -T "$module" "$out"/unzipped/libs/cp$abi/*.so* 2>/dev/null |
      grep -o "$1_[0-9.]*" | sort -uV | tail -1; }
  needed="$needed(oldest system: $(newest GLIBC), $(newest GLIBCXX))"
  if [ ${#outside[@]} -eq 0 ] && [ ${#from_zip[@]} -gt 0 ] && ! grep -q "not found" <<<"$lines"; then
    pass "ldd cp$abi ($where): needs $needed; from the zip: ${from_zip[*]}"
  else
    echo "$lines"
    fail "ldd cp$abi ($where): outside the zip: ${outside[*]:-none} $(grep "not found" <<<"$lines" | tr -s ' \t' ' ')"
  fi
done

# 2. Install the one zip into each extension Blender's fresh user folder and render.
for entry in 4.3:trixie 5.2:sid 4.3-minimal:minimal; do
  version=${entry%%:*}
  user=$out/user-$version
  mkdir -p "$user"
  blender_env_prefix "$entry"
  log=$out/install-$version.log
  if ! "${prefix[@]}" env BLENDER_USER_RESOURCES="/src/$user" blender --command extension \
      install-file -r user_default -e "/src/$zip" >"$log" 2>&1; then
    cat "$log"; fail "install $zip into Blender $version"; continue
  fi
  pass "install $(basename "$zip") into Blender $version (extension install-file)"
  log=$out/render-$version.log
  "${prefix[@]}" env BLENDER_USER_RESOURCES="/src/$user" blender -b --factory-startup \
    --python tests/blender/extension_render.py -- --out "/src/$out/$version" >"$log" 2>&1
  grep -E "^(PASS|FAIL|  )" "$log"
  result=$(grep -E "^RESULT extension" "$log" | tail -1)
  if [ -z "$result" ]; then
    tail -30 "$log"; fail "render in Blender $version: did not finish"
  else
    p=$(sed -n 's/.*: \([0-9]*\) passed, \([0-9]*\) failed.*/\1/p' <<<"$result")
    f=$(sed -n 's/.*: \([0-9]*\) passed, \([0-9]*\) failed.*/\2/p' <<<"$result")
    passed=$((passed + p)); failed=$((failed + f))
    [ "$f" -eq 0 ] || grep -B30 "^FAIL" "$log" | grep -v "^PASS" | head -40
  fi
done

# 4. The demo (demo/showcase.py, what `make demo` renders) from the zip, small: in
#    each Blender it must equal, pixel for pixel to float rounding, the same render by the
#    module the other suites tested (that Blender's build tree, through GLSLPPM_MODULE_DIR),
#    so the zip's module and the libraries it bundles render what was tested; the minimal
#    chroot's must equal Debian 13's (the same Blender 4.3 and Mesa). A render is fixed by
#    its seed and pass count up to the order of atomic float sums
#    (tests/blender/extension_demo_compare.py states the bound).
demo_args=(--size 48 --passes 8 --photons 16384)
for entry in 4.3:trixie:build-trixie 5.2:sid:build-sid 4.3-minimal:minimal:; do
  IFS=: read -r version where build <<<"$entry"
  [ -d "$out/user-$version" ] || continue
  blender_env_prefix "$version:$where"
  log=$out/demo-$version.log
  "${prefix[@]}" env BLENDER_USER_RESOURCES="/src/$out/user-$version" blender -b \
    --factory-startup --python demo/showcase.py -- --out "/src/$out/$version/demo-zip" \
    "${demo_args[@]}" >"$log" 2>&1
  reference=$out/4.3/demo-zip.exr
  if [ -n "$build" ]; then
    "${prefix[@]}" env BLENDER_USER_RESOURCES="/src/$out/user-$version" \
      GLSLPPM_MODULE_DIR="/src/$build" blender -b --factory-startup \
      --python demo/showcase.py -- --out "/src/$out/$version/demo-build" \
      "${demo_args[@]}" >>"$log" 2>&1
    reference=$out/$version/demo-build.exr
  fi
  if verdict=$(PYTHONPATH=build /usr/bin/python3 tests/blender/extension_demo_compare.py \
      "$out/$version/demo-zip.exr" "$reference" 2>&1); then
    pass "demo from the zip in Blender $version: $verdict"
  else
    tail -20 "$log"; fail "demo from the zip in Blender $version: $verdict"
  fi
done

echo "RESULT extension: $passed passed, $failed failed ($(du -k "$zip" | cut -f1) KiB zip)"
[ "$failed" -eq 0 ]
