#!/usr/bin/python3
"""The equal-cost harness (issue 28 item 4, docs/equal_cost.md): glslppm's estimators against
Cycles at equal CPU-seconds, scored by relative RMSE against a converged reference.

Plain Python (with numpy: /usr/bin/python3 here); each render runs as its own
`nice blender -b --factory-startup --python scripts/equal_cost_render.py -- ...` process,
one at a time. Steps, each resumable (results already in the work folder are reused):

    scripts/equal_cost.py reference --scene caustic --count 40000 [--method cycles]
    scripts/equal_cost.py calibrate --scene caustic --methods sppm,pppm,cycles,cycles-mnee
    scripts/equal_cost.py measure   --scene caustic --methods sppm,pppm,cycles,cycles-mnee \\
                                    --budgets 30,120,480
    scripts/equal_cost.py table     --scenes caustic,cornell [--json docs/equal_cost.json]
    scripts/equal_cost.py all --scene ring --reference-count 20000 --budgets 30,120  (all four)

Cost: the CPU-seconds (user + sys, all threads) the render process spends inside
bpy.ops.render.render (scene export or sync, BVH, shader compilation, every pass or sample,
film read-back): getrusage(RUSAGE_SELF) around the call, in the process. Blender's start-up,
the add-on's registration and building the scene are the rest of the child's total
(os.wait4's rusage) and are reported apart as "start-up", not counted in the budget.

Error: luminance Y = 0.2126 R + 0.7152 G + 0.0722 B per pixel;
    relative RMSE = sqrt(mean over the region's pixels of (Y - Y_ref)^2) / mean(Y_ref).
The reference is the mean of two (or more) independent renders ("halves", seeds 1001, ...).
Its own noise per pixel is estimated from their spread, var(mean) = sum((h_i - mean)^2) /
(k (k - 1)), reported as the reference's relative RMSE, and subtracted from each measured
MSE ("corrected": sqrt(max(0, MSE - mean var(mean))) / mean(Y_ref)), since
E[(x - ref)^2] = (x - truth)^2 + var(ref) for a reference independent of x.

The budget's sample or pass count comes from two calibration renders per method (a small
and a larger count): CPU-s = fixed + per_unit * count, solved for the budget.
"""

import argparse
import json
import math
import os
import subprocess
import sys
import zlib
import struct

import numpy as np

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
RENDER_SCRIPT = os.path.join(REPO, "scripts", "equal_cost_render.py")

# Per scene: named regions (x0, y0, x1, y1) as fractions of width and height, row 0 at the
# top, drawn around the caustic in the reference; and whether Cycles' MNEE applies (a
# refractive caster under a light MNEE samples; the ring's caustic is reflective).
SCENES = {
    "caustic": {"regions": {"caustic": (0.48, 0.51, 0.72, 0.65)}, "mnee": True},
    "ring": {"regions": {"cardioid": (0.40, 0.38, 0.80, 0.75)}, "mnee": False},
    "pool": {"regions": {"floor through water": (0.20, 0.25, 0.80, 0.70)}, "mnee": True},
    "point_ball": {"regions": {"caustic": (0.48, 0.51, 0.72, 0.65)}, "mnee": True},
    "cornell": {"regions": {"glass sphere caustic": (0.57, 0.76, 0.76, 0.88)}, "mnee": False},
    "showcase": {"regions": {"tea caustic": (0.31, 0.545, 0.45, 0.61),
                             "ring cardioid": (0.57, 0.565, 0.75, 0.645),
                             "blue ball caustic": (0.65, 0.445, 0.80, 0.525)}, "mnee": True},
}
CYCLES_METHODS = ("cycles", "cycles-mnee")
CALIBRATION = {"glslppm": (2, 10), "cycles": (16, 256)}  # (small, larger) counts
REFERENCE_SEED = 1001
BUDGET_TOLERANCE = 0.2  # a run more than 20% off its budget is rendered again
MAX_ATTEMPTS = 3
MEASURE_SEED = 1


def is_cycles(method):
    return method.split(":")[0] in CYCLES_METHODS


def work_dir(args, *parts):
    path = os.path.join(os.path.abspath(args.work), *parts)
    os.makedirs(os.path.dirname(path) if parts else path, exist_ok=True)
    return path


def safe(method):
    return method.replace(":", "_").replace(",", "_").replace("=", "-")


def render(args, scene, method, count, seed, out):
    """Runs one render process; returns its record with the child's total CPU-s (wait4)."""
    if os.path.exists(out + ".json") and os.path.exists(out + ".npy"):
        with open(out + ".json") as f:
            return json.load(f)
    env = dict(os.environ)
    env.setdefault("GLSLPPM_MODULE_DIR", os.path.join(REPO, "build"))
    command = ["nice", args.blender, "-b", "--factory-startup", "--python", RENDER_SCRIPT,
               "--", "--scene", scene, "--method", method, "--count", str(count),
               "--seed", str(seed), "--size", str(args.size), "--out", out]
    log = open(out + ".log", "w")
    process = subprocess.Popen(command, env=env, stdout=log, stderr=subprocess.STDOUT)
    _, status, usage = os.wait4(process.pid, 0)
    log.close()
    process.returncode = os.waitstatus_to_exitcode(status)
    if process.returncode != 0 or not os.path.exists(out + ".json"):
        with open(out + ".log") as f:
            tail = f.read()[-3000:]
        raise SystemExit(f"equal_cost: render failed ({' '.join(command)}):\n{tail}")
    with open(out + ".json") as f:
        record = json.load(f)
    record["process_cpu_s"] = usage.ru_utime + usage.ru_stime
    record["startup_cpu_s"] = record["process_cpu_s"] - record["render_cpu_s"]
    with open(out + ".json", "w") as f:
        json.dump(record, f, indent=1)
    print(f"  {scene} {method} x{count} seed {seed}: render {record['render_cpu_s']:.1f} "
          f"CPU-s, start-up {record['startup_cpu_s']:.1f} CPU-s", flush=True)
    return record


def luminance(rgb):
    return rgb[..., 0] * 0.2126 + rgb[..., 1] * 0.7152 + rgb[..., 2] * 0.0722


def region_slices(box, height, width):
    x0, y0, x1, y1 = box
    return (slice(int(round(y0 * height)), int(round(y1 * height))),
            slice(int(round(x0 * width)), int(round(x1 * width))))


def load_reference(args, scene):
    path = work_dir(args, scene, "reference.npz")
    if not os.path.exists(path):
        raise SystemExit(f"equal_cost: no reference for {scene}: run `reference` first")
    data = np.load(path)
    return data["mean"], data["var"], json.loads(str(data["info"]))


def scores(image, ref, var, regions):
    """Per region (and "whole"): relative RMSE, noise-corrected, reference noise."""
    y, y_ref = luminance(image.astype(np.float64)), luminance(ref)
    height, width = y.shape
    out = {}
    boxes = dict(regions, whole=(0.0, 0.0, 1.0, 1.0))
    for name, box in boxes.items():
        rows, cols = region_slices(box, height, width)
        d2 = (y[rows, cols] - y_ref[rows, cols]) ** 2
        mean_ref = float(y_ref[rows, cols].mean())
        mse, noise = float(d2.mean()), float(var[rows, cols].mean())
        out[name] = {"rel_rmse": mse ** 0.5 / mean_ref,
                     "rel_rmse_corrected": max(0.0, mse - noise) ** 0.5 / mean_ref,
                     "reference_rel_noise": noise ** 0.5 / mean_ref,
                     "reference_mean": mean_ref,
                     "bias": float((y[rows, cols] - y_ref[rows, cols]).mean()) / mean_ref}
    return out


def reference_from_halves(halves):
    """The reference (mean of k independent renders, RGB) and the variance of that mean's
    luminance per pixel, sum((Y_i - Y_mean)^2) / (k (k - 1))."""
    stack = np.stack([h.astype(np.float64) for h in halves])
    k = len(halves)
    mean = stack.mean(axis=0)
    var = ((luminance(stack) - luminance(mean)[None]) ** 2).sum(axis=0) / (k * (k - 1))
    return mean, var


def command_reference(args):
    halves = []
    records = []
    count = args.count // args.halves
    for k in range(args.halves):
        out = work_dir(args, args.scene, "reference", f"{safe(args.method)}_{k}")
        records.append(render(args, args.scene, args.method, count, REFERENCE_SEED + k, out))
        halves.append(np.load(out + ".npy").astype(np.float64))
    mean, var = reference_from_halves(halves)
    k = len(halves)
    info = {"method": args.method, "count": count * k, "halves": k,
            "render_cpu_s": sum(r["render_cpu_s"] for r in records)}
    np.savez(work_dir(args, args.scene, "reference.npz"), mean=mean, var=var,
             info=json.dumps(info))
    write_png(work_dir(args, args.scene, "reference.png"), mean,
              SCENES[args.scene]["regions"])
    noise = scores(mean, mean, var, SCENES[args.scene]["regions"])
    print(f"reference {args.scene}: {info}; its own relative noise: " +
          ", ".join(f"{n} {v['reference_rel_noise']:.4f}" for n, v in noise.items()))


def fit_cost(counts, costs):
    """CPU-s = fixed + per_unit * count through two (count, CPU-s) points; neither part
    negative."""
    per_unit = max((costs[1] - costs[0]) / (counts[1] - counts[0]), 1e-6)
    return {"per_unit_cpu_s": per_unit, "fixed_cpu_s": max(0.0, costs[0] - per_unit * counts[0])}


def count_for_budget(cost, budget):
    """The sample or pass count whose predicted CPU-s is the budget (at least 1)."""
    return max(1, int(round((budget - cost["fixed_cpu_s"]) / cost["per_unit_cpu_s"])))


def predict_count(cost, budget):
    """The count for a budget: from the linear fit while only the calibration's two points
    are known; once measured runs add points, a power law CPU-s = a count^b through the
    two points nearest the budget (PPPM's cost per pass grows with the pass count)."""
    points = [tuple(p) for p in cost.get("points", [])]
    if len(points) < 1:
        return count_for_budget(cost, budget)
    points = sorted([(cost["counts"][1], cost["render_cpu_s"][1])] + points)
    near = sorted(points, key=lambda p: abs(math.log(p[1] / budget)))[:2]
    (n1, c1), (n2, c2) = sorted(near)
    if n1 == n2 or c1 <= 0 or c2 <= c1:
        n, c = near[0]
        return max(1, int(round(n * budget / c)))
    b = math.log(c2 / c1) / math.log(n2 / n1)
    return max(1, int(round(n2 * (budget / c2) ** (1 / b))))


def record_point(args, scene, method, count, cpu_s):
    path = work_dir(args, scene, "calibration.json")
    table = json.load(open(path))
    points = table[method].setdefault("points", [])
    if [count, cpu_s] not in points:
        points.append([count, cpu_s])
    with open(path, "w") as f:
        json.dump(table, f, indent=1)


def calibration(args, scene, method):
    path = work_dir(args, scene, "calibration.json")
    table = json.load(open(path)) if os.path.exists(path) else {}
    if method not in table:
        small, large = CALIBRATION["cycles" if is_cycles(method) else "glslppm"]
        if not is_cycles(method):  # compiles and caches the GL programs (Mesa's cache)
            render(args, scene, method, 1, MEASURE_SEED + 99,
                   work_dir(args, scene, "calibration", f"{safe(method)}_warmup"))
        costs = []
        for count in (small, large):
            out = work_dir(args, scene, "calibration", f"{safe(method)}_{count}")
            costs.append(render(args, scene, method, count, MEASURE_SEED + 100, out)
                         ["render_cpu_s"])
        table[method] = dict(fit_cost((small, large), costs), counts=[small, large],
                             render_cpu_s=costs)
        with open(path, "w") as f:
            json.dump(table, f, indent=1)
    return table[method]


def command_calibrate(args):
    for method in args.methods:
        c = calibration(args, args.scene, method)
        print(f"calibration {args.scene} {method}: {c['fixed_cpu_s']:.2f} CPU-s fixed + "
              f"{c['per_unit_cpu_s']:.4f} per {'sample' if is_cycles(method) else 'pass'}")


def command_measure(args):
    ref, var, _ = load_reference(args, args.scene)
    regions = SCENES[args.scene]["regions"]
    for budget in args.budgets:
        for method in args.methods:
            c = calibration(args, args.scene, method)
            out = work_dir(args, args.scene, "runs", f"{safe(method)}_{budget:g}")
            for attempt in range(MAX_ATTEMPTS):
                count = predict_count(c, budget)
                record = render(args, args.scene, method, count, MEASURE_SEED, out)
                record_point(args, args.scene, method, count, record["render_cpu_s"])
                c = calibration(args, args.scene, method)
                if abs(record["render_cpu_s"] / budget - 1) <= BUDGET_TOLERANCE or \
                        attempt == MAX_ATTEMPTS - 1:
                    break
                # Off budget (a cost that is not linear in the count): kept, scored, not
                # tabled as this budget's run; the next attempt uses its cost too.
                for ext in (".json", ".npy", ".png", ".log"):
                    os.replace(out + ext, f"{out}_off{attempt}{ext}")
                print(f"  off budget ({record['render_cpu_s']:.1f} CPU-s), again", flush=True)
            record["budget"] = budget
            record["scores"] = scores(np.load(out + ".npy"), ref, var, regions)
            with open(out + ".json", "w") as f:
                json.dump(record, f, indent=1)
            s = record["scores"]
            print(f"{args.scene} {budget:g} {method} x{record['count']}: "
                  f"{record['render_cpu_s']:.1f} CPU-s, "
                  + ", ".join(f"{n} {v['rel_rmse']:.4f}" for n, v in s.items()), flush=True)


def collect(args, scene):
    folder = work_dir(args, scene, "runs")
    ref, var, info = load_reference(args, scene)
    regions = SCENES[scene]["regions"]
    runs, off_budget = [], []
    for name in sorted(os.listdir(folder)):
        if name.endswith(".json"):
            with open(os.path.join(folder, name)) as f:
                record = json.load(f)
            # Rescored, so that a newer reference or region applies to every run.
            record["scores"] = scores(np.load(os.path.join(folder, name[:-5] + ".npy")),
                                      ref, var, regions)
            if "_off" in name:
                record.pop("budget", None)
                off_budget.append(record)
            elif "budget" in record:
                runs.append(record)
    noise = scores(ref, ref, var, regions)
    return {"scene": scene, "size": runs[0]["size"] if runs else None, "reference": info,
            "reference_rel_noise": {n: v["reference_rel_noise"] for n, v in noise.items()},
            "regions": regions, "runs": runs, "off_budget_runs": off_budget}


def markdown(result):
    region = next(iter(result["regions"]))
    lines = [f"### {result['scene']} ({result['size']}², region \"{region}\")", "",
             f"Reference: {result['reference']['method']}, {result['reference']['count']} "
             f"samples/passes in {result['reference']['halves']} halves, "
             f"{result['reference']['render_cpu_s']:.0f} CPU-s; its own relative noise: "
             f"region {result['reference_rel_noise'][region]:.4f}, whole "
             f"{result['reference_rel_noise']['whole']:.4f}.", "",
             "| budget | method | count | CPU-s (render) | start-up CPU-s | region rel. RMSE "
             "(corrected) | region bias | whole rel. RMSE (corrected) |",
             "|---|---|---|---|---|---|---|---|"]
    budgets = sorted({r["budget"] for r in result["runs"]})
    ratios = []
    for budget in budgets:
        runs = sorted((r for r in result["runs"] if r["budget"] == budget),
                      key=lambda r: r["method"])
        for r in runs:
            s = r["scores"]
            lines.append(
                f"| {budget:g} | {r['method']} | {r['count']} | {r['render_cpu_s']:.1f} | "
                f"{r['startup_cpu_s']:.1f} | {s[region]['rel_rmse']:.4f} "
                f"({s[region]['rel_rmse_corrected']:.4f}) | {s[region]['bias']:+.3f} | "
                f"{s['whole']['rel_rmse']:.4f} ({s['whole']['rel_rmse_corrected']:.4f}) |")
        ours = [r["scores"][region]["rel_rmse"] for r in runs if not is_cycles(r["method"])]
        theirs = [r["scores"][region]["rel_rmse"] for r in runs if is_cycles(r["method"])]
        ours_w = [r["scores"]["whole"]["rel_rmse"] for r in runs if not is_cycles(r["method"])]
        theirs_w = [r["scores"]["whole"]["rel_rmse"] for r in runs if is_cycles(r["method"])]
        if ours and theirs:
            ratios.append(f"| {budget:g} | {min(ours):.4f} | {min(theirs):.4f} | "
                          f"{min(ours) / min(theirs):.2f} | {min(ours_w):.4f} | "
                          f"{min(theirs_w):.4f} | {min(ours_w) / min(theirs_w):.2f} |")
    for r in result["off_budget_runs"]:
        s = r["scores"]
        lines.append(f"| (off budget) | {r['method']} | {r['count']} | {r['render_cpu_s']:.1f} | "
                     f"{r['startup_cpu_s']:.1f} | {s[region]['rel_rmse']:.4f} "
                     f"({s[region]['rel_rmse_corrected']:.4f}) | {s[region]['bias']:+.3f} | "
                     f"{s['whole']['rel_rmse']:.4f} ({s['whole']['rel_rmse_corrected']:.4f}) |")
    if ratios:
        lines += ["", "| budget | glslppm best, region | Cycles best, region | ratio | "
                  "glslppm best, whole | Cycles best, whole | ratio |",
                  "|---|---|---|---|---|---|---|"] + ratios
    if len(result["regions"]) > 1:
        lines += ["", region_table(result)]
    return "\n".join(lines)


def region_table(result):
    """Every region's relative RMSE (corrected) and bias per run, for scenes with several
    regions (the table above shows the first); the reference's own noise in the header."""
    names = list(result["regions"]) + ["whole"]
    noise = result["reference_rel_noise"]
    lines = ["| budget | method | CPU-s | " + " | ".join(
                 f"{n} (ref. noise {noise[n]:.3f})" for n in names) + " |",
             "|---|---|---|" + "---|" * len(names)]
    for r in sorted(result["runs"], key=lambda r: (r["budget"], r["method"])):
        s = r["scores"]
        lines.append(f"| {r['budget']:g} | {r['method']} | {r['render_cpu_s']:.1f} | " +
                     " | ".join(f"{s[n]['rel_rmse']:.3f} ({s[n]['rel_rmse_corrected']:.3f}), "
                                f"bias {s[n]['bias']:+.3f}" for n in names) + " |")
    return "\n".join(lines)


def command_table(args):
    results = [collect(args, scene) for scene in args.scenes]
    text = "\n\n".join(markdown(r) for r in results)
    print(text)
    if args.json:
        with open(args.json, "w") as f:
            json.dump(results, f, indent=1)
    if args.markdown:
        with open(args.markdown, "w") as f:
            f.write(text + "\n")


def write_png(path, rgb, regions):
    """The image (clamped, sRGB-ish gamma) with each region outlined in red."""
    image = np.clip(rgb, 0.0, 1.0) ** (1 / 2.2)
    image = (image * 255 + 0.5).astype(np.uint8)
    height, width = image.shape[:2]
    for box in regions.values():
        rows, cols = region_slices(box, height, width)
        for r in (rows.start, rows.stop - 1):
            image[r, cols] = (255, 0, 0)
        for c in (cols.start, cols.stop - 1):
            image[rows, c] = (255, 0, 0)
    raw = b"".join(b"\0" + image[r].tobytes() for r in range(height))

    def chunk(kind, data):
        return (struct.pack(">I", len(data)) + kind + data +
                struct.pack(">I", zlib.crc32(kind + data) & 0xffffffff))
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height,
                                                                 8, 2, 0, 0, 0)) +
                chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b""))


def parse_methods(text):
    """"sppm,pppm:radius_scale=0.5,photons_per_pass=16384,cycles" -> three methods: an item
    with "=" and no ":" is one more setting of the method before it (';' also separates)."""
    methods = []
    for part in text.replace(";", ",").split(","):
        if "=" in part and ":" not in part and methods:
            methods[-1] += "," + part
        elif part:
            methods.append(part)
    return methods


def parse_args():
    parser = argparse.ArgumentParser(prog="equal_cost.py", description=__doc__.split("\n")[0])
    parser.add_argument("--work", default=os.path.join(REPO, "build", "equal_cost"),
                        help="folder for renders and results (default build/equal_cost)")
    parser.add_argument("--blender", default=os.environ.get("BLENDER", "blender"))
    parser.add_argument("--size", type=int, default=128)
    sub = parser.add_subparsers(dest="command", required=True)
    p = sub.add_parser("reference")
    p.add_argument("--scene", required=True, choices=SCENES)
    p.add_argument("--method", default="cycles")
    p.add_argument("--count", type=int, required=True, help="total over all halves")
    p.add_argument("--halves", type=int, default=2)
    for name in ("calibrate", "measure"):
        p = sub.add_parser(name)
        p.add_argument("--scene", required=True, choices=SCENES)
        p.add_argument("--methods", type=parse_methods,
                       help="comma-separated, settings after ':' (sppm:radius_scale=0.5); default "
                            "sppm, pppm, cycles and cycles-mnee where MNEE applies")
        if name == "measure":
            p.add_argument("--budgets", default="30,120,480",
                           type=lambda s: [float(b) for b in s.split(",")])
    p = sub.add_parser("all", help="reference (unless made), calibrate, measure, table")
    p.add_argument("--scene", required=True, choices=SCENES)
    p.add_argument("--reference-method", default="cycles")
    p.add_argument("--reference-count", type=int, required=True)
    p.add_argument("--halves", type=int, default=2)
    p.add_argument("--methods", type=parse_methods)
    p.add_argument("--budgets", default="30,120,480",
                   type=lambda s: [float(b) for b in s.split(",")])
    p = sub.add_parser("table")
    p.add_argument("--scenes", required=True, type=lambda s: s.split(","))
    p.add_argument("--json")
    p.add_argument("--markdown")
    return parser.parse_args()


def command_all(args):
    if not os.path.exists(work_dir(args, args.scene, "reference.npz")):
        command_reference(argparse.Namespace(**vars(args), method=args.reference_method,
                                             count=args.reference_count))
    command_calibrate(args)
    command_measure(args)
    command_table(argparse.Namespace(**vars(args), scenes=[args.scene], json=None,
                                     markdown=None))


def default_methods(scene):
    """glslppm's estimators (add vcm once the add-on has it), Cycles, and Cycles' MNEE
    where it applies."""
    return ["sppm", "pppm", "cycles"] + (["cycles-mnee"] if SCENES[scene]["mnee"] else [])


def main():
    args = parse_args()
    if getattr(args, "methods", "unset") is None:
        args.methods = default_methods(args.scene)
    {"reference": command_reference, "calibrate": command_calibrate, "all": command_all,
     "measure": command_measure, "table": command_table}[args.command](args)


if __name__ == "__main__":
    sys.exit(main())
