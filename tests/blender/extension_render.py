"""Run by scripts/test-extension.sh in a Blender (4.2+) into whose fresh user folder the
extension zip was installed with `blender --command extension install-file`:

    blender -b --factory-startup --python tests/blender/extension_render.py -- --out DIR

Checks that the add-on enabled from the zip loads the zip's own module (the one of this
Python's ABI, not a build tree's) and renders: a white Lambertian floor (albedo 0.8) under
a sun of strength 3 W/m^2 straight above, whose radiance is 0.8 x 3 / pi (closed form),
within 0.5%.
Prints PASS/FAIL lines and "RESULT extension Blender X: N passed, M failed".
"""

import math
import os
import sys
import traceback

import addon_utils
import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import helpers  # noqa: E402

MODULE = "bl_ext.user_default.glslppm"
# 32 passes of 32 x 32 pixels: the centre's mean is the closed form x 0.99998 in Blender 4.3
# and 5.2 (measured; the sun's direct light is a light sample, nearly noiseless here). 0.5%
# fails a 1% bias in the module's sun or Lambert lobe.
BOUND = 0.005


def test_zip_module_is_loaded():
    addon = helpers.ADDON
    native, problem = addon.native_module.load()
    assert native is not None, problem
    folder = os.path.dirname(os.path.abspath(addon.__file__))
    assert os.path.dirname(os.path.abspath(native.__file__)) == folder, native.__file__
    tag = "cpython-%d%d-" % sys.version_info[:2]
    assert tag in os.path.basename(native.__file__), native.__file__
    print(f"  module {native.__file__}; the zip holds Python "
          f"{', '.join(addon.native_module.bundled_pythons(folder))}")


def test_sun_on_white_floor_renders_its_closed_form():
    helpers.reset_scene(size=(32, 32))
    scene = bpy.context.scene
    scene.glslppm.passes = 32
    white = helpers.diffuse_material("White", (0.8, 0.8, 0.8))
    helpers.add_mesh_object("Floor", [(-10, -10, 0), (10, -10, 0), (10, 10, 0), (-10, 10, 0)],
                            [(0, 1, 2, 3)], material=white)
    helpers.add_light('SUN', 3.0, location=(0, 0, 3), angle=math.radians(1))
    location = (0, -4, 2)
    helpers.add_camera(location, helpers.look_at_rotation(location, (0, 0, 0)), lens=35.0)
    image = helpers.render_image("extension_sun")
    centre = float(image[8:24, 8:24, :3].mean())
    expected = 0.8 * 3.0 / math.pi
    print(f"  floor centre {centre:.5f}, closed form {expected:.5f}, "
          f"ratio {centre / expected:.5f} (bound {BOUND})")
    assert abs(centre / expected - 1.0) < BOUND, (centre, expected)


def main():
    out = sys.argv[sys.argv.index("--out") + 1] if "--out" in sys.argv else "/tmp"
    os.makedirs(out, exist_ok=True)
    helpers.OUT = out
    version = ".".join(map(str, bpy.app.version))
    passed = failed = 0
    try:
        helpers.ADDON = addon_utils.enable(MODULE, default_set=True, handle_error=None)
        assert helpers.ADDON is not None, f"{MODULE} could not be enabled"
        helpers.ADDON_NAME = MODULE
        tests = [test_zip_module_is_loaded, test_sun_on_white_floor_renders_its_closed_form]
    except Exception:  # noqa: BLE001 - reported as a failure
        traceback.print_exc()
        print("FAIL enable the installed extension")
        tests, failed = [], 1
    for test in tests:
        try:
            test()
            print(f"PASS extension.{test.__name__}", flush=True)
            passed += 1
        except Exception:  # noqa: BLE001 - reported as a failure
            traceback.print_exc()
            print(f"FAIL extension.{test.__name__}", flush=True)
            failed += 1
    print(f"RESULT extension Blender {version}: {passed} passed, {failed} failed")
    sys.exit(1 if failed else 0)


main()
