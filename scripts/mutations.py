"""`make test-mutations`: plants deliberate bugs in a copy of the shaders, one at a time,
runs the suites against that copy (GLSLPPM_SHADER_DIR) and reports which tests caught
each. A mutation that no test catches is a hole in the suite; the script exits 1 then.

    python3 scripts/mutations.py [--build build] [--suites python,bench,native,blender]
                                 [--only NAME]... [--list]

Each mutation replaces one exact piece of shader text; when the text is no longer found
(the shader changed), the script fails and names the mutation, so the list is kept in step
with the shaders rather than silently testing nothing. Takes 4-14 minutes a mutation
on two llvmpipe cores (the Blender suite adds about 4 minutes each); not part of `make test`.
"""
import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))
# Debian's Python, which has pytest and numpy (the Makefile's PYTHON).
PYTHON = os.environ.get("PYTHON", "/usr/bin/python3")

# name: (what the bug does, shader file, text, replacement)
MUTATIONS = {
    "fresnel-dropped": (
        "glass always refracts: Fresnel reflection never chosen",
        "common/bsdf.glsl", "if (u < f) return reflect(dir, nn);",
        "if (false) return reflect(dir, nn);"),
    "diffuse-loss-2pct": (
        "2% of the light reflected at the visible point lost (diffuse surfaces the camera sees)",
        "eye_trace.comp", "weight = throughput * color / PI;",
        "weight = throughput * color * 0.98 / PI;"),
    "photon-bounce-loss-2pct": (
        "2% of a photon's flux lost at each diffuse bounce (indirect light only)",
        "photon_trace.comp", "flux *= albedo / q;", "flux *= 0.98 * albedo / q;"),
    "emitter-cosine-dropped": (
        "emissive triangles emit uniformly over the hemisphere instead of by cosine",
        "common/emitters.glsl",
        "dir = sample_cosine_hemisphere(n, u3, u4);\n        origin = offset_origin(p, n, dir);",
        "dir = sample_sphere(u3, u4);\n        if (dot(dir, n) < 0.0) dir = -dir;\n"
        "        origin = offset_origin(p, n, dir);"),
    "mtbvh-order-flipped": (
        "rays take the link set of the opposite direction: the far child first",
        "common/mtbvh.glsl", "return 2 * axis + (d[axis] < 0.0 ? 1 : 0);",
        "return 2 * axis + (d[axis] < 0.0 ? 0 : 1);"),
    "radius-square-dropped": (
        "the progressive update scales tau by R'/R instead of (R'/R)^2",
        "gather.comp", "float shrink = (r_new * r_new) / r2;", "float shrink = r_new / r;"),
}


def apply(shader_dir, name):
    _, path, old, new = MUTATIONS[name]
    full = os.path.join(shader_dir, path)
    with open(full) as f:
        text = f.read()
    if text.count(old) != 1:
        raise SystemExit(f"mutation {name}: expected the text once in shaders/{path}, found it "
                         f"{text.count(old)} times; update scripts/mutations.py")
    with open(full, "w") as f:
        f.write(text.replace(old, new))


def run(command, env, log):
    result = subprocess.run(command, cwd=ROOT, env=env, stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True)
    with open(log, "w") as f:
        f.write(result.stdout)
    return result.returncode, result.stdout


def caught_by(suite, build, env, log):
    """The names of the tests of `suite` that failed."""
    if suite == "python":
        env = dict(env, PYTHONPATH=os.path.join(ROOT, build))
        _, out = run([PYTHON, "-m", "pytest", "-q", "-rf", "-p", "no:cacheprovider",
                      "tests/python"], env, log)
        if not re.search(r"\d+ (passed|failed)", out):
            raise SystemExit(f"pytest did not run (see {log})")
        return sorted(set(re.findall(r"^FAILED (\S+?)(?: - .*)?$", out, re.M)))
    if suite == "native":
        _, out = run(["ctest", "--test-dir", build, "-j", str(os.cpu_count() or 2)], env, log)
        return sorted(set(re.findall(r"^\s*\d+ - (\S+) \(Failed\)", out, re.M)))
    if suite == "bench":
        rc, out = run([PYTHON, "tests/bench/check_bench.py",
                       os.path.join(build, "glslppm-bench")], env, log)
        fails = re.findall(r"^\s*FAIL (.*)$", out, re.M)
        return fails or (["check_bench.py (exit %d)" % rc] if rc else [])
    if suite == "blender":
        env = dict(env, GLSLPPM_MODULE_DIR=os.path.join(ROOT, build))
        rc, out = run(["blender", "-b", "--factory-startup", "--python", "tests/blender/run.py",
                       "--", "--source", "addon", "-k", "test_cycles"], env, log)
        return sorted(set(re.findall(r"^FAIL (\S+)", out, re.M)))
    raise SystemExit(f"unknown suite {suite}")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--build", default="build")
    parser.add_argument("--suites", default="python,bench,native")
    parser.add_argument("--only", action="append", default=[])
    parser.add_argument("--list", action="store_true")
    args = parser.parse_args()
    if args.list:
        for name, (what, path, _, _) in MUTATIONS.items():
            print(f"{name:26s} shaders/{path}: {what}")
        return 0
    names = args.only or list(MUTATIONS)
    suites = args.suites.split(",")
    work = tempfile.mkdtemp(prefix="glslppm-mutations-")
    table = []
    for name in names:
        shader_dir = os.path.join(work, name, "shaders")
        shutil.copytree(os.path.join(ROOT, "shaders"), shader_dir)
        apply(shader_dir, name)
        env = dict(os.environ, GLSLPPM_SHADER_DIR=shader_dir)
        started = time.monotonic()
        caught = []
        for suite in suites:
            log = os.path.join(work, name, f"{suite}.log")
            caught += [f"{suite}: {t}" for t in caught_by(suite, args.build, env, log)]
        seconds = time.monotonic() - started
        table.append((name, caught))
        print(f"{name}: {'caught by ' + str(len(caught)) if caught else 'NOT CAUGHT'} "
              f"({seconds:.0f} s; logs in {os.path.join(work, name)})", flush=True)
        for test in caught:
            print(f"    {test}", flush=True)
    print("\n| mutation | what it breaks | tests that caught it |\n|---|---|---|")
    for name, caught in table:
        shown = ", ".join(t.split("::")[-1] for t in caught[:4])
        more = f" and {len(caught) - 4} more" if len(caught) > 4 else ""
        print(f"| {name} | {MUTATIONS[name][0]} | {len(caught)}: {shown}{more} |"
              if caught else f"| {name} | {MUTATIONS[name][0]} | NONE |")
    missed = [name for name, caught in table if not caught]
    if missed:
        print(f"not caught: {', '.join(missed)}")
    return 1 if missed else 0


if __name__ == "__main__":
    sys.exit(main())
