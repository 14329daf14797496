"""theta_max approximations: worst relative error over the issue-12 box (run by hand).

    python benchmarks/bench_theta_max_approx.py [--grid small|full] [--random N] [--seed S]

The box is gamma in [-1, 3], d in 0..200, delta in [1e-6, 1].  The reference
at every point is the certified enclosure
(:func:`symstab.numeric.paper.theta_bounds.theta_max_enclosure`, relative width
about 4e-16, proved by interval arithmetic; the 30-digit scan
:func:`symstab.theta_max` is timed beside it on a few points; since the
scan proves every cell before the first root root-free, it no longer steps
over a narrow first dip of alpha).  Grids: ``small`` (9 gamma x 8 d x 6
delta = 432 points, about 15 s) and ``full`` (14 x 12 x 9 = 1512; with
``--random 3000`` about a minute); both contain the box's 8 corners.  ``--random N`` adds N seeded random points
(delta log-uniform, 30 % of them with d <= 5 where the arcs are long).

Forms compared, each on the same points:

* the paper's eq. (12): one Newton step on N_alpha from pi / (2 (d + 1)),
  printed for gamma = 0 only, so measured on the gamma = 0 points;
* the same step with the gamma terms of N_alpha kept, on every point;
* :func:`symstab.numeric.paper.theta_bounds.theta_max_approx` (8 Newton steps on
  the phase form of the reduced equation from a start derived from the
  model; no fitted constant).

Prints: form, points, worst relative error and where, median relative
error, median time per evaluation.  Accuracy numbers, not a pass/fail; the
timings come from a shared, loaded machine: read the medians.
"""

import argparse
import itertools
import statistics
import time

import mpmath
import numpy as np
import sympy as sp

from symstab.numeric.paper.theta_bounds import theta_max_approx, theta_max_enclosure
from symstab.symbolic import model
from symstab.symbolic.boundary import boundary
from symstab.symbolic.theta_max import theta_max, theta_max_newton

from _timing import fmt

GRIDS = {
    "small": ([-1, -0.5, 0, 0.5, 1, 1.5, 2, 2.5, 3], [0, 1, 2, 5, 10, 40, 100, 200],
              [1e-6, 1e-4, 2.53125e-3, 1e-2, 0.1, 1.0]),
    "full": ([-1, -0.75, -0.5, -0.25, 0, 0.25, 0.5, 0.75, 1, 1.25, 1.5, 2, 2.5, 3],
             [0, 1, 2, 3, 5, 10, 20, 40, 70, 100, 150, 200],
             [1e-6, 1e-5, 1e-4, 1e-3, 2.53125e-3, 1e-2, 0.1, 0.3, 1.0]),
}


def _points(grid, n_random, seed):
    points = [(float(g), int(d), float(dl)) for g, d, dl in itertools.product(*GRIDS[grid])]
    rng = np.random.default_rng(seed)
    for _ in range(n_random):
        d = int(rng.integers(0, 6)) if rng.random() < 0.3 else int(rng.integers(0, 201))
        points.append((float(rng.uniform(-1, 3)), d, float(10 ** rng.uniform(-6, 0))))
    return points


def _one_step_any_gamma():
    """theta0 - N_alpha/N_alpha' at theta0 = pi/(2(d+1)), gamma kept (mpmath, 30 digits)."""
    theta, d = model.theta, model.d
    num = boundary().alpha_numerator
    theta0 = sp.pi / (2 * (d + 1))
    step = (num / sp.diff(num, theta)).subs(theta, theta0)
    f = sp.lambdify((model.gamma, d, model.delta, model.Gamma), theta0 - step, modules="mpmath")

    def one_step(gamma, d_, delta):
        with mpmath.workdps(30):
            dl = mpmath.mpf(delta)
            return float(f(mpmath.mpf(gamma), d_, dl, mpmath.exp(dl)))
    return one_step


def _measure(name, form, points, reference):
    errors, times = [], []
    for p in points:
        start = time.perf_counter()
        value = form(*p)
        times.append(time.perf_counter() - start)
        exact = reference[p]
        errors.append((abs(value - exact) / exact if value == value else float("inf"), p))
    worst = max(errors)
    g, d, dl = worst[1]
    return (name, len(points), f"{worst[0]:.2e}", f"gamma={g:g}, d={d}, delta={dl:g}",
            f"{statistics.median(e for e, _ in errors):.1e}", fmt(statistics.median(times)))


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--grid", choices=sorted(GRIDS), default="small")
    parser.add_argument("--random", type=int, default=0, help="seeded random points added to the grid")
    parser.add_argument("--seed", type=int, default=12)
    args = parser.parse_args(argv)
    points = _points(args.grid, args.random, args.seed)

    start = time.perf_counter()
    reference, ref_times = {}, []
    for p in points:
        t0 = time.perf_counter()
        reference[p] = theta_max_enclosure(gamma=p[0], d=p[1], delta=p[2]).mid
        ref_times.append(time.perf_counter() - t0)
    print(f"{len(points)} points ({args.grid} grid + {args.random} random, seed {args.seed}); "
          f"certified references in {time.perf_counter() - start:.1f} s")

    theta_max_approx(gamma=0.0, d=1, delta=0.1)          # derive and lambdify once, untimed
    one_step = _one_step_any_gamma()
    one_step(0.0, 1, 0.1)
    scan_points = [p for p in points if p[1] in (0, 40, 200)][:6]
    rows = [
        _measure("paper eq. (12), gamma = 0 points", lambda g, d, dl: theta_max_newton(d=d, delta=dl),
                 [p for p in points if p[0] == 0], reference),
        _measure("one Newton step on N_alpha, any gamma", one_step, points, reference),
        _measure("theta_max_approx (8 steps)",
                 lambda g, d, dl: theta_max_approx(gamma=g, d=d, delta=dl), points, reference),
        _measure("theta_max, 30-digit scan (reference)",
                 lambda g, d, dl: theta_max(gamma=g, d=d, delta=dl), scan_points, reference),
    ]
    rows.append(("theta_max_enclosure (certified)", len(points), "(reference)", "",
                 "", fmt(statistics.median(ref_times))))
    header = ("form", "points", "worst rel. err", "where", "median err", "time/eval")
    widths = [max(len(str(r[i])) for r in rows + [header]) for i in range(len(header))]
    for row in [header] + rows:
        print("  ".join(str(c).ljust(w) for c, w in zip(row, widths, strict=True)))
    print("time/eval: median on a shared, loaded machine; the Newton step on N_alpha runs in "
          "mpmath at 30 digits (its float form cancels), theta_max_approx in floats")


if __name__ == "__main__":
    main()
