"""The one root engine: structured against dense, the paper's loop through Loop against the paper's path.

    python benchmarks/bench_engine.py [--runs 3] [--points 500]

Every row is one run on the same machine state, medians of ``--runs``:

1. Certified root counts (:func:`symstab.numeric.engine.roots.root_counts`) of the
   paper's loop at d = 10, 100, 1000 for ``--points`` random (K, B) points:
   the loop of ``examples/loops/paper.toml`` (the Loop path of a user's
   loop: plant at 30 digits, environment kernel, structured chi; the same
   loop as ``symstab.PAPER_LOOP``, which counts the roots of eq. (5)'s
   closed form instead) against the dimensionless
   path (``symstab.numeric.paper.stability.unstable_root_counts``: generated
   kernel, structured chi), and against the obvious alternative, the same
   counter on the dense coefficients (O(d) per angle: O(d**2) per point,
   what Loop did before the structured polynomial).
2. ``classify`` the same way (Loop against the dimensionless path).
3. ``spectral_radius`` at d = 2000 of one point: the structured radius
   (counts on circles, Newton on chi) against companion eigenvalues of the
   dense polynomial (``numpy.linalg.eigvals``, O(d**3)).
4. The stable set's limits at ``--limits-delays`` (default 200, 1000,
   5000): ``symstab.PAPER_LOOP.limits`` (the D-decomposition on the
   structured polynomial, its window from the exact stable hull) in the
   device's units against ``symstab.limits`` in Table I's, which is the
   same engine at m = T = 1 (the paper's own line integration is gone): the
   ratio is what the dimensionless adapter costs, and K_max from both.
   One run each from d = 1000 on.
5. Stable K intervals on ``--lines`` vertical lines across the stable B
   range at d = 10, 100, 1000: one family
   (``PAPER_LOOP.stable_intervals("K", B=array)``, the lines' brackets
   scanned, refined and counted together) against the obvious alternative,
   a loop of single lines; and that both give the same intervals.

Targets (issue 19): the Loop path within 1.3x of the paper's; the radius at
d = 2000 under 1 s; Loop limits under 2 s at d = 1000 and 20 s at d = 5000.  BLAS threads on a busy 2-core machine distort short
products badly: run with ``OPENBLAS_NUM_THREADS=1`` for stable numbers.
"""

import argparse
import pathlib
import statistics

import numpy as np

import symstab
from symstab.numeric.engine import roots
from symstab.numeric.engine.polynomial import DelayedPolynomial
from symstab.numeric.paper import stability

from _timing import fmt, timed_runs


def _median(fn, runs):
    return statistics.median(timed_runs(fn, runs))


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--points", type=int, default=500)
    parser.add_argument("--limits-delays", default="200,1000,5000")
    parser.add_argument("--lines", type=int, default=40)
    args = parser.parse_args(argv)
    loop, device = symstab.PAPER_LOOP, symstab.PAPER_DEVICE
    own = symstab.load_loop(pathlib.Path(__file__).parent.parent / "examples" / "loops" / "paper.toml")
    rng = np.random.default_rng(0)
    K, B = rng.uniform(0.0, 6.0, args.points), rng.uniform(0.0, 0.5, args.points)
    alpha, beta = device.alpha(K), device.beta(B)
    print(f"{'what':<34} {'d':>5} {'Loop':>9} {'paper':>9} {'ratio':>6} {'dense':>9} {'dense/structured':>17}")
    for d in (10, 100, 1000):
        paper = dict(alpha=alpha, beta=beta, gamma=0.0, d=d, delta=device.delta)
        t_loop = _median(lambda d=d: own.unstable_root_counts(K=K, B=B, d=d), args.runs)
        t_paper = _median(lambda paper=paper: stability.unstable_root_counts(**paper), args.runs)
        dense = DelayedPolynomial.from_dense(stability.loop_coefficients(**paper))
        runs = args.runs if d < 1000 else 1
        t_dense = _median(lambda dense=dense: roots.root_counts(dense), runs)
        agree = np.array_equal(own.unstable_root_counts(K=K, B=B, d=d), stability.unstable_root_counts(**paper))
        print(f"{'certified counts (' + str(args.points) + ' pts)':<34} {d:>5} {fmt(t_loop):>9} "
              f"{fmt(t_paper):>9} {t_loop / t_paper:>6.2f} {fmt(t_dense):>9} {t_dense / t_paper:>17.1f}"
              f"{'' if agree else '  COUNTS DIFFER'}")
        t_loop = _median(lambda d=d: own.classify(K=K, B=B, d=d), args.runs)
        t_paper = _median(lambda paper=paper: stability.classify(**paper), args.runs)
        print(f"{'classify':<34} {d:>5} {fmt(t_loop):>9} {fmt(t_paper):>9} {t_loop / t_paper:>6.2f}")
    d = 2000
    chi = stability.paper_polynomial(alpha=device.alpha(3.0), beta=device.beta(0.01), gamma=0.0, d=d,
                                     delta=device.delta)
    t_structured = _median(lambda: roots.spectral_radius(chi), args.runs)
    dense = chi.dense()

    def eigenvalues():
        companion = np.zeros((d + 4, d + 4))
        companion[0, :] = -dense[1:] / dense[0]
        companion[np.arange(1, d + 4), np.arange(d + 3)] = 1.0
        return float(np.max(np.abs(np.linalg.eigvals(companion))))

    t_eig = _median(eigenvalues, 1)
    r_structured, r_eig = float(roots.spectral_radius(chi)), eigenvalues()
    print(f"spectral radius d = {d}: structured {fmt(t_structured)}, eigenvalues {fmt(t_eig)} "
          f"(ratio {t_eig / t_structured:.0f}); radii {r_structured:.15f} and {r_eig:.15f}")
    print()
    print(f"{'limits':<8} {'d':>5} {'Loop':>9} {'paper':>9} {'paper/Loop':>11}  K_max (N/m): Loop, paper")
    for d in (int(v) for v in args.limits_delays.split(",")):
        runs, warmup = (args.runs, 1) if d < 1000 else (1, 0)
        found = {}
        t_loop = statistics.median(timed_runs(
            lambda d=d, found=found: found.update(loop=loop.limits(d=d)), runs, warmup))
        t_paper = statistics.median(timed_runs(
            lambda d=d, found=found:
            found.update(paper=symstab.limits(gamma=0.0, d=d, delta=device.delta)),
            runs, warmup))
        ours, theirs = found["loop"].y_max, float(device.stiffness(found["paper"].alpha_max))
        print(f"{'':<8} {d:>5} {fmt(t_loop):>9} {fmt(t_paper):>9} {t_paper / t_loop:>11.2f}  "
              f"{ours:.9g}, {theirs:.9g}")
    print()
    print(f"{'K intervals on ' + str(args.lines) + ' lines':<26} {'d':>5} {'family':>9} "
          f"{'one by one':>11} {'ratio':>6}  same intervals")
    for d in (10, 100, 1000):
        lim = loop.limits(d=d)
        dampings = np.linspace(lim.x_min, lim.x_max, args.lines + 2)[1:-1]
        runs = args.runs if d < 1000 else 1
        found = {}
        t_family = _median(
            lambda d=d, found=found, dampings=dampings:
            found.update(family=loop.stable_intervals("K", B=dampings, d=d)), runs)
        t_single = _median(
            lambda d=d, found=found, dampings=dampings:
            found.update(single=[loop.stable_intervals("K", B=b, d=d) for b in dampings]), runs)
        print(f"{'':<26} {d:>5} {fmt(t_family):>9} {fmt(t_single):>11} "
              f"{t_single / t_family:>6.1f}  {found['family'] == found['single']}")


if __name__ == "__main__":
    main()
