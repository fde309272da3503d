#!/usr/bin/env python3
"""Equal-time error of the two direct-light modes from `glslppm-bench converge --direct
sampled,photons --json` output (docs/direct_light.md).

Each run's RMSE is interpolated in log-log against the time spent after its first pass
(that pass also pays for compiling the programs on the first dispatch, which a long render
amortises), at the longest time both runs reached. Prints one line per (scene, settings)
pair: the time, both RMSEs, RMSE(sampled) / RMSE(photons) and the time photons would need
for sampled's error, assuming MSE ~ 1 / time (Monte Carlo), as "speed-up".
"""
import json
import math
import sys


def rmse_at(points, t):
    """log-log interpolation of RMSE at time t (seconds after the first pass)."""
    base = points[0]["seconds"]
    xs = [(p["seconds"] - base, p["rmse"]) for p in points[1:] if p["seconds"] > base]
    for (t0, e0), (t1, e1) in zip(xs, xs[1:]):
        if t0 <= t <= t1:
            a = (math.log(t) - math.log(t0)) / (math.log(t1) - math.log(t0))
            return math.exp((1 - a) * math.log(e0) + a * math.log(e1))
    raise ValueError(f"time {t} outside the run's range {xs[0][0]}..{xs[-1][0]}")


def main(paths):
    for path in paths:
        with open(path) as f:
            data = json.load(f)
        runs = {r["direct_light"]: r for r in data["runs"]}
        if set(runs) != {"sampled", "photons"}:
            raise SystemExit(f"{path}: needs one run of each direct-light mode")
        s, p = runs["sampled"]["points"], runs["photons"]["points"]
        t = min(s[-1]["seconds"] - s[0]["seconds"], p[-1]["seconds"] - p[0]["seconds"])
        es, ep = rmse_at(s, t), rmse_at(p, t)
        per_pass = {k: (r["points"][-1]["seconds"] - r["points"][0]["seconds"]) /
                    (r["points"][-1]["passes"] - 1) for k, r in runs.items()}
        print(f"{data['scene']:16s} {data['width']}x{data['height']} "
              f"{runs['sampled']['photons_per_pass']} photons/pass: at {t:.2f} s "
              f"RMSE sampled {es:.5f}, photons {ep:.5f}, ratio {es / ep:.3f}, "
              f"speed-up {(ep / es) ** 2:.2f}x; ms/pass sampled {1e3 * per_pass['sampled']:.1f}, "
              f"photons {1e3 * per_pass['photons']:.1f}")


if __name__ == "__main__":
    main(sys.argv[1:])
