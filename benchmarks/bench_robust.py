"""The certified robust region against the obvious alternative, sampling the box, in one run.

    python benchmarks/bench_robust.py [--strips 64] [--samples 25] [--runs 3]

The paper's loop (examples/loops/paper.toml) at d = 10 with b uncertain by
+-50 % (and, second, m by +-10 % too).  The certified region
(``Loop.robust_region(..., uncertain=box)``: zero exclusion over the box and theta,
:mod:`symstab.numeric.analysis.robust`) against the intersection of the stable
intervals at ``samples`` values of the box on the same strips' edges (the
line engine at each value: what a user would do by hand, and not a
guarantee between the values).  Prints the medians, their ratio, the areas
(the sampled set is an outer estimate, the certified one an inner set),
the marginal area, how the certified area grows with the strips, for a
box of zero width, how close it comes to the nominal set's area, and the
cost of a continuum of delays (every Td from 1.5 to 2.5 ms) against its
whole delays.
"""

import argparse
import pathlib
import statistics

import numpy as np

import symstab

from _timing import fmt, timed_runs

ROOT = pathlib.Path(__file__).resolve().parent.parent


def sampled(loop, box, strips, samples, values):
    """Area of the intersection of the stable intervals at ``samples`` values, on the strips' edges."""
    nominal = loop.region("B", "K", **values, **{k: 0.5 * (lo + hi) for k, (lo, hi) in box.items()})
    points = np.vstack([c.outer for c in nominal.stable])
    edges = np.linspace(points[:, 0].min(), points[:, 0].max(), strips + 1)
    rng = np.random.default_rng(0)
    draws = [dict(zip(box, p, strict=True)) for p in zip(*[rng.uniform(lo, hi, samples)
                                              for lo, hi in box.values()], strict=True)]
    kept = [[(-np.inf, np.inf)] for _ in edges]
    for value in draws:
        found = loop.stable_intervals("K", B=edges, **values, **value)
        kept = [[(max(a, c), min(b, e)) for a, b in k for c, e in f if max(a, c) < min(b, e)]
                for k, f in zip(kept, found, strict=True)]
    # Trapezoids between the edges, as the certified region's pieces.
    area = 0.0
    for i in range(strips):
        left, right = kept[i], kept[i + 1]
        if len(left) == len(right):
            area += 0.5 * (edges[i + 1] - edges[i]) * sum(b - a for a, b in left + right)
        else:
            area += (edges[i + 1] - edges[i]) * sum(
                max(0.0, min(b, e) - max(a, c)) for a, b in left for c, e in right)
    return area


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--strips", type=int, default=64)
    parser.add_argument("--samples", type=int, default=25)
    parser.add_argument("--runs", type=int, default=3)
    args = parser.parse_args()
    loop = symstab.load_loop(ROOT / "examples" / "loops" / "paper.toml")
    values = {"d": 10, "M": 0.0}
    for box in ({"b": (0.0162, 0.0648)}, {"b": (0.0162, 0.0648), "m": (0.0115, 0.0141)}):
        words = ", ".join(f"{k} in [{lo:g}, {hi:g}]" for k, (lo, hi) in box.items())
        region = loop.robust_region("B", "K", uncertain=box, strips=args.strips, **values)
        certified = timed_runs(lambda box=box: loop.robust_region("B", "K", uncertain=box,
                                                          strips=args.strips, **values), args.runs)
        area = sampled(loop, box, args.strips, args.samples, values)
        by_hand = timed_runs(lambda box=box: sampled(loop, box, args.strips, args.samples, values),
                             args.runs)
        c, s = statistics.median(certified), statistics.median(by_hand)
        print(f"{words}, {args.strips} strips (median of {args.runs}):")
        print(f"  certified robust region  {fmt(c):>9}  area {region.area:.6g}, marginal "
              f"{region.marginal_area:.3g}, {region.examined} cells examined")
        print(f"  {args.samples} sampled values     {fmt(s):>9}  area {area:.6g} (not "
              f"certified between the values)")
        print(f"  ratio certified / sampled: {c / s:.2f}; area ratio {region.area / area:.4f}; "
              f"nominal area {region.nominal.area:.6g}")
    box = {"b": (0.0162, 0.0648)}
    print("the certified area as the strips narrow (b in [0.0162, 0.0648]):")
    for strips in (16, 64, 256):
        region = loop.robust_region("B", "K", uncertain=box, strips=strips, **values)
        print(f"  {strips:>4} strips  area {region.area:.6g}  marginal {region.marginal_area:.3g}")
    b = loop.defaults["b"]
    nominal = nominal_area(loop, values)
    print(f"a box of zero width (b = {b:g}): the certified area against the nominal set's "
          f"{nominal:.10g} (its stable intervals' lengths integrated by scipy's quad):")
    for strips, rtol in ((16, 1e-6), (64, 1e-6), (256, 1e-6), (1024, 1e-7), (4096, 1e-7)):
        times = timed_runs(lambda strips=strips, rtol=rtol: loop.robust_region(
            "B", "K", uncertain={"b": (b, b)}, strips=strips, rtol=rtol, **values), 1)
        region = loop.robust_region("B", "K", uncertain={"b": (b, b)}, strips=strips, rtol=rtol,
                                    **values)
        print(f"  {strips:>4} strips, rtol {rtol:g}  {fmt(statistics.median(times)):>9}  area "
              f"{region.area:.10g}, short by {(nominal - region.area) / nominal:.2e} of it")
    delay_range_case(loop, args.strips, args.runs)


def delay_range_case(loop, strips, runs):
    """A continuum of delays (every Td from 1.5 to 2.5 ms) against its whole delays 2 and 3."""
    print(f"every delay from 1.5 to 2.5 ms (M = 0, {strips} strips, median of {runs}):")
    for words, uncertain in (("Td in [1.5, 2.5] ms, a continuum", {"Td": (0.0015, 0.0025)}),
                             ("d in {2, 3}, whole delays", {"d": (2, 3)})):
        times = timed_runs(lambda u=uncertain: loop.robust_region(
            "B", "K", uncertain=u, strips=strips, M=0.0), runs)
        region = loop.robust_region("B", "K", uncertain=uncertain, strips=strips, M=0.0)
        print(f"  {words:<34} {fmt(statistics.median(times)):>9}  area {region.area:.6g}, "
              f"marginal {region.marginal_area:.3g}, {region.examined} cells examined")


def nominal_area(loop, values):
    """The nominal stable set's area: the line engine's stable intervals' lengths, integrated."""
    from scipy.integrate import quad

    x_range = loop.region("B", "K", **values).x_range

    def length(B):
        return sum(hi - lo for lo, hi in loop.stable_intervals("K", B=np.array([B]), **values)[0])

    return quad(length, *x_range, limit=400, epsabs=1e-10, epsrel=1e-12)[0]


if __name__ == "__main__":
    main()
