"""The margins at a point against the obvious alternative, python-control, in one run.

    python benchmarks/bench_margins.py [--runs 7]

The paper's loop (examples/loops/paper.toml) at a stable point per delay d.
symstab: ``Loop.margins`` (the certified modulus margin, every gain and phase
crossover, the stable intervals of K and B, the delay margin in whole
samples) and its modulus margin alone
(:func:`symstab.numeric.engine.roots.circle_minimum`).  The alternative: the
open loop built with python-control (``c2d`` of the plant, ``VE`` and the
delay as transfer functions) and ``control.stability_margins(returnall=True)``
(gain, phase and stability margins, no parameter or delay margin, and a
stability margin that is a minimum on its frequency grid, not certified).
Prints the medians, their ratio and both stability margins.  Then a modulus-margin
map of the plane at d = 40 (``Loop.margin_map``, 100 x 100 points, every stable
point certified) against python-control's stability margin point by point (on a
10 x 10 grid of the same window: the per-point time is what a user's loop would
cost at 100 x 100).  Then the exact delay-margin map (``margin="delay"``, 30 x
30 points at d = 40, ``--delay-map N`` for N x N) against the whole-sample map
it replaced (kept here only, as the comparison: from each point's first
possible whole delay, one verdict a whole sample) and against
``Loop.delay_margin`` point by point (on every fifth point of each axis).

Measured 2026-12-07 (2 CPUs, quiet), the delay map: 30 x 30 at d = 40, 734
stable points with margins 0.2 to 406.5 samples: the exact map 61.8 s (84 ms
a stable point), the whole-sample map 1.21 s (ceil of the exact margin equal
to it at all 730 finite points), delay_margin point by point 110 ms a point.
"""

import argparse
import pathlib
import statistics
import warnings

import control

import symstab
from symstab.numeric.engine.roots import circle_minimum

from _timing import fmt, timed_runs

ROOT = pathlib.Path(__file__).resolve().parent.parent

#: Stable points of the paper's device per delay (K in N m/rad, B in N m s/rad).
POINTS = {0: dict(K=100.0, B=1.0), 10: dict(K=3.0, B=0.2), 40: dict(K=2.0, B=0.1, M=0.004)}


def python_control_open_loop(values):
    T = values["T"]
    z = control.tf([1, 0], [1], T)
    plant = control.c2d(control.tf([1], [values["m"], values["b"], 0]), T, "zoh")
    environment = (values["K"] + values["B"] * (z - 1) / (T * z)
                   + values["M"] * (z - 1) ** 2 / (T * z) ** 2)
    return environment * plant * control.tf([1], [1] + [0] * values["d"], T)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=7)
    parser.add_argument("--delay-map", type=int, default=30, metavar="N",
                        help="points per axis of the delay-margin map (0: skip it)")
    args = parser.parse_args()
    loop = symstab.load_loop(ROOT / "examples" / "loops" / "paper.toml")
    for d, point in POINTS.items():
        values = {**loop.defaults, **point, "d": d}
        found = loop.margins(**values)
        ours = statistics.median(timed_runs(lambda values=values: loop.margins(**values),
                                            args.runs))
        chi = loop.polynomial(**values)
        modulus = statistics.median(timed_runs(lambda chi=chi: circle_minimum(chi), args.runs))
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")    # its fallback to a frequency grid at long delays
            theirs_fn = lambda values=values: control.stability_margins(  # noqa: E731
                python_control_open_loop(values), returnall=True)
            sm = min(theirs_fn()[2])
            theirs = statistics.median(timed_runs(theirs_fn, args.runs))
        print(f"d = {d}, {point} (median of {args.runs}):")
        print(f"  symstab Loop.margins       {fmt(ours):>9}  modulus {found.modulus:.9f} "
              f"(certified >= {found.modulus_lower:.9f}), delay margin {found.delay}")
        print(f"  symstab modulus alone      {fmt(modulus):>9}")
        print(f"  python-control margins    {fmt(theirs):>9}  stability margin {sm:.9f}")
        print(f"  ratio symstab / python-control: {ours / theirs:.2f} (all margins), "
              f"{modulus / theirs:.2f} (modulus)")

    map_benchmark(loop, args.runs)
    if args.delay_map:
        delay_map_benchmark(loop, args.delay_map)


def map_benchmark(loop, runs):
    """The 100 x 100 modulus-margin map at d = 40 against python-control per point."""
    import numpy as np

    at = {"d": 40, "M": 0.004}
    xs, ys = np.linspace(0.0, 0.25, 100), np.linspace(0.0, 4.0, 100)
    found = loop.margin_map(xs, ys, **at)
    ours = statistics.median(timed_runs(lambda: loop.margin_map(xs, ys, **at), max(1, runs // 3)))
    coarse = [(B, K) for B in xs[::10] for K in ys[::10]
              if loop.is_stable(**{**loop.defaults, **at, "B": B, "K": K})]

    def theirs_fn():
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            for B, K in coarse:
                control.stability_margins(python_control_open_loop(
                    {**loop.defaults, **at, "B": B, "K": K}))

    theirs = statistics.median(timed_runs(theirs_fn, 1, warmup=0)) / max(1, len(coarse))
    stable = int(np.isfinite(found.values).sum())
    print(f"modulus-margin map, d = 40, 100 x 100 points ({stable} stable):")
    print(f"  symstab Loop.margin_map            {fmt(ours):>9}  ({fmt(ours / stable)} a stable "
          f"point, certified)")
    print(f"  python-control stability_margins   {fmt(theirs):>9} a stable point "
          f"({len(coarse)} points of a 10 x 10 grid): {fmt(theirs * stable)} for the map")
    print(f"  ratio symstab / python-control: {ours / (theirs * stable):.3f}")


def whole_sample_delay_map(loop, xs, ys, at, limit):
    """The delay margin in whole samples per point of the (B, K) grid: the map before the exact one.

    From each stable point's first whole delay that can be unstable
    (``first_whole_delays``), the verdicts at ``d + k`` of every point waiting
    on the same ``k`` in one call.
    """
    import numpy as np

    from symstab.numeric.analysis.margins import first_whole_delays
    from symstab.numeric.engine.roots import STABLE

    at = {k: v for k, v in at.items() if k not in ("B", "K")}
    X, Y = np.meshgrid(xs, ys)
    out = np.full(X.shape, np.nan)
    stable = np.asarray(loop.classify(**at, B=X, K=Y)) == STABLE
    bs, ks = X[stable], Y[stable]
    first = first_whole_delays(loop.polynomial(**at, B=bs, K=ks))
    found = np.full(bs.size, np.inf)
    pending = np.isfinite(first)
    k = np.where(pending, first, 0).astype(int)
    while pending.any():
        for added in np.unique(k[pending]):
            wait = np.flatnonzero(pending & (k == added))
            if added > limit:
                pending[wait] = False
                continue
            code = loop.classify(**{**at, "d": at["d"] + added}, B=bs[wait], K=ks[wait])
            hit = np.asarray(code) != STABLE
            found[wait[hit]] = added
            pending[wait[hit]] = False
            k[wait[~hit]] += 1
    out[stable] = found
    return out


def delay_map_benchmark(loop, n):
    """The exact delay-margin map, n x n at d = 40, against the whole-sample one and point by point."""
    import time

    import numpy as np

    at = {"d": 40, "M": 0.004}
    xs, ys = np.linspace(0.0, 0.25, n), np.linspace(0.0, 4.0, n)
    # One run each: the exact map takes minutes.
    point = {**loop.defaults, **at}
    wholes = whole_sample_delay_map(loop, xs, ys, point, 410)
    whole = statistics.median(timed_runs(
        lambda: whole_sample_delay_map(loop, xs, ys, point, 410), 3))
    print(f"  whole-sample map: {fmt(whole)}", flush=True)
    start = time.perf_counter()
    found = loop.margin_map(xs, ys, margin="delay", **at)
    exact = time.perf_counter() - start
    print(f"  exact map: {fmt(exact)}", flush=True)
    subset = [(i, j) for i in range(0, n, 5) for j in range(0, n, 5)
              if np.isfinite(found.values[i, j])]
    start = time.perf_counter()
    for i, j in subset:
        margin = loop.delay_margin(**at, B=xs[j], K=ys[i]).margin
        assert margin == found.values[i, j] or abs(margin / found.values[i, j] - 1) < 1e-9
    single = (time.perf_counter() - start) / max(1, len(subset))
    stable = int(np.sum(~np.isnan(found.values)))
    finite = np.isfinite(found.values) & np.isfinite(wholes)
    print(f"delay-margin map, d = 40, {n} x {n} points ({stable} stable, margins "
          f"{np.nanmin(found.values):.4g} to {np.max(found.values[finite]):.4g} samples, "
          f"limit {found.delay_limit:g}):")
    print(f"  symstab exact map (fractional)     {fmt(exact):>9}  ({fmt(exact / stable)} a "
          f"stable point)")
    print(f"  whole-sample map (the old one)     {fmt(whole):>9}  ratio exact / whole "
          f"{exact / whole:.0f}; ceil(exact) == whole at "
          f"{int(np.sum(np.ceil(found.values[finite]) == wholes[finite]))} of "
          f"{int(finite.sum())}")
    print(f"  Loop.delay_margin point by point   {fmt(single):>9} a stable point ({len(subset)} "
          f"points): {fmt(single * stable)} for the map; ratio map / point by point "
          f"{exact / (single * stable):.2f}")


if __name__ == "__main__":
    main()
