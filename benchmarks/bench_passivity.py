"""The passive set at long delays: the condition in Dirichlet kernels against its cosine series.

    python benchmarks/bench_passivity.py [--runs 3] [--delays 10,100,1000]

Colgate and Schenkel's condition of a plane is ``a0 + x ax + y ay <= 0``
at every angle; :mod:`symstab.numeric.analysis.passivity` evaluates each term as a
short sum of Dirichlet kernels in closed form (``len(N) + len(D) - 1``
sines per angle, whatever the delay).  The obvious alternative, what the
module did before, expands the same sum into a cosine series of ``d + 3``
terms and evaluates it with ``numpy.polynomial.chebyshev.chebval``.  Rows,
medians of ``--runs`` on one machine state:

1. The three terms on the grid ``passive_region`` uses (16 angles per
   period of the highest harmonic) and on 2 000 scattered angles (what the
   refining search asks for), both ways; then the largest error of each
   way, relative to the terms' size, against the same sum of kernels at 40
   digits (mpmath) at 40 angles (0, 1e-7, 1e-3, pi and 36 random ones).
2. ``passive_region`` of the paper's loop at each delay, beside
   ``Loop.limits`` of the same plane (the stable set's engine).
"""

import argparse
import statistics

import mpmath
import numpy as np

from symstab.numeric.analysis import passivity
from symstab.numeric.paper.paper_loop import paper_point

from _timing import fmt, timed_runs

DELTA = 0.00253125


def cosine_series_terms(plane, theta):
    """The obvious alternative: the Dirichlet sum expanded into cosines, then ``chebval``."""
    q = np.zeros((int(plane.orders.max()) + 1, 3))
    orders = plane.orders.astype(int)
    # D_m = 1 + 2 (cos theta + ... + cos m theta).
    for m, w in zip(orders, plane.weights, strict=True):
        q[0] += w
        q[1:m + 1] += 2 * w
    c = np.cos(theta)
    den = np.asarray(plane.den, dtype=float)
    auto = np.convolve(den, den[::-1])
    n = len(den) - 1
    r = np.polynomial.chebyshev.chebval(c, np.concatenate([[auto[n]], 2 * auto[n + 1:]]))
    a = plane.scale * np.polynomial.chebyshev.chebval(c, q) / r
    a[0] = a[0] - plane.damping
    return a


def _plane(d):
    """The prepared plane ``passive_region`` makes for the paper's loop at ``d``."""
    loop, values = paper_point(gamma=0.0, d=d, delta=DELTA)
    seen = []
    solve = passivity._solve

    def keep(plane, *args, **kwargs):
        seen.append(plane)
        return solve(plane, *args, **kwargs)

    passivity._solve = keep
    try:
        passivity.passive_region(loop, "B", "K", **values)
    finally:
        passivity._solve = solve
    return seen[0]


def reference_terms(plane, theta):
    """The same Dirichlet sum at 40 digits: ``(3, len(theta))``."""
    out = []
    with mpmath.workdps(40):
        den = [mpmath.mpf(float(c)) for c in plane.den]
        for t in theta:
            t = mpmath.mpf(float(t))
            r = abs(mpmath.polyval(den, mpmath.expj(t)))**2
            kernels = [2 * m + 1 if t == 0 else mpmath.sin((m + 0.5) * t) / mpmath.sin(t / 2)
                       for m in plane.orders]
            a = [plane.scale * mpmath.fsum(mpmath.mpf(float(w)) * k
                                           for w, k in zip(plane.weights[:, j], kernels,
                                                           strict=True)) / r
                 for j in range(3)]
            a[0] -= plane.damping
            out.append([float(v) for v in a])
    return np.array(out).T


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--delays", default="10,100,1000")
    args = parser.parse_args(argv)
    delays = [int(v) for v in args.delays.split(",")]
    rng = np.random.default_rng(1)
    print("1. The condition's three terms: Dirichlet kernels against the cosine series")
    print(f"{'d':>5} {'angles':>8} {'kernels':>10} {'series':>10} {'ratio':>7}")
    for d in delays:
        plane = _plane(d)
        for label, theta in (("grid", passivity._grid(plane.harmonic)),
                             ("2000", np.sort(rng.uniform(0, np.pi, 2000)))):
            ours = statistics.median(timed_runs(lambda plane=plane, theta=theta:
                                                plane.terms(theta), args.runs))
            other = statistics.median(timed_runs(lambda plane=plane, theta=theta:
                                                 cosine_series_terms(plane, theta), args.runs))
            print(f"{d:>5} {theta.size if label == 'grid' else label:>8} {fmt(ours):>10} "
                  f"{fmt(other):>10} {other / ours:>7.1f}")
        theta = np.concatenate([[0.0, 1e-7, 1e-3, np.pi], rng.uniform(0, np.pi, 36)])
        exact = reference_terms(plane, theta)
        size = np.max(np.abs(exact), axis=1)[:, None]
        errors = [float(np.max(np.abs(f(plane, theta) - exact) / size))
                  for f in (lambda p, t: p.terms(t), cosine_series_terms)]
        print(f"{d:>5} error against 40 digits: kernels {errors[0]:.1e}, series {errors[1]:.1e}")
    print()
    print("2. passive_region of the paper's loop beside Loop.limits (same plane)")
    print(f"{'d':>5} {'passive':>10} {'limits':>10}")
    for d in delays:
        loop, values = paper_point(gamma=0.0, d=d, delta=DELTA)
        runs = args.runs if d < 1000 else 1
        passive = statistics.median(timed_runs(
            lambda loop=loop, values=values: passivity.passive_region(loop, "B", "K", **values),
            runs, warmup=0))
        limits = statistics.median(timed_runs(
            lambda loop=loop, values=values: loop.limits("B", "K", **values), runs, warmup=0))
        print(f"{d:>5} {fmt(passive):>10} {fmt(limits):>10}")


if __name__ == "__main__":
    main()
