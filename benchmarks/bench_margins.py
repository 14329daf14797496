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
cost at 100 x 100).
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


if __name__ == "__main__":
    main()
