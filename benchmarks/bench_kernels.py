"""Time symstab's numeric kernels against the obvious alternatives (run by hand).

    python benchmarks/bench_kernels.py [--runs 7] [--pc-points 200] [--quick]

Everything is on the paper's device, ``symstab.PAPER_DEVICE`` (m = 0.0128,
b = 0.0324, T = 1 ms, so delta = b T / m = 0.00253125); each measurement is a median of ``--runs``
runs after one warm-up, timed with ``time.perf_counter``.

1. Classification of a 100 x 100 (alpha, beta) grid at d = 10 (alpha in
   [0, 0.03], beta in [-0.01, 0.3]: the stable region and its boundary),
   gamma = 0 and 1: ``symstab.classify`` against python-control per point
   (the closed loop of ``python_control_closed_loop`` in tests/oracles.py,
   c2d included, then ``.poles()``; and the same with ``Gd = c2d(G)`` built
   once and ``feedback(VE z^-d Gd, 1)``), against ``symstab.spectral_radius``
   (batched eigenvalues) and against a ``numpy.roots`` loop on the
   coefficients of ``symstab.numeric.paper.stability.loop_coefficients``.  python-control
   is timed per point on a random subset of the grid (``--pc-points``); its
   median per point is extrapolated to the 10^4 points, and its verdicts are
   checked against ``classify`` on the subset.  Ratio = alternative per point
   / classify per point; the project's target is >= 1000x over
   python-control.
2. A 10^5-point boundary arc, ``boundary_curve(gamma=0.5, d=10, n=100_000,
   segments=False)`` (target < 20 ms), against ``sympy.lambdify`` of the
   derivation's own ``boundary().alpha``/``.beta`` (Gamma -> exp(delta),
   modules="numpy") on the same theta grid, with its error for small delta,
   and against the C kernel ``symstab_boundary`` (compiled with
   ``cc -O2 -shared -fPIC``) called in a loop by a small C driver that times
   itself with ``clock_gettime``.
3. ``symstab.limits`` for d in {0, 10, 40} (gamma = 0 and 1) and
   ``symstab.best_virtual_mass(d=0)``: medians only.

``--quick`` is a smoke run: 3 runs, a 50-point python-control subset, one
run of part 3.
"""

import argparse
import importlib.util
import os
import pathlib
import platform
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

from symstab.numeric.paper.device import PAPER_DEVICE

REPO = pathlib.Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "benchmarks"))
from _timing import fmt, timed_runs  # noqa: E402  (the benchmarks' shared helpers)

#: The paper's device, from its one home (symstab.PAPER_DEVICE).
M, B_FRICTION, T = PAPER_DEVICE.m, PAPER_DEVICE.b, PAPER_DEVICE.T
DELTA = PAPER_DEVICE.delta
D_GRID = 10
N_GRID = 100
ALPHA_WINDOW = (0.0, 0.03)
BETA_WINDOW = (-0.01, 0.3)
GAMMAS = (0.0, 1.0)
#: python-control radii this close to 1 are left out of the agreement check.
NEAR_ONE = 1e-6
TARGET_RATIO = 1000.0
CURVE = dict(gamma=0.5, d=10, n=100_000)
CURVE_TARGET = 20e-3


def _oracles():
    """tests/oracles.py as a module (python_control_closed_loop, first-principles points)."""
    spec = importlib.util.spec_from_file_location("_symstab_test_oracles", REPO / "tests" / "oracles.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _row(label, total, per_point, ratio, note=""):
    ratio_text = "" if ratio is None else f"{ratio:,.0f}x" if ratio >= 10 else f"{ratio:.2g}x"
    print(f"  {label:<44} {total:>14} {per_point:>11} {ratio_text:>10}  {note}".rstrip())


# --------------------------------------------------------------------------
# 1. Grid classification


def bench_grid(args, oracles):
    import control

    import symstab
    from symstab.numeric.engine.roots import MARGINAL, STABLE, UNSTABLE
    from symstab.numeric.paper.stability import loop_coefficients

    A, B = np.meshgrid(np.linspace(*ALPHA_WINDOW, N_GRID), np.linspace(*BETA_WINDOW, N_GRID))
    n_points = A.size
    rng = np.random.default_rng(args.seed)
    subset = rng.choice(n_points, size=min(args.pc_points, n_points), replace=False)
    a_flat, b_flat = A.ravel(), B.ravel()

    # python-control, the alternative "Gd built once": G, c2d outside the loop.
    Gd = control.c2d(control.tf([1], [M, B_FRICTION, 0]), T, "zoh")
    z = control.tf([1, 0], [1], T)
    delay = control.tf([1], [1] + [0] * D_GRID, T)

    def pc_hoisted(alpha, beta, gamma):
        K_w, B_w, M_w = alpha * M / T**2, beta * M / T, gamma * M
        VE = oracles.eq1_virtual_environment(z, K_w, B_w, M_w, T)
        return control.feedback(VE * delay * Gd, 1)  # poles: 1 + VE z^-d Gd = 0

    def pc_conftest(alpha, beta, gamma):
        return oracles.python_control_closed_loop(alpha=alpha, beta=beta, gamma=gamma, d=D_GRID,
                                                  delta=DELTA, m=M, T=T)

    print(f"\n1. Classification of a {N_GRID} x {N_GRID} (alpha, beta) grid, d = {D_GRID}, "
          f"alpha in {list(ALPHA_WINDOW)}, beta in {list(BETA_WINDOW)}")
    print(f"   python-control timed per point on {len(subset)} random grid points (seed {args.seed}), "
          f"median x {n_points} = extrapolated grid total (marked ~)")
    print(f"  {'method':<44} {'grid total':>14} {'per point':>11} {'ratio':>10}")
    headline = []
    for gamma in GAMMAS:
        print(f" gamma = {gamma:g}")
        kw = dict(alpha=A, beta=B, gamma=gamma, d=D_GRID, delta=DELTA)
        codes = symstab.classify(**kw)
        t_cls = statistics.median(timed_runs(lambda kw=kw: symstab.classify(**kw), args.runs))
        per_cls = t_cls / n_points
        counts = {name: int(np.count_nonzero(codes == c))
                  for name, c in (("stable", STABLE), ("marginal", MARGINAL), ("unstable", UNSTABLE))}
        _row("symstab.classify", fmt(t_cls), fmt(per_cls), 1.0,
             ", ".join(f"{k} {v}" for k, v in counts.items()))

        radius = symstab.spectral_radius(**kw)
        t_rad = statistics.median(timed_runs(lambda kw=kw: symstab.spectral_radius(**kw),
                                             args.runs))
        _row("symstab.spectral_radius (batched eig)", fmt(t_rad), fmt(t_rad / n_points), t_rad / t_cls)

        def roots_loop(kw=kw):
            coeffs = loop_coefficients(**kw).reshape(n_points, -1)
            return np.array([np.max(np.abs(np.roots(c))) for c in coeffs])

        r_roots = roots_loop()
        t_roots = statistics.median(timed_runs(roots_loop, args.runs))
        _row("loop_coefficients + numpy.roots per point", fmt(t_roots), fmt(t_roots / n_points),
             t_roots / t_cls)

        # python-control: every subset point timed once per build (after a
        # warm-up), the two builds interleaved so that they see the same load.
        builds = {"conftest": pc_conftest, "hoisted": pc_hoisted}
        for build in builds.values():
            for k in subset[:3]:
                build(a_flat[k], b_flat[k], gamma).poles()
        per = {name: [] for name in builds}
        radii = {name: [] for name in builds}
        for k in subset:
            for name, build in builds.items():
                start = time.perf_counter()
                poles = build(a_flat[k], b_flat[k], gamma).poles()
                per[name].append(time.perf_counter() - start)
                radii[name].append(np.max(np.abs(poles)))
        per_pc, r_pc = statistics.median(per["conftest"]), np.array(radii["conftest"])
        per_h, r_h = statistics.median(per["hoisted"]), np.array(radii["hoisted"])
        _row("python-control per point (conftest, c2d in)", "~" + fmt(per_pc * n_points), fmt(per_pc),
             per_pc / per_cls)
        _row("python-control per point (Gd built once)", "~" + fmt(per_h * n_points), fmt(per_h),
             per_h / per_cls)
        headline.append((gamma, per_pc / per_cls, per_h / per_cls))

        # Agreement on the subset.
        sub_codes = codes.ravel()[subset]
        decided = np.abs(r_pc - 1.0) > NEAR_ONE
        agree = np.count_nonzero(((sub_codes == STABLE) == (r_pc < 1.0)) & decided & (sub_codes != MARGINAL))
        print(f"   python-control vs classify on the subset: {agree}/{np.count_nonzero(decided)} agree, "
              f"{np.count_nonzero(~decided)} excluded (|radius - 1| <= {NEAR_ONE:g}); "
              f"the two python-control builds differ by max |d radius| = {np.max(np.abs(r_pc - r_h)):.1e}")
        full_decided = (np.abs(radius - 1.0) > NEAR_ONE).ravel()
        flat_codes = codes.ravel()
        for label, r in (("spectral_radius", radius.ravel()), ("numpy.roots", r_roots)):
            ok = np.count_nonzero(((flat_codes == STABLE) == (r < 1.0)) & full_decided)
            print(f"   {label} vs classify on the whole grid: {ok}/{np.count_nonzero(full_decided)} agree "
                  f"({np.count_nonzero(~full_decided)} excluded)", end="")
            print(f"; max |radius - spectral_radius| = {np.max(np.abs(r - radius.ravel())):.1e}"
                  if label == "numpy.roots" else "")
    worst = min(min(c, h) for _, c, h in headline)
    print("   ratio python-control / classify per point: "
          + "; ".join(f"gamma {g:g}: {c:,.0f}x (c2d in), {h:,.0f}x (Gd once)" for g, c, h in headline)
          + f" -> target >= {TARGET_RATIO:,.0f}x {'met' if worst >= TARGET_RATIO else 'NOT met'} "
          f"(worst {worst:,.0f}x)")


# --------------------------------------------------------------------------
# 2. Boundary curve

C_DRIVER = r"""
#define _POSIX_C_SOURCE 199309L
#include <stdio.h>
#include <stdlib.h>
#include <time.h>
#include "symstab_kernels.h"

int main(int argc, char **argv)
{
    int n = atoi(argv[1]), runs = atoi(argv[2]), d = atoi(argv[5]);
    double theta_max = atof(argv[3]), gamma = atof(argv[4]), delta = atof(argv[6]);
    double step = theta_max / (n - 1);         /* the angles of numpy.linspace(0, theta_max, n) */
    double *alpha = malloc(n * sizeof *alpha), *beta = malloc(n * sizeof *beta);
    for (int r = -1; r < runs; r++) {          /* r = -1: warm-up */
        struct timespec t0, t1;
        clock_gettime(CLOCK_MONOTONIC, &t0);
        for (int k = 0; k < n; k++)
            symstab_boundary(k == n - 1 ? theta_max : k * step, gamma, d, delta, &alpha[k], &beta[k]);
        clock_gettime(CLOCK_MONOTONIC, &t1);
        if (r >= 0)
            printf("ns %.0f\n", (t1.tv_sec - t0.tv_sec) * 1e9 + (t1.tv_nsec - t0.tv_nsec));
    }
    for (int k = 1; k < n; k += (n - 1) / 8)
        printf("point %d %.17g %.17g\n", k, alpha[k], beta[k]);
    free(alpha);
    free(beta);
    return 0;
}
"""


def _c_kernel(theta_max, runs):
    """(times in s, {k: (alpha, beta)}) from the C driver, or a reason string."""
    cc = shutil.which("cc")
    if cc is None:
        return "no C compiler (cc) on PATH"
    import symstab._generated as generated

    source_dir = pathlib.Path(generated.__file__).parent
    with tempfile.TemporaryDirectory() as tmp:
        tmp = pathlib.Path(tmp)
        (tmp / "driver.c").write_text(C_DRIVER)
        subprocess.run([cc, "-O2", "-shared", "-fPIC", "-o", str(tmp / "libsymstab_kernels.so"),
                        str(source_dir / "symstab_kernels.c"), "-lm"], check=True)
        subprocess.run([cc, "-O2", "-o", str(tmp / "driver"), str(tmp / "driver.c"), f"-I{source_dir}",
                        f"-L{tmp}", "-lsymstab_kernels", f"-Wl,-rpath,{tmp}", "-lm"], check=True)
        out = subprocess.run([str(tmp / "driver"), str(CURVE["n"]), str(runs), repr(theta_max),
                              repr(CURVE["gamma"]), str(CURVE["d"]), repr(DELTA)],
                             check=True, capture_output=True, text=True).stdout
    times, points = [], {}
    for line in out.splitlines():
        fields = line.split()
        if fields[0] == "ns":
            times.append(float(fields[1]) * 1e-9)
        else:
            points[int(fields[1])] = (float(fields[2]), float(fields[3]))
    return times, points


def _lambdified_boundary():
    import sympy as sp

    from symstab import boundary
    from symstab.symbolic import model

    bd = boundary()
    args = (model.theta, model.gamma, model.d, model.delta)
    sub = {model.Gamma: sp.exp(model.delta)}
    return (sp.lambdify(args, bd.alpha.subs(sub), modules="numpy"),
            sp.lambdify(args, bd.beta.subs(sub), modules="numpy"))


def _scaled_error(value, reference):
    """max |value - reference| / max |reference| over the arc (theta = 0 left out: 0/0 there)."""
    v, r = value[1:], reference[1:]
    scale = np.max(np.abs(r))
    bad = ~np.isfinite(v)
    return np.max(np.abs(v[~bad] - r[~bad])) / scale, int(np.count_nonzero(bad))


def bench_curve(args, oracles):
    import mpmath

    import symstab
    from symstab._generated import kernels

    gamma, d, n = CURVE["gamma"], CURVE["d"], CURVE["n"]
    curve_kw = dict(gamma=gamma, d=d, delta=DELTA, n=n, segments=False)
    curve = symstab.boundary_curve(**curve_kw)
    theta = curve.theta
    print(f"\n2. Boundary arc with {n:,} points: gamma = {gamma:g}, d = {d}, delta = {DELTA:g} "
          f"(theta_max = {curve.theta_max:.6f})")
    print(f"  {'method':<44} {'time':>14} {'per point':>11} {'ratio':>10}")

    def ns(seconds):
        return f"{seconds / n * 1e9:.0f} ns"

    t_curve = statistics.median(timed_runs(lambda: symstab.boundary_curve(**curve_kw), args.runs))
    _row("symstab.boundary_curve (theta_max + arc)", fmt(t_curve), ns(t_curve), 1.0,
         f"target < {fmt(CURVE_TARGET)}: {'met' if t_curve < CURVE_TARGET else 'NOT met'}")
    t_kernel = statistics.median(timed_runs(lambda: kernels.boundary(theta, gamma, d, DELTA), args.runs))
    _row("  of which the NumPy kernel on the arc", fmt(t_kernel), ns(t_kernel), t_kernel / t_curve)

    start = time.perf_counter()
    f_alpha, f_beta = _lambdified_boundary()
    t_setup = time.perf_counter() - start
    with np.errstate(invalid="ignore", divide="ignore"):
        t_lamb = statistics.median(timed_runs(lambda: (f_alpha(theta, gamma, d, DELTA),
                                                   f_beta(theta, gamma, d, DELTA)), args.runs))
    _row("lambdify(boundary().alpha, .beta), numpy", fmt(t_lamb), ns(t_lamb), t_lamb / t_curve,
         f"(+ {fmt(t_setup)} once: boundary() and lambdify)")

    ref_a, ref_b = kernels.boundary(theta, gamma, d, DELTA)
    c_result = _c_kernel(curve.theta_max, args.runs)
    if isinstance(c_result, str):
        print(f"  {'C kernel symstab_boundary, C loop':<44} skipped: {c_result}")
    else:
        c_times, c_points = c_result
        t_c = statistics.median(c_times)
        c_dev = max(max(abs(a - ref_a[k]) / np.max(np.abs(ref_a)), abs(b - ref_b[k]) / np.max(np.abs(ref_b)))
                    for k, (a, b) in c_points.items())
        _row("C kernel symstab_boundary, C loop (cc -O2)", fmt(t_c), ns(t_c), t_c / t_curve,
             f"(C vs NumPy kernel at {len(c_points)} angles: {c_dev:.1e})")

    # Accuracy of the lambdified expression for small delta.  Reference: the
    # generated kernel, itself checked here against the first-principles
    # boundary (eqs. (1), (2), (4) with mpmath at 40 digits) at a few angles.
    print("   accuracy, max |error| / max |value| over the arc (alpha; beta), gamma = "
          f"{gamma:g}, d = {d}; the lambdify reference is the NumPy kernel")
    for delta in (DELTA, 1e-4, 1e-6):
        arc = symstab.boundary_curve(gamma=gamma, d=d, delta=delta, n=n, segments=False)
        ref_a, ref_b = kernels.boundary(arc.theta, gamma, d, delta)
        with np.errstate(invalid="ignore", divide="ignore"):
            lam_a, lam_b = f_alpha(arc.theta, gamma, d, delta), f_beta(arc.theta, gamma, d, delta)
        (err_a, bad_a), (err_b, _) = _scaled_error(lam_a, ref_a), _scaled_error(lam_b, ref_b)
        angles = np.linspace(1, n - 1, 9).astype(int)
        with mpmath.workdps(40):
            exact = np.array([[float(v) for v in oracles.first_principles_boundary_point(
                arc.theta[k], gamma, d, delta)] for k in angles])
        kernel_a = np.max(np.abs(ref_a[angles] - exact[:, 0])) / np.max(np.abs(ref_a))
        kernel_b = np.max(np.abs(ref_b[angles] - exact[:, 1])) / np.max(np.abs(ref_b))
        print(f"     delta = {delta:<10g} lambdify {err_a:.1e}; {err_b:.1e}"
              f"{f' ({bad_a} non-finite)' if bad_a else ''}   "
              f"NumPy kernel vs first principles at {len(angles)} angles {kernel_a:.1e}; {kernel_b:.1e}")


# --------------------------------------------------------------------------
# 3. Region functions


def bench_region(args):
    import symstab

    print(f"\n3. Region functions, delta = {DELTA:g} (median of {args.limits_runs} run(s) after a warm-up)")
    for d in (0, 10, 40):
        cells = []
        for gamma in GAMMAS:
            t = statistics.median(timed_runs(
                lambda gamma=gamma, d=d: symstab.limits(gamma=gamma, d=d, delta=DELTA),
                args.limits_runs))
            cells.append(f"gamma {gamma:g}: {fmt(t):>9}")
        print(f"  limits, d = {d:<3} " + "   ".join(cells))
    t = statistics.median(timed_runs(lambda: symstab.best_virtual_mass(d=0, delta=DELTA), args.limits_runs))
    print(f"  best_virtual_mass, d = 0   {fmt(t)}")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=None, help="timed runs per measurement (default 7)")
    parser.add_argument("--pc-points", type=int, default=None,
                        help="grid points timed with python-control per gamma (default 200)")
    parser.add_argument("--limits-runs", type=int, default=None, help="runs of part 3 (default 3)")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--quick", action="store_true",
                        help="smoke run: 3 runs, 50 python-control points, 1 run of part 3")
    args = parser.parse_args()
    quick = dict(runs=3, pc_points=50, limits_runs=1)
    full = dict(runs=7, pc_points=200, limits_runs=3)
    for key, value in (quick if args.quick else full).items():
        if getattr(args, key) is None:
            setattr(args, key, value)

    import control

    start = time.perf_counter()
    print(f"symstab kernel benchmarks{' (--quick)' if args.quick else ''}: median of {args.runs} runs "
          f"after a warm-up, time.perf_counter")
    print(f"python {platform.python_version()}, numpy {np.__version__}, python-control {control.__version__}, "
          f"{platform.machine()}, {os.cpu_count()} CPUs; OPENBLAS_CORETYPE "
          + (f"= {os.environ['OPENBLAS_CORETYPE']!r}" if "OPENBLAS_CORETYPE" in os.environ else "not set"))
    print(f"device: m = {M}, b = {B_FRICTION}, T = {T} -> delta = b T / m = {DELTA:g}")
    print("load average (1, 5, 15 min) at start: " + ", ".join(f"{x:.2f}" for x in os.getloadavg()))
    oracles = _oracles()
    bench_grid(args, oracles)
    bench_curve(args, oracles)
    bench_region(args)
    print(f"\ntotal benchmark time {time.perf_counter() - start:.1f} s; load average at end: "
          + ", ".join(f"{x:.2f}" for x in os.getloadavg()))


if __name__ == "__main__":
    main()
