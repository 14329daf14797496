"""A design with a noise budget against the obvious alternative, a dense scan, in one run.

    python benchmarks/bench_design_budget.py [--runs 3] [--points 200]

The engineer's device of issue 44 (examples/loops/lowpass_velocity.toml with
m = 0.2 kg, b = 2 N s/m, T = 0.25 ms, d = 20) over the velocity filter's
cut-off f_c in [20, 1800] Hz, a wall of K = 600 N/m and B = 15 N s/m rendered
within 10 mN of force noise, an encoder of 3.83 um.  symstab:
``Loop.design(..., encoder_resolution=q, noise_limit=0.01, noise_at=wall)``
(the noise scanned and its edge bisected, then the certified K_max searched
within it).  The alternative a user writes: ``Loop.force_noise`` and
``Loop.limits`` at ``--points`` evenly spaced cut-offs, the best K_max among
those within the budget.  Prints the medians of their times, their
ratio, and the two answers (the scan's is on its grid: its step is its error).
"""

import argparse
import math
import pathlib
import statistics

import numpy as np

import symstab

from _timing import fmt, timed_runs

ROOT = pathlib.Path(__file__).resolve().parent.parent
DEVICE = dict(m=0.2, b=2.0, T=2.5e-4, d=20)
WALL = {"B": 15.0, "K": 600.0}
Q = 2 * math.pi * 0.01 / 16384
LIMIT = 0.01
WINDOW = (20.0, 1800.0)


def dense_scan(loop, points):
    """The best K_max among ``points`` cut-offs whose force noise is within the budget."""
    best = (None, -math.inf)
    for f_c in np.linspace(*WINDOW, points):
        at = {**loop.defaults, **DEVICE, "f_c": float(f_c)}
        try:
            noise = loop.force_noise(encoder_resolution=Q, **{**at, **WALL}).rms
        except ValueError:
            continue
        if noise <= LIMIT:
            k_max = loop.limits(**{k: v for k, v in at.items() if k not in WALL}).y_max
            if k_max is not None and k_max > best[1]:
                best = (float(f_c), k_max)
    return best


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--points", type=int, default=200)
    args = parser.parse_args()
    loop = symstab.load_loop(ROOT / "examples" / "loops" / "lowpass_velocity.toml")

    def ours():
        return loop.design(over={"f_c": WINDOW}, encoder_resolution=Q, noise_limit=LIMIT,
                           noise_at=WALL, **DEVICE)

    found = ours()
    scanned = dense_scan(loop, args.points)
    design_time = statistics.median(timed_runs(ours, args.runs))
    scan_time = statistics.median(timed_runs(lambda: dense_scan(loop, args.points), args.runs))
    step = (WINDOW[1] - WINDOW[0]) / (args.points - 1)
    print(f"design with a budget: f_c = {found.best['f_c']:.4f} Hz, K_max = {found.value:.6g} "
          f"N/m, noise {found.best_noise:.6g} N, {len(found.samples)} limits evaluations, "
          f"{fmt(design_time)}")
    print(f"dense scan ({args.points} points, step {step:.3g} Hz): f_c = {scanned[0]:.4f} Hz, "
          f"K_max = {scanned[1]:.6g} N/m, {fmt(scan_time)}")
    print(f"ratio scan / design: {scan_time / design_time:.1f}; K_max of the design over the "
          f"scan's: {found.value / scanned[1]:.6f}")


if __name__ == "__main__":
    main()
