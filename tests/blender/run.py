"""Runs the Blender tests inside Blender (pytest is not part of Blender's Python):

    blender -b --factory-startup --python tests/blender/run.py -- [options]

    --module NAME    enable the installed add-on NAME ("glslppm" for Blender 3.x,
                     "bl_ext.user_default.glslppm" for an extension in 4.2+)
    --source DIR     import the add-on package from DIR (the repo's addon/) instead
    --out DIR        where tests write images (default: a temporary directory)
    -k TEXT          run only tests whose name contains TEXT (repeatable)

Each test_*.py module's test_* functions run in file order. A test fails on any
exception, is skipped by raising helpers.Skip. Prints one line per test and a
summary "N passed, M failed, K skipped"; exits 1 when any test failed.
"""

import argparse
import importlib
import os
import sys
import tempfile
import time
import traceback

HERE = os.path.dirname(os.path.abspath(__file__))
TEST_MODULES = ("test_install", "test_export", "test_render", "test_cycles", "test_fidelity",
                "test_materials", "test_absorption",
                "test_cancel_latency", "test_ray_visibility", "test_sky",
                "test_curves", "test_farm", "test_instances", "test_passes",
                "test_texture_coordinates", "test_motion_blur", "test_showcase",
                "test_light_groups")


def parse_args():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    parser = argparse.ArgumentParser(prog="run.py")
    parser.add_argument("--module")
    parser.add_argument("--source")
    parser.add_argument("--out")
    parser.add_argument("-k", dest="keywords", action="append", default=[])
    return parser.parse_args(argv)


def enable_addon(args):
    import addon_utils
    if args.source:
        link_dir = tempfile.mkdtemp(prefix="glslppm-source-")
        os.symlink(os.path.abspath(args.source), os.path.join(link_dir, "glslppm"))
        sys.path.insert(0, link_dir)
        package = importlib.import_module("glslppm")
        package.register()
        return package, "glslppm"
    name = args.module or "glslppm"
    module = addon_utils.enable(name, default_set=True, handle_error=_raise)
    if module is None:
        raise RuntimeError(f"add-on {name} could not be enabled")
    return module, name


def _raise(error):
    raise error


def main():
    args = parse_args()
    sys.path.insert(0, HERE)
    import bpy
    import helpers
    version = ".".join(map(str, bpy.app.version))
    print(f"== Blender {version} tests ==", flush=True)
    helpers.OUT = os.path.abspath(args.out or tempfile.mkdtemp(prefix="glslppm-tests-"))
    os.makedirs(helpers.OUT, exist_ok=True)
    passed, failed, skipped = [], [], []
    started = time.perf_counter()
    try:
        helpers.SOURCE_MODE = bool(args.source)
        helpers.ADDON, helpers.ADDON_NAME = enable_addon(args)
    except Exception:  # noqa: BLE001 - reported as a failed test
        traceback.print_exc()
        failed.append("enable add-on")
        helpers.ADDON = None
    if helpers.ADDON is not None:
        for module_name in TEST_MODULES:
            module = importlib.import_module(module_name)
            for name, test in list(vars(module).items()):  # tests may add globals
                if not name.startswith("test_") or not callable(test):
                    continue
                full = f"{module_name}.{name}"
                if args.keywords and not any(k in full for k in args.keywords):
                    continue
                run_test(full, test, passed, failed, skipped)
    seconds = time.perf_counter() - started
    print_slowest()
    print(f"RESULT Blender {version}: {len(passed)} passed, {len(failed)} failed, "
          f"{len(skipped)} skipped in {seconds:.0f} s", flush=True)
    for name in failed:
        print(f"FAILED {name}")
    sys.exit(1 if failed else 0)


# Each test's seconds and its slow mark's reason (helpers.slow), for print_slowest.
DURATIONS = {}
SLOW_SECONDS = 30.0


def print_slowest(count=20):
    """The slowest tests as DURATION lines (scripts/test_summary.py lists them): over 30 s a
    test carries helpers.slow("why"), and a line names any that does not."""
    import bpy
    version = ".".join(map(str, bpy.app.version))
    print(f"{count} slowest tests in Blender {version} (over {SLOW_SECONDS:.0f} s they carry "
          "helpers.slow, which says why):")
    for name, (seconds, reason) in sorted(DURATIONS.items(), key=lambda item: -item[1][0])[:count]:
        line = f"DURATION {seconds:.1f} {name} [Blender {version}]"
        if reason is not None:
            line += f" (slow: {reason})"
        elif seconds > SLOW_SECONDS:
            line += f" (over {SLOW_SECONDS:.0f} s, NOT MARKED SLOW)"
        print(line)


def run_test(full, test, passed, failed, skipped):
    import helpers
    helpers.reset_scene()
    began = time.perf_counter()
    try:
        _run_test(full, test, passed, failed, skipped, began)
    finally:
        DURATIONS[full] = (time.perf_counter() - began, getattr(test, "slow_reason", None))


def _run_test(full, test, passed, failed, skipped, began):
    import helpers
    try:
        test()
    except helpers.Skip as reason:
        skipped.append(full)
        print(f"SKIP {full}: {reason}", flush=True)
        return
    except Exception:  # noqa: BLE001 - a failing test, whatever it raised
        failed.append(full)
        print(f"FAIL {full} ({time.perf_counter() - began:.1f} s)", flush=True)
        traceback.print_exc()
        sys.stdout.flush()
        return
    passed.append(full)
    print(f"PASS {full} ({time.perf_counter() - began:.1f} s)", flush=True)


if __name__ == "__main__":
    main()
