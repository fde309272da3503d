#!/usr/bin/env python3
"""The 200,000-pass run, for a GPU (not part of make test: at llvmpipe
speed it takes hours). Prints one JSON object and exits 1 if a check failed.

The scene is the box furnace of tests/python/test_stability.py: inside a closed box whose
walls emit Le = 1 and reflect a = 0.5, with max_bounces = 0 (direct light only, as Cycles
counts bounces) every pixel sees L = 1.5 exactly and every photon path ends after one
bounce, so photons_emitted must equal passes * photons_per_pass exactly. The default 21,504 photons per pass take the count past
2^32 (4,300,800,000 after 200,000 passes).

Checks at log-spaced checkpoints: the film is finite; passes and photons_emitted are exact;
the mean and largest radius never grow; the rms error against 1.5 keeps falling (log-log
slope over the last two decades below -0.2; measured -0.33 to -0.39 on llvmpipe with 64
photons per pass up to 1e5 passes).

    GLSLPPM_BUILD=build /usr/bin/python3 tests/long/long_run.py [--passes N] [--photons P]
"""
import argparse
import json
import math
import os
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "python"))
from conftest import native as g  # noqa: E402
from test_stability import box_furnace  # noqa: E402


def checkpoints(total, first=100, per_decade=4):
    ks, i = [], 0
    while True:
        k = int(round(first * 10 ** (i / per_decade)))
        if k >= total:
            break
        ks.append(k)
        i += 1
    return sorted(set(ks + [total]))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--passes", type=int, default=200000)
    parser.add_argument("--photons", type=int, default=21504)
    parser.add_argument("--width", type=int, default=8)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--device", type=int, default=-1)
    args = parser.parse_args()

    settings = g.Settings(width=args.width, height=args.width, photons_per_pass=args.photons,
                          max_bounces=0, seed=args.seed, device=args.device)
    r = g.Renderer(box_furnace(g), settings)
    failures, rows = [], []
    previous = r.stats()
    done, start = 0, time.time()
    for k in checkpoints(args.passes):
        r.run(k - done)
        done = k
        film = r.film()[..., :3].astype(np.float64)
        s = r.stats()
        finite = bool(np.isfinite(film).all())
        error = math.sqrt(np.mean((film - 1.5) ** 2)) if finite else float("nan")
        row = dict(passes=s["passes"], photons_emitted=s["photons_emitted"],
                   mean_radius=s["mean_radius"], max_radius=s["max_radius"],
                   rms_error=error, mean=float(film.mean()), seconds=time.time() - start)
        rows.append(row)
        if not finite:
            failures.append(f"film not finite after {k} passes")
        if s["passes"] != k:
            failures.append(f"passes {s['passes']} != {k}")
        if s["photons_emitted"] != k * args.photons:
            failures.append(f"photons_emitted {s['photons_emitted']} != {k * args.photons}")
        if s["mean_radius"] > previous["mean_radius"] or s["max_radius"] > previous["max_radius"]:
            failures.append(f"radius grew between {previous['passes']} and {k} passes")
        previous = s
    k = np.array([row["passes"] for row in rows], float)
    e = np.array([row["rms_error"] for row in rows])
    last = (k >= k[-1] / 100) & np.isfinite(e)
    slope = float(np.polyfit(np.log10(k[last]), np.log10(e[last]), 1)[0]) if last.sum() > 2 \
        else float("nan")
    if not slope < -0.2:
        failures.append(f"error slope {slope:.3f} over the last two decades is not below -0.2")
    seconds = time.time() - start
    s = r.stats()
    print(json.dumps(dict(
        renderer=s["renderer"], passes=s["passes"], photons_per_pass=args.photons,
        photons_emitted=s["photons_emitted"], past_2_32=s["photons_emitted"] > 2 ** 32,
        seconds=seconds, passes_per_second=s["passes"] / seconds,
        initial_radius=s["initial_radius"], radius_floor=1e-5 * 2.0 * math.sqrt(3.0),
        error_slope_last_two_decades=slope, checkpoints=rows, failures=failures,
        ok=not failures), indent=1))
    return 0 if not failures else 1


if __name__ == "__main__":
    sys.exit(main())
