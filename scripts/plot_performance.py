#!/usr/bin/env python3
"""Plots and tables of glslppm-bench results (docs/performance.md).

    scripts/plot_performance.py RESULTS_DIR --out docs/performance/NAME [--tables]

Reads every .json (one object) and .jsonl (one object per line) file under RESULTS_DIR:
`rays` results become bars of rays/s, MTBVH against TBVH by leaf size, one panel per scene
and ray kind (rays.png); each `converge` file becomes a log-log plot of MSE against passes
and against seconds, one line per setting with its fitted slope (converge_<file>.png);
`passes` results in files named triangles/resolution/photons .jsonl become scaling curves
of time per pass and GPU memory (scaling.png). --tables prints the same numbers as
Markdown tables. Needs python3-matplotlib (scripts/install-deps.sh bench).
"""

import argparse
import json
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

MODES = ("primary", "shadow", "incoherent")
SETTING_KEYS = ("alpha", "photons_per_pass", "radius_scale", "hash", "rng")


def load(root):
    """{path relative to root: [objects]} for every JSON file under root."""
    found = {}
    for folder, _, files in os.walk(root):
        for name in sorted(files):
            path = os.path.join(folder, name)
            if name.endswith(".json"):
                with open(path) as f:
                    text = f.read().strip()
                objects = [json.loads(text)] if text else []
            elif name.endswith(".jsonl"):
                with open(path) as f:
                    objects = [json.loads(line) for line in f if line.strip()]
            else:
                continue
            found[os.path.relpath(path, root)] = objects
    return found


def by_bench(found, bench):
    return {path: [o for o in objects if o.get("bench") == bench]
            for path, objects in found.items()
            if any(o.get("bench") == bench for o in objects)}


# --- rays -------------------------------------------------------------------------------

def rays_rows(found):
    return [row for objects in by_bench(found, "rays").values() for o in objects
            for row in o["results"]]


def plot_rays(rows, out):
    scenes = list(dict.fromkeys(r["scene"] for r in rows))
    fig, axes = plt.subplots(len(MODES), len(scenes), figsize=(4 * len(scenes), 8),
                             squeeze=False)
    for col, scene in enumerate(scenes):
        mine = [r for r in rows if r["scene"] == scene]
        leaves = sorted({r["leaf_size"] for r in mine})
        for row_index, mode in enumerate(MODES):
            ax = axes[row_index][col]
            for k, layout in enumerate(("mtbvh", "tbvh")):
                values = [next((r[mode]["rays_per_second"] / 1e6 for r in mine
                                if r["layout"] == layout and r["leaf_size"] == leaf), 0.0)
                          for leaf in leaves]
                ax.bar([i + 0.4 * k - 0.2 for i in range(len(leaves))], values, width=0.4,
                       label=layout.upper())
            ax.set_xticks(range(len(leaves)), [str(leaf) for leaf in leaves])
            ax.set_title(f"{scene} ({mine[0]['triangles']:,} tri): {mode}", fontsize=9)
            ax.set_xlabel("leaf size")
            ax.set_ylabel("Mrays/s")
            ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "rays.png"), dpi=110)
    plt.close(fig)


def table_rays(rows):
    print("| scene | triangles | leaf | layout | primary Mrays/s | shadow Mrays/s "
          "| incoherent Mrays/s | GPU = CPU |")
    print("|---|---|---|---|---|---|---|---|")
    for r in sorted(rows, key=lambda r: (r["scene"], r["leaf_size"], r["layout"])):
        agreement = min(r[m]["agreement"] for m in MODES)
        checked = sum(r[m]["checked"] for m in MODES)
        print(f"| {r['scene']} | {r['triangles']:,} | {r['leaf_size']} | {r['layout'].upper()} | "
              + " | ".join(f"{r[m]['rays_per_second'] / 1e6:,.2f}" for m in MODES)
              + f" | {100 * agreement:.2f}% of {checked:,} |")
    print()
    print("| scene | leaf | MTBVH / TBVH primary | shadow | incoherent |")
    print("|---|---|---|---|---|")
    for r in sorted(rows, key=lambda r: (r["scene"], r["leaf_size"])):
        if r["layout"] != "mtbvh":
            continue
        t = next((x for x in rows if x["scene"] == r["scene"] and x["layout"] == "tbvh"
                  and x["leaf_size"] == r["leaf_size"]), None)
        if t is None:
            continue
        ratios = [r[m]["rays_per_second"] / max(t[m]["rays_per_second"], 1e-9) for m in MODES]
        print(f"| {r['scene']} | {r['leaf_size']} | "
              + " | ".join(f"{x:.2f}x" for x in ratios) + " |")
    print()


# --- converge ---------------------------------------------------------------------------

def varying(runs):
    return [k for k in SETTING_KEYS if len({str(r[k]) for r in runs}) > 1] or ["alpha"]


def run_label(run, keys):
    names = {"alpha": "α", "photons_per_pass": "photons", "radius_scale": "radius ×"}
    parts = []
    for k in keys:
        value = run[k]
        if isinstance(value, float):
            value = f"{value:.3g}"
        parts.append(f"{names.get(k, k)} {value}" if k in names else str(value))
    return ", ".join(parts) + f" (slope {run['slope']:.2f})"


def plot_converge(path, result, out):
    runs = result["runs"]
    keys = varying(runs)
    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4.2))
    for run in runs:
        passes = [p["passes"] for p in run["points"]]
        mse = [p["rmse"] ** 2 for p in run["points"]]
        seconds = [max(p["seconds"], 1e-6) for p in run["points"]]
        label = run_label(run, keys)
        left.loglog(passes, mse, marker="o", ms=3, label=label)
        right.loglog(seconds, mse, marker="o", ms=3, label=label)
    first = runs[0]["points"]
    if first:
        # The theoretical slope of the first setting, through its first fitted point.
        anchor = next((p for p in first if p["passes"] >= result["fit_from"]), first[0])
        slope = runs[0]["theoretical_slope"]
        xs = [anchor["passes"], first[-1]["passes"]]
        left.loglog(xs, [anchor["rmse"] ** 2 * (x / xs[0]) ** slope for x in xs], "k--",
                    lw=1, label=f"theory {slope:.2f}")
    left.set_xlabel("passes")
    right.set_xlabel("seconds (render time)")
    for ax in (left, right):
        ax.set_ylabel("MSE against the reference")
        ax.grid(True, which="both", alpha=0.3)
    left.legend(fontsize=7)
    ref = result["reference"]
    fig.suptitle(f"{result['scene']} {result['width']}x{result['height']}, "
                 f"reference {ref['source']} {ref['passes']:,} passes — {result['renderer']}",
                 fontsize=9)
    fig.tight_layout()
    name = os.path.splitext(os.path.basename(path))[0]
    name = name[len("converge_"):] if name.startswith("converge_") else name
    fig.savefig(os.path.join(out, f"converge_{name}.png"), dpi=110)
    plt.close(fig)


def rmse_at(run, seconds):
    """RMSE at a render time, interpolated linearly in log MSE against log seconds."""
    points = [p for p in run["points"] if p["seconds"] > 0 and p["rmse"] > 0]
    for a, b in zip(points, points[1:]):
        if a["seconds"] <= seconds <= b["seconds"]:
            if b["seconds"] == a["seconds"]:
                return b["rmse"]
            f = math.log(seconds / a["seconds"]) / math.log(b["seconds"] / a["seconds"])
            return math.exp((1 - f) * math.log(a["rmse"]) + f * math.log(b["rmse"]))
    return points[-1]["rmse"] if points and seconds >= points[-1]["seconds"] else float("nan")


def table_converge(path, result):
    runs = result["runs"]
    # The same wall time for every setting: the shortest of their total render times.
    same_time = min(r["points"][-1]["seconds"] for r in runs)
    print(f"`{path}`: {result['scene']} {result['width']}x{result['height']}, reference "
          f"{result['reference']['source']} {result['reference']['passes']:,} passes"
          + (f"; reference against {os.path.basename(result['cross_check']['path'])}: RMSE "
             f"{result['cross_check']['rmse']:.4f}, relative MSE "
             f"{result['cross_check']['rel_mse']:.4f}" if "cross_check" in result else ""))
    print()
    print("| α | photons/pass | radius × | hash | rng | slope (fit) | slope (theory) | passes "
          f"| seconds | RMSE | rel. MSE | RMSE at {same_time:.3g} s |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for r in runs:
        last = r["points"][-1]
        print(f"| {r['alpha']:.3g} | {r['photons_per_pass']:,} | {r['radius_scale']:.3g} | "
              f"{r['hash']} | {r['rng']} | {r['slope']:.3f} | {r['theoretical_slope']:.3f} | "
              f"{last['passes']:,} | {last['seconds']:.2f} | {last['rmse']:.4f} | "
              f"{last['rel_mse']:.4f} | {rmse_at(r, same_time):.4f} |")
    print()


# --- scaling ----------------------------------------------------------------------------

SCALING = {"triangles": ("triangles", "triangles"),
           "resolution": ("pixels", lambda o: o["width"] * o["height"]),
           "photons": ("photons per pass", "photons_per_pass")}


def scaling_series(found):
    series = {}
    for path, objects in by_bench(found, "passes").items():
        kind = os.path.splitext(os.path.basename(path))[0]
        if kind in SCALING:
            series[kind] = objects
    return series


def x_of(kind, o):
    key = SCALING[kind][1]
    return key(o) if callable(key) else o[key]


def plot_scaling(series, out):
    fig, axes = plt.subplots(2, len(series), figsize=(4.2 * len(series), 7), squeeze=False)
    for col, (kind, objects) in enumerate(sorted(series.items())):
        xs = [x_of(kind, o) for o in objects]
        top, bottom = axes[0][col], axes[1][col]
        top.loglog(xs, [1e3 / o["passes_per_second"] for o in objects], "o-", label="pass")
        for stage in ("eye", "photon", "hash", "gather"):
            top.loglog(xs, [max(o["stage_ms"][stage], 1e-4) for o in objects], ".--", lw=1,
                       label=stage)
        top.set_ylabel("ms per pass")
        top.legend(fontsize=7)
        bottom.loglog(xs, [o["gpu_bytes"] / 2**20 for o in objects], "s-")
        bottom.set_ylabel("GPU buffers (MiB)")
        for ax in (top, bottom):
            ax.set_xlabel(SCALING[kind][0])
            ax.grid(True, which="both", alpha=0.3)
    fig.suptitle(objects[0]["renderer"], fontsize=9)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "scaling.png"), dpi=110)
    plt.close(fig)


def table_scaling(series):
    for kind, objects in sorted(series.items()):
        print(f"| {SCALING[kind][0]} | passes/s | ms/pass | eye | photon | hash | gather "
              "| GPU MiB | photon paths/s |")
        print("|---|---|---|---|---|---|---|---|---|")
        for o in objects:
            s = o["stage_ms"]
            print(f"| {x_of(kind, o):,} | {o['passes_per_second']:,.1f} | "
                  f"{1e3 / o['passes_per_second']:.3f} | {s['eye']:.3f} | {s['photon']:.3f} | "
                  f"{s['hash']:.3f} | {s['gather']:.3f} | {o['gpu_bytes'] / 2**20:,.1f} | "
                  f"{o['photons_per_second'] / 1e6:,.3f} M |")
        print()


def table_passes(found):
    rows = [o for path, objects in by_bench(found, "passes").items()
            if os.path.splitext(os.path.basename(path))[0] not in SCALING for o in objects]
    if not rows:
        return
    print("| scene | resolution | photons/pass | hash | rng | passes/s | photon paths/s "
          "| rays/s | eye / photon / hash / gather ms |")
    print("|---|---|---|---|---|---|---|---|---|")
    for o in rows:
        s = o["stage_ms"]
        print(f"| {o['scene']} ({o.get('triangles', 0):,} tri) | {o['width']}² | "
              f"{o['photons_per_pass']:,} | {o['hash']} | {o['rng']} | "
              f"{o['passes_per_second']:,.2f} | {o['photons_per_second'] / 1e6:,.3f} M | "
              f"{o['rays_per_second'] / 1e6:,.2f} M | {s['eye']:.2f} / {s['photon']:.2f} / "
              f"{s['hash']:.2f} / {s['gather']:.2f} |")
    print()


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("results", help="folder of glslppm-bench JSON files")
    parser.add_argument("--out", required=True, help="folder for the PNG files")
    parser.add_argument("--tables", action="store_true", help="print Markdown tables")
    args = parser.parse_args()
    found = load(args.results)
    if not found:
        sys.exit(f"plot_performance: no .json or .jsonl files under {args.results}")
    os.makedirs(args.out, exist_ok=True)
    rows = rays_rows(found)
    if rows:
        plot_rays(rows, args.out)
        if args.tables:
            table_rays(rows)
    for path, objects in sorted(by_bench(found, "converge").items()):
        for result in objects:
            plot_converge(path, result, args.out)
            if args.tables:
                table_converge(path, result)
    series = scaling_series(found)
    if series:
        plot_scaling(series, args.out)
        if args.tables:
            table_scaling(series)
    if args.tables:
        table_passes(found)
    print(f"plot_performance: wrote {sorted(os.listdir(args.out))} to {args.out}",
          file=sys.stderr)


if __name__ == "__main__":
    main()
