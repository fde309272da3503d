#!/usr/bin/env python3
"""Runs each glslppm-bench subcommand once on a tiny configuration and checks its JSON:
the fields are there and the numbers are sane (positive rates, GPU traversal agreeing with
the CPU's on every checked ray, in its answers and in the nodes it visits, the MTBVH
visiting fewer nodes than the TBVH, error falling with passes, the furnace converging to its
exact radiance, the SPPM reference of the diffuse Cornell box matching a Cycles render of
it). The Cycles cross-check needs `blender` (3.4 or later) on PATH: without it this FAILS,
naming what is missing. `make test-bench` runs it in about 65 s on llvmpipe.

usage: check_bench.py BUILD/glslppm-bench [WORK_DIR]
"""

import json
import math
import os
import shutil
import subprocess
import sys
import tempfile
import time

FAILURES = []
ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")


def check(condition, message):
    if not condition:
        FAILURES.append(message)
        print(f"  FAIL {message}")


def run(bench, *args, expect_failure=False):
    command = [bench, *args]
    start = time.monotonic()
    result = subprocess.run(command, capture_output=True, text=True, timeout=300)
    seconds = time.monotonic() - start
    print(f"{' '.join(args[:1])}: {seconds:.1f} s  ({' '.join(command[1:])})")
    if expect_failure:
        check(result.returncode != 0, f"{args[0]} should have failed: {result.stdout}")
        return result.stderr
    if result.returncode != 0:
        check(False, f"{args[0]} exited {result.returncode}: {result.stderr.strip()}")
        return None
    try:
        return json.loads(result.stdout)
    except json.JSONDecodeError as error:
        check(False, f"{args[0]} printed no JSON object ({error}): {result.stdout[:200]}")
        return None


def run_lines(bench, *args):
    """A command that prints one JSON object a line: the list of them, or None (a failure
    recorded)."""
    command = [bench, *args]
    start = time.monotonic()
    result = subprocess.run(command, capture_output=True, text=True, timeout=300)
    print(f"{args[0]}: {time.monotonic() - start:.1f} s  ({' '.join(command[1:])})")
    if result.returncode != 0:
        check(False, f"{args[0]} exited {result.returncode}: {result.stderr.strip()}")
        return None
    try:
        return [json.loads(line) for line in result.stdout.splitlines() if line.strip()]
    except json.JSONDecodeError as error:
        check(False, f"{args[0]} printed a line that is no JSON object ({error})")
        return None


def positive(value):
    return isinstance(value, (int, float)) and math.isfinite(value) and value > 0


def check_bvh(bench):
    out = run(bench, "bvh", "--triangles", "2000", "--rays", "2000", "--json")
    if out is None:
        return
    check(out["triangles"] == 2000, f"bvh triangles {out['triangles']} != 2000")
    check(out["nodes"] >= out["leaves"] > 0, f"bvh nodes {out['nodes']} leaves {out['leaves']}")
    for key in ("build_seconds", "mtbvh_bytes_per_triangle", "tbvh_bytes_per_triangle",
                "mtbvh_cpu_mrays_per_second", "tbvh_cpu_mrays_per_second"):
        check(positive(out.get(key)), f"bvh {key} = {out.get(key)}")
    # Six link sets cost more than one: MTBVH storage exceeds the TBVH's.
    check(out["mtbvh_bytes_per_triangle"] > out["tbvh_bytes_per_triangle"], "bvh storage order")


def check_rng(bench):
    out = run(bench, "rng", "--generator", "pcg", "--threads", "4096", "--per-thread", "16",
              "--json")
    if out is None:
        return
    check(positive(out.get("numbers_per_second")), f"rng rate {out.get('numbers_per_second')}")
    # Mean of 65,536 uniforms: standard error 0.29 / 256 = 0.0011; 5 sigma.
    check(abs(out["stream_mean"] - 0.5) < 0.0057, f"rng stream mean {out['stream_mean']}")
    # A path that JSON must escape comes back as it was given.
    with tempfile.TemporaryDirectory() as folder:
        path = os.path.join(folder, 'stream "quoted" \\ name.bin')
        out = run(bench, "rng", "--generator", "pcg", "--threads", "64", "--per-thread", "16",
                  "--out", path, "--json")
        if out is not None:
            check(out["out"] == path and out["stream_numbers"] == 64 * 16,
                  f"rng --out {path!r}: {out['out']!r}, {out['stream_numbers']} numbers")


def check_passes(bench):
    out = run(bench, "passes", "--width", "32", "--height", "32", "--photons", "4096",
              "--passes", "4", "--warmup", "1", "--scene", "caustic", "--json")
    if out is None:
        return
    check(out["scene"] == "caustic", f"passes scene {out['scene']}")
    for key in ("passes_per_second", "photons_per_second", "rays_per_second", "gpu_bytes",
                "triangles"):
        check(positive(out.get(key)), f"passes {key} = {out.get(key)}")
    for stage in ("eye", "photon", "hash", "gather"):
        check(positive(out["stage_ms"][stage]), f"passes stage {stage} = {out['stage_ms']}")
    check("area-lights" in out["variant"].split(","), f"caustic scene variant {out['variant']}")
    check(out["instancing"] == "none" and out["instances"] == 0,
          f"caustic scene instancing {out['instancing']}")
    # The instancing scene: 200 bumpy spheres of about 2k triangles, past the flattening
    # bound (262,144), so the two-level MTBVH; the distinct triangles are the room's 12 and
    # one sphere's.
    out = run(bench, "passes", "--width", "32", "--height", "32", "--photons", "4096",
              "--passes", "2", "--warmup", "1", "--scene", "instances:200x2k", "--json")
    if out is None:
        return
    check(out["instancing"] == "two-level", f"instances scene path {out['instancing']}")
    check("instances" in out["variant"].split(","), f"instances variant {out['variant']}")
    check(out["instances"] == 200, f"instances {out['instances']}")
    sphere = out["triangles"] - 12
    check(out["instanced_triangles"] == 200 * sphere and sphere > 1900,
          f"instanced triangles {out['instanced_triangles']}, distinct {out['triangles']}")
    for key in ("passes_per_second", "bvh_seconds", "setup_seconds", "film_read_seconds", "gpu_bytes"):
        check(positive(out.get(key)), f"instances passes {key} = {out.get(key)}")
    check(out["motion"] == "none" and out["motion_refit_ms_per_pass"] == 0,
          f"static instances motion {out['motion']}")
    # +motion: 20 small instances (flattened when still) move, so two levels, refitted.
    out = run(bench, "passes", "--width", "32", "--height", "32", "--photons", "4096",
              "--passes", "2", "--warmup", "1", "--scene", "instances:20x1k+motion", "--json")
    if out is None:
        return
    check(out["motion"] == "camera,instances" and out["moving_instances"] == 20,
          f"moving instances {out['motion']} {out['moving_instances']}")
    check(out["instancing_reason"] == "instances move (motion blur)",
          f"moving instances path {out['instancing_reason']}")
    check(positive(out["motion_refit_ms_per_pass"]), f"refit {out['motion_refit_ms_per_pass']}")


def check_passes_vcm(bench):
    """passes --estimator vcm --vcm-techniques pt+lt: the variant names the weighted pair, the
    rates are positive, the stage times null (VCM has no profile yet, docs/vcm.md)."""
    out = run(bench, "passes", "--width", "32", "--height", "32", "--photons", "4096",
              "--passes", "2", "--warmup", "1", "--scene", "caustic", "--estimator", "vcm",
              "--vcm-techniques", "pt+lt", "--json")
    if out is None:
        return
    variant = out["variant"].split(",")
    check("estimator=vcm" in variant and "vcm=pt+lt" in variant, f"vcm variant {out['variant']}")
    check(out["vcm_techniques"] == "pt+lt", f"vcm techniques {out.get('vcm_techniques')}")
    for key in ("passes_per_second", "rays_per_second"):
        check(positive(out.get(key)), f"vcm passes {key} = {out.get(key)}")
    check(out["stage_ms"] is None, f"vcm stage times {out['stage_ms']}")


def check_render_passes(bench):
    """--render-passes: the variant names them and every pass's films add to the bytes per
    pixel (32 each, Direct 32 with sampled direct light: 9 passes, 288 bytes). The plain run
    has light tracing off, as the light split's passes turn it off (its splats are 48 bytes
    a pixel of their own)."""
    plain = run(bench, "passes", "--width", "32", "--height", "32", "--photons", "4096",
                "--passes", "2", "--warmup", "1", "--scene", "caustic", "--light-tracing", "off",
                "--json")
    every = run(bench, "passes", "--width", "32", "--height", "32", "--photons", "4096",
                "--passes", "2", "--warmup", "1", "--scene", "caustic", "--render-passes",
                "all", "--json")
    if plain is None or every is None:
        return
    check("passes=" not in plain["variant"], f"no-pass variant {plain['variant']}")
    check("passes=depth+normal" in every["variant"], f"all-pass variant {every['variant']}")
    extra = every["gpu_bytes_per_pixel"] - plain["gpu_bytes_per_pixel"]
    check(extra == 9 * 32, f"render passes' bytes per pixel {extra}")
    check(positive(every.get("passes_per_second")), f"render passes {every}")


def check_passes_two_workers(bench):
    """PPPM with two workers on device 0 (two contexts; on llvmpipe one device is all
    there is): the passes are shared, each worker reports its own passes per second."""
    out = run(bench, "passes", "--width", "32", "--height", "32", "--photons", "4096",
              "--passes", "6", "--warmup", "2", "--estimator", "pppm", "--device", "0,0",
              "--against-one-device", "--json")
    if out is None:
        return
    check(out["estimator"] == "pppm", f"passes estimator {out['estimator']}")
    devices = out["devices"]
    check(len(devices) == 2, f"passes devices {devices}")
    check(sum(d["passes"] for d in devices) == 6, f"passes split {devices}")
    for d in devices:
        check(d["passes"] >= 1 and positive(d["passes_per_second"]), f"passes worker {d}")
    check(positive(out["passes_per_second"]), f"passes_per_second {out['passes_per_second']}")
    # The same 8 pass indices on one worker: the films agree to float rounding in the merge
    # (each worker's mean weighted by its passes; measured 1e-7 relative at most).
    one = out["one_device"]
    check(positive(one["passes_per_second"]) and positive(one["speedup"]), f"one device {one}")
    check(one["max_difference_relative"] < 1e-5,
          f"two workers' film against one worker's: {one['max_difference_relative']:.3g} relative")


def check_rays(bench):
    out = run(bench, "rays", "--rays", "16k", "--batches", "1", "--scenes",
              "cornell,million:3k", "--leaf", "1,8", "--json")
    if out is None:
        return
    rows = out["results"]
    check(len(rows) == 8, f"rays: {len(rows)} rows, expected 2 scenes x 2 leaves x 2 layouts")
    for row in rows:
        name = f"rays {row['scene']} {row['layout']} leaf {row['leaf_size']}"
        for mode in ("primary", "shadow", "incoherent"):
            m = row[mode]
            check(positive(m["rays_per_second"]), f"{name} {mode} rate {m['rays_per_second']}")
            check(m["checked"] >= 500, f"{name} {mode}: only {m['checked']} rays checked")
            check(m["agreement"] == 1.0, f"{name} {mode}: GPU/CPU agreement {m['agreement']}")
            # The counted dispatch: every sampled ray visits exactly the nodes and triangles
            # that TraversalCounts counts on the CPU for it (a wrong order choice shows here:
            # with the sign of bvh_select_order flipped, 35 to 90% of rays agreed).
            check(m["count_checked"] >= 500, f"{name} {mode}: {m['count_checked']} counts checked")
            check(m["count_agreement"] == 1.0,
                  f"{name} {mode}: GPU/CPU node counts agree on {m['count_agreement']:.4f}")
            check(positive(m["nodes_per_ray"]) and positive(m["triangles_per_ray"]),
                  f"{name} {mode}: work per ray {m['nodes_per_ray']}, {m['triangles_per_ray']}")
    million = [r for r in rows if r["scene"] == "million:3k"]
    check(all(2900 <= r["triangles"] <= 3300 for r in million),
          f"million:3k triangles {[r['triangles'] for r in million]}")
    check(out["agreement_min"] == 1.0, f"rays agreement_min {out['agreement_min']}")
    check(out["count_agreement_min"] == 1.0,
          f"rays count_agreement_min {out['count_agreement_min']}")


def check_mtbvh_visits(bench):
    """The MTBVH's point: incoherent rays visit fewer nodes than through the single-order
    TBVH of the same tree, counted on the GPU."""
    out = run(bench, "rays", "--rays", "16k", "--batches", "1", "--repeat", "1", "--scenes",
              "million:100k", "--leaf", "4", "--json")
    if out is None:
        return
    rows = {r["layout"]: r["incoherent"] for r in out["results"]}
    mtbvh, tbvh = rows["mtbvh"], rows["tbvh"]
    ratio = mtbvh["nodes_per_ray"] / tbvh["nodes_per_ray"]
    print(f"  incoherent nodes per ray: MTBVH {mtbvh['nodes_per_ray']:.2f}, "
          f"TBVH {tbvh['nodes_per_ray']:.2f}, ratio {ratio:.4f}")
    # Measured on llvmpipe: 35.46 / 39.73 = 0.8925 (16k rays; 0.8898 with 64k, so the ray
    # sample moves it by ~0.003). With bvh_select_order's sign flipped (far child first):
    # 45.14 / 39.73 = 1.136. The bound leaves 0.03 for noise and small BVH build changes.
    check(ratio < 0.92, f"MTBVH/TBVH incoherent nodes per ray {ratio:.4f}, expected < 0.92")
    for layout, m in rows.items():
        check(m["count_agreement"] == 1.0,
              f"million:100k {layout} incoherent: GPU/CPU counts agree on {m['count_agreement']}")


def cycles_reference(bench, work):
    """A 24x24 Cycles render of the diffuse Cornell box (scripts/cycles_reference.py), or
    None (a failure recorded) where it cannot be made."""
    if shutil.which("blender") is None:
        check(False, "Cycles cross-check cannot run: no `blender` on PATH (Debian: apt-get "
                     "install blender); it is part of this test, not optional")
        return None
    out = os.path.join(work, "cycles_cornell_diffuse_24.exr")
    script = os.path.join(ROOT, "scripts", "cycles_reference.py")
    env = dict(os.environ, PYTHONPATH=os.path.dirname(bench))
    start = time.monotonic()
    result = subprocess.run(["blender", "-b", "--factory-startup", "--python", script, "--",
                             "--out", out, "--size", "24", "--samples", CYCLES_SAMPLES],
                            capture_output=True, text=True, timeout=300, env=env)
    print(f"cycles_reference: {time.monotonic() - start:.1f} s")
    check(result.returncode == 0 and os.path.exists(out),
          f"cycles_reference.py failed: {result.stdout[-500:]} {result.stderr[-500:]}")
    return out if os.path.exists(out) else None


# The Cycles cross-check, measured on llvmpipe with Blender 3.4.1 (24x24, against 16,384
# Cycles samples; bias = SPPM mean / Cycles mean - 1 over the image and over a 4x4 grid of
# 6x6-pixel regions):
#   SPPM 256 passes x 8192 photons:  mean -0.49%, regions to -4.7% (the corners), RMSE 0.056
#   SPPM 1024 x 8192:                mean -0.74%, regions to -2.1%,                RMSE 0.032
#   SPPM 4096 x 8192 (34 s):         mean -0.06%, regions to -1.1%,                RMSE 0.016
# The corner regions darken by SPPM's finite-radius bias (a gather disc reaching past the
# corner finds no photons there), which shrinks with the radius as passes accumulate: too
# few passes, not a wrong answer. Cycles' own noise is small: 1024 samples are within 0.02%
# of 16,384 in the mean and 0.5% in every region (256 samples: 0.9%). With 4096 passes and
# 1024 samples, against each other: mean -0.04%, regions to 1.3%, RMSE 0.017.
CYCLES_SAMPLES = "1024"
REFERENCE_PASSES = "4096"
CROSS_MEAN_BOUND = 0.015    # |mean relative error|: "matches Cycles to 1.5%"
CROSS_REGION_BOUND = 0.03   # |bias| of every region: twice the mean's, for the region noise
CROSS_RMSE_BOUND = 0.035    # per-pixel, twice the measured 0.017


def check_converge(bench, work):
    cycles = cycles_reference(bench, work)
    reference = os.path.join(work, "converge_reference.exr")
    common = ["converge", "--scene", "cornell-diffuse", "--size", "24", "--reference", reference,
              "--reference-passes", REFERENCE_PASSES, "--reference-photons", "8192"]
    out = run(bench, *common, "--passes", "32", "--photons", "4096", "--json")
    if out is None:
        return
    check(out["reference"]["created"] is True, "converge did not render its reference")
    run_ = out["runs"][0]
    points = run_["points"]
    check([p["passes"] for p in points] == [1, 2, 4, 8, 16, 32],
          f"converge checkpoints {[p['passes'] for p in points]}")
    check(all(positive(p["rmse"]) and positive(p["rel_mse"]) for p in points),
          "converge errors not positive")
    check(all(b["seconds"] >= a["seconds"] for a, b in zip(points, points[1:])),
          "converge wall time not increasing")
    # Error falls with passes: the fitted MSE slope is negative and the last RMSE is below
    # the first by more than noise (measured here: slope -0.63, RMSE 0.82 -> 0.16).
    check(run_["slope"] < -0.2, f"converge slope {run_['slope']}")
    check(points[-1]["rmse"] < 0.7 * points[0]["rmse"], f"converge rmse {points}")
    check(positive(out["automatic_radius"]), f"automatic radius {out['automatic_radius']}")

    # Reused, with two settings, checked against Cycles; a reference of another size is
    # refused by name.
    extra = ["--cross-check", cycles] if cycles else []
    out = run(bench, *common, "--passes", "4", "--photons", "4096", "--radius-scale", "0.5,2",
              *extra, "--json")
    if out is not None:
        check(out["reference"]["created"] is False, "converge rendered its reference again")
        radii = [r["initial_radius"] for r in out["runs"]]
        check(len(radii) == 2 and abs(radii[1] / radii[0] - 4.0) < 1e-3,
              f"radius scales 0.5, 2 gave radii {radii}")
        if cycles:
            # Two independent renderers; the bounds and their measurements are above
            # CYCLES_SAMPLES. A 1% error of the whole image is inside the 1.5% mean bound
            # here (the reference's own noise is a few tenths of a percent); the furnace
            # (check_furnace) is the check that a 1% bias fails. A film 2% too bright (a
            # copy of resolve_film.comp scaled by 1.02) measured mean +1.96%, and fails.
            cross = out["cross_check"]
            regions = cross["region_bias"]
            worst = max(regions, key=abs)
            print(f"  SPPM against Cycles: mean {100 * cross['mean_bias']:+.2f}%, worst region "
                  f"{100 * worst:+.2f}% of {len(regions)}, RMSE {cross['rmse']:.4f}")
            check(abs(cross["mean_bias"]) < CROSS_MEAN_BOUND,
                  f"SPPM reference against Cycles: mean off by {100 * cross['mean_bias']:+.2f}%"
                  f" (bound {100 * CROSS_MEAN_BOUND}%)")
            check(len(regions) == 16 and abs(worst) < CROSS_REGION_BOUND,
                  f"SPPM reference against Cycles: a region off by {100 * worst:+.2f}% (bound "
                  f"{100 * CROSS_REGION_BOUND}%): {[round(r, 4) for r in regions]}")
            check(cross["rmse"] < CROSS_RMSE_BOUND, f"SPPM reference against Cycles: {cross}")
    message = run(bench, "converge", "--scene", "cornell-diffuse", "--size", "16",
                  "--reference", reference, "--passes", "2", "--json", expect_failure=True)
    check("24x24" in message and "16x16" in message, f"size mismatch message: {message}")


def check_furnace(bench):
    """Convergence to the right answer, not only towards our own reference: inside the
    closed furnace every pixel's exact radiance under a Total of 16 (Cycles' rule: 17
    scatters, docs/bounces.md) is Le (1 - a^18) / (1 - a) = 1.999992."""
    out = run(bench, "converge", "--scene", "furnace", "--size", "16", "--passes", "1024",
              "--photons", "16384", "--json")
    if out is None:
        return
    ref = out["reference"]
    check(ref["source"] == "analytic" and abs(ref["value"] - 2 * (1 - 2 ** -18)) < 1e-6,
          f"furnace reference {ref}")
    last = out["runs"][0]["points"][-1]
    print(f"  furnace after {last['passes']} passes: mean {100 * last['mean_bias']:+.3f}%, "
          f"RMSE {last['rmse']:.4f}")
    # Measured (four seeds, 1024 passes x 16384 photons, 16x16): mean bias -0.01, +0.08,
    # -0.08, -0.17%, RMSE 0.036-0.038 (1.9% of L per pixel). The mean bound 0.5% is about
    # five of those spreads, and a renderer 1% too bright or dark lands at 0.8% or more and
    # fails (the film scaled by 1.01 and by 0.99 in a copy of resolve_film.comp: +0.99%
    # and -1.01%, both fail). It cannot be much tighter at this cost: the image starts dark
    # and catches up with passes (4096 photons: -19% after one pass, -3.1% after 16, -1.2%
    # after 128, -0.5% after 256), most likely the photons of paths still in flight, whose
    # emission is already counted. The RMSE bound checks convergence, not bias: noise and
    # bias add in quadrature, and 1% bias alone is only 0.02.
    check(abs(last["mean_bias"]) < 0.005,
          f"furnace: image mean off the exact radiance by {100 * last['mean_bias']:+.3f}% "
          f"(bound 0.5%)")
    check(last["rmse"] < 0.05, f"furnace: RMSE {last['rmse']} against the exact radiance")


def check_specialize(bench):
    out = run(bench, "specialize", "--width", "16", "--height", "16", "--photons", "2048",
              "--passes", "2", "--rounds", "1", "--json")
    if out is None:
        return
    for key in ("specialized_passes_per_second", "full_passes_per_second", "speedup"):
        check(positive(out.get(key)), f"specialize {key} = {out.get(key)}")
    # The diffuse Cornell box compiles neither glass nor textures; the full variant does.
    check("textures" not in out["specialized_variant"].split(","), out["specialized_variant"])
    check("textures" in out["full_variant"].split(","), out["full_variant"])
    # Same seed, two passes: the images agree far inside the noise.
    check(out["max_image_difference_relative"] < 0.05, f"specialize images {out}")
    # Each row the diffuse box does not need, forced alone into its programs: one object a
    # row, with both speeds.
    lines = run_lines(bench, "specialize", "--each", "--width", "16", "--height", "16",
                      "--photons", "2048", "--passes", "1", "--rounds", "1", "--json")
    if lines is None:
        return
    rows = {line["row"]: line for line in lines}
    for name in ("textures", "spot-lights", "rough-lobes", "depth-of-field"):
        check(name in rows, f"specialize --each measured no {name}: {sorted(rows)}")
    check("area-lights" not in rows, "specialize --each forced a row the box needs")
    check("(control)" in rows, "specialize --each printed no control")
    for line in rows.values():
        check(positive(line["base_passes_per_second"]) and
              positive(line["forced_passes_per_second"]), f"specialize --each {line}")


def check_restart(bench):
    out = run(bench, "restart", "--scene", "cornell", "--width", "32", "--height", "24",
              "--photons", "1024", "--moves", "4", "--json")
    if out is None:
        return
    for key in ("camera_restart_seconds_median", "table_update_seconds_median",
                "rebuild_seconds_median"):
        check(positive(out.get(key)), f"restart {key} = {out.get(key)}")
    # Every move went through set_camera and every edit through update_tables.
    check(out["camera_updates"] == 4 and out["table_updates"] == 4, f"restart counts {out}")


def check_longrun(bench):
    out = run(bench, "longrun", "--passes", "1000", "--photons", "64")
    if out is None:
        return
    check(out["ok"] and not out["failures"], f"longrun failures {out['failures']}")
    check(out["photons_emitted"] == 1000 * 64, f"longrun photons {out['photons_emitted']}")


def check_furnace_pppm(bench):
    """PPPM in the same furnace. Its passes trace whole paths, so there is no start-up
    darkening (SPPM's -19% after one pass): measured +1.2% after 1 pass (noise), -0.48%
    after 32, -0.22% after 128 (16x16, 16384 photons, seed 1; RMSE 0.049); the mean's noise
    at 128 passes is about 0.15% (per-pixel RMSE 2.5% over 768 values). A 1% bias fails the
    0.5% bound."""
    out = run(bench, "converge", "--scene", "furnace", "--size", "16", "--passes", "128",
              "--photons", "16384", "--estimator", "pppm", "--json")
    if out is None:
        return
    run_ = out["runs"][0]
    check(run_["estimator"] == "pppm", f"furnace estimator {run_['estimator']}")
    last = run_["points"][-1]
    print(f"  pppm furnace after {last['passes']} passes: mean {100 * last['mean_bias']:+.3f}%, "
          f"RMSE {last['rmse']:.4f}")
    check(abs(last["mean_bias"]) < 0.005,
          f"pppm furnace: image mean off the exact radiance by {100 * last['mean_bias']:+.3f}% "
          f"(bound 0.5%)")
    check(last["rmse"] < 0.06, f"pppm furnace: RMSE {last['rmse']} against the exact radiance")


def check_refit(bench):
    """Refit, rebuild and motion-aware trees of a rippling mesh (issue 32): unmoved, the
    refitted and motion-aware trees are the built tree box for box, so every ray visits the
    same nodes in all three; rippled, the motion-aware tree on a step is the refitted one and
    between steps never tighter."""
    rows = run_lines(bench, "refit", "--triangles", "2000", "--rays", "4000",
                     "--amplitudes", "0,0.3", "--json")
    if rows is None:
        return
    check(len(rows) == 4, f"refit: {len(rows)} rows for 2 amplitudes x 2 times")
    for row in rows:
        nodes = row["nodes_per_ray"]
        check(row["rebuild_ms"] > 0 and row["host_refit_ms"] >= 0, f"refit: times {row}")
        if row["amplitude"] == 0:
            check(nodes["rebuilt"] == nodes["refitted"] == nodes["motion_aware"],
                  f"refit: unmoved trees visit different nodes {nodes}")
        elif row["t"] == 1.0:
            check(nodes["motion_aware"] == nodes["refitted"],
                  f"refit: on a step the motion-aware tree is not the refitted one {nodes}")
        else:
            check(nodes["motion_aware"] >= nodes["refitted"] > nodes["rebuilt"],
                  f"refit: between steps nodes visited out of order {nodes}")


def main():
    if len(sys.argv) < 2:
        print(__doc__)
        return 2
    bench = os.path.abspath(sys.argv[1])
    os.environ.setdefault("GLSLPPM_SHADER_DIR", os.path.abspath(os.path.join(ROOT, "shaders")))
    with tempfile.TemporaryDirectory(prefix="glslppm-bench-") as tmp:
        work = sys.argv[2] if len(sys.argv) > 2 else tmp
        os.makedirs(work, exist_ok=True)
        start = time.monotonic()
        check_bvh(bench)
        check_rng(bench)
        check_passes(bench)
        check_passes_vcm(bench)
        check_render_passes(bench)
        check_passes_two_workers(bench)
        check_rays(bench)
        check_mtbvh_visits(bench)
        check_converge(bench, work)
        check_furnace(bench)
        check_furnace_pppm(bench)
        check_specialize(bench)
        check_restart(bench)
        check_longrun(bench)
        check_refit(bench)
        print(f"test-bench: {time.monotonic() - start:.1f} s, {len(FAILURES)} failures")
    return 1 if FAILURES else 0


if __name__ == "__main__":
    sys.exit(main())
