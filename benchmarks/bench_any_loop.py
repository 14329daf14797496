"""Time ``symstab.Loop`` (any loop) against the paper-specific API and python-control (run by hand).

    python benchmarks/bench_any_loop.py [--runs 7] [--build-runs 3] [--pc-points 200]
                                        [--limits-runs 3] [--quick]

Each measurement is a median of its runs after one warm-up (except where
said), timed with ``time.perf_counter``; every target of issue 11 is printed
with PASS or FAIL.  Nothing here is a test: the machine may be shared, so the
load average is printed at the start and at the end.

1. Building a new loop (derivation + kernels): ``symstab.Loop(plant,
   environment)``, its ``characteristic_polynomial()`` with a symbolic delay
   ``d`` (a plant on the numeric path gets its values), its
   ``affine_parameters()`` and a first ``classify()`` at its default values
   (which generates, writes and imports the loop's NumPy kernels and
   evaluates the plant's pulse transfer function).  Four loops: the paper's;
   an actuator lag ``1/((m s^2 + b s)(tau s + 1))`` (residues, a third
   pole); a two-mass device with a compliant transmission and an operator's
   arm holding the device (both with a quadratic or cubic factor: the
   matrix-exponential path).  Cold: in a fresh ``python`` subprocess per run
   (SymPy's caches empty), with ``SYMSTAB_CACHE_DIR`` a new empty folder;
   the build is timed inside the subprocess after ``import symstab`` (shown
   apart, with the subprocess's wall time).  Warm: in this process, a new
   empty cache folder and the loop's kernel module dropped from
   ``sys.modules`` before each run.  Target: < 10 s.  The verdict at the
   default values is checked against python-control's closed-loop poles.
2. Classification of a 100 x 100 (B, K) grid of the paper's device at
   d = 10, M = 0 and M = m (the window of ``bench_kernels.py``: alpha in
   [0, 0.03], beta in [-0.01, 0.3], in physical units): ``Loop.classify``
   (the per-loop kernel) against ``symstab.classify`` (the paper-specific
   kernel) on the same points, converted one by one with
   ``symstab.dimensionless_values`` outside the timing (target: within 2x),
   and against python-control per point (``c2d`` of the plant, eq. (1)'s
   environment, the delay, ``feedback``, ``.poles()``; also with the
   discretised plant built once), timed on a random subset
   (``--pc-points``) and extrapolated (target: >= 1000x).  The verdicts of
   the two kernels are compared on the whole grid, python-control's on the
   subset (poles within 1e-6 of the unit circle left out).
3. ``Loop.limits`` (B, K plane) and ``Loop.stable_intervals("K")`` (at the
   B of K_max) on the paper's loop at d = 0, 10, 40 and M = 0, m, against
   ``symstab.limits`` and ``StabilityRegion.alpha_intervals`` (medians of
   ``--limits-runs``), with the largest relative difference of their
   numbers (K_max, the B where it is reached, the B range, the area).

``--quick`` is a smoke run: 3 runs, 1 cold and 2 warm builds, 50
python-control points, 1 run of part 3 without a warm-up.
"""

import argparse
import importlib.util
import json
import os
import pathlib
import platform
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

from symstab.numeric.paper.device import PAPER_DEVICE

REPO = pathlib.Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "benchmarks"))
from _timing import fmt  # noqa: E402  (the benchmarks' shared helpers)

#: The paper's device, from its one home.
M_DEV, B_DEV, T_DEV = PAPER_DEVICE.m, PAPER_DEVICE.b, PAPER_DEVICE.T
PAPER_ENVIRONMENT = "K + B*(z - 1)/(T*z) + M*(z - 1)**2/(T**2*z**2)"
DEVICE = dict(m=M_DEV, b=B_DEV, T=T_DEV)
RENDERED = dict(K=2.0, B=0.1, M=0.0, d=10)

#: The loops built in part 1: name -> (plant, values).  All render the
#: paper's environment; the last two have a quadratic or cubic factor that
#: SymPy cannot split into linear ones (numeric ZOH).
LOOPS = {
    "paper": ("1/(m*s**2 + b*s)", dict(DEVICE)),
    "actuator lag": ("1/((m*s**2 + b*s)*(tau*s + 1))", dict(DEVICE, tau=2e-3)),
    "two-mass": ("(m2*s**2 + c*s + k)/(s*(m*m2*s**3 + (m*c + m2*c + b*m2)*s**2"
                 " + (m*k + m2*k + b*c)*s + b*k))",
                 dict(DEVICE, m2=0.005, k=1400.0, c=0.1)),
    "operator arm": ("1/((m + ma)*s**2 + (b + ba)*s + ka)", dict(DEVICE, ma=0.02, ba=0.5, ka=50.0)),
}
BUILD_TARGET = 10.0

N_GRID = 100
D_GRID = 10
ALPHA_WINDOW = (0.0, 0.03)
BETA_WINDOW = (-0.01, 0.3)
MASSES = (0.0, M_DEV)
NEAR_ONE = 1e-6
KERNEL_TARGET = 2.0
PC_TARGET = 1000.0
LIMIT_DELAYS = (0, 10, 40)

#: Run in a fresh interpreter by part 1 (argv: the loop's JSON).
BUILD_SCRIPT = r"""
import json, pathlib, sys, time
spec = json.loads(sys.argv[1])
start = time.perf_counter()
import symstab
imported = time.perf_counter()
loop = symstab.Loop(spec["plant"], spec["environment"], values=spec["values"], plane=("B", "K"))
given = {} if loop.zoh_method == "residues" else {k: v for k, v in spec["values"].items() if k != "d"}
loop.characteristic_polynomial(**given)
loop.affine_parameters()
code = loop.classify()
built = time.perf_counter()
kernel = loop.kernel_file()
print(json.dumps(dict(import_s=imported - start, build_s=built - imported, zoh=loop.zoh_method,
                      code=code, kernel=kernel)))
"""


def _times_interleaved(fns, runs, warmup=1):
    """As :func:`timed_runs` for several functions, run in turn so that they see the same load."""
    for _ in range(warmup):
        for fn in fns:
            fn()
    out = [[] for _ in fns]
    for _ in range(runs):
        for fn, times in zip(fns, out, strict=True):
            start = time.perf_counter()
            fn()
            times.append(time.perf_counter() - start)
    return out


def _verdict(ok):
    return "PASS" if ok else "FAIL"


def _ratio(value):
    return f"{value:,.0f}x" if value >= 10 else f"{value:.2g}x"


def _oracles():
    """tests/oracles.py as a module (eq1_virtual_environment)."""
    spec = importlib.util.spec_from_file_location("_symstab_test_oracles", REPO / "tests" / "oracles.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


# --------------------------------------------------------------------------
# 1. Building a loop


def _spec(name):
    plant, values = LOOPS[name]
    return dict(plant=plant, environment=PAPER_ENVIRONMENT, values=dict(values, **RENDERED))


def _build_cold(spec):
    """One cold build in a fresh interpreter: (wall s, the script's JSON)."""
    with tempfile.TemporaryDirectory(prefix="symstab-bench-cache-") as cache:
        env = dict(os.environ, SYMSTAB_CACHE_DIR=cache)
        start = time.perf_counter()
        out = subprocess.run([sys.executable, "-c", BUILD_SCRIPT, json.dumps(spec)], env=env,
                             check=True, capture_output=True, text=True).stdout
        wall = time.perf_counter() - start
        result = json.loads(out.splitlines()[-1])
        # The kernel must have been generated into the empty folder, not found elsewhere.
        result["fresh"] = bool(result["kernel"]) and result["kernel"].startswith(cache)
    return wall, result


def _build_warm(spec):
    """One build in this process with an empty kernel cache; returns (seconds, loop)."""
    import symstab

    with tempfile.TemporaryDirectory(prefix="symstab-bench-cache-") as cache:
        saved = os.environ.get("SYMSTAB_CACHE_DIR")
        os.environ["SYMSTAB_CACHE_DIR"] = cache
        for key in [k for k in sys.modules if k.startswith("symstab_loop_")]:
            del sys.modules[key]   # else load_numpy_kernels reuses the imported module
        try:
            start = time.perf_counter()
            loop = symstab.Loop(spec["plant"], spec["environment"], values=spec["values"],
                                plane=("B", "K"))
            given = {} if loop.zoh_method == "residues" else {
                k: v for k, v in spec["values"].items() if k != "d"}
            loop.characteristic_polynomial(**given)
            loop.affine_parameters()
            loop.classify()
            elapsed = time.perf_counter() - start
        finally:
            if saved is None:
                del os.environ["SYMSTAB_CACHE_DIR"]
            else:
                os.environ["SYMSTAB_CACHE_DIR"] = saved
    return elapsed, loop


def _python_control_radius(spec):
    """Largest closed-loop pole modulus at the loop's values, built with python-control alone."""
    import control
    import sympy as sp

    values = spec["values"]
    s, z = sp.symbols("s z")
    names = {k: sp.Symbol(k) for k in values}
    plant = sp.sympify(spec["plant"], locals=dict(names, s=s))
    env = sp.sympify(spec["environment"], locals=dict(names, z=z))
    sub = {names[k]: sp.Float(v, 30) for k, v in values.items() if k != "d"}

    def tf(expr, var, dt=None):
        num, den = sp.fraction(sp.cancel(sp.together(expr.subs(sub))))
        coeffs = [[float(c) for c in sp.Poly(p, var).all_coeffs()] for p in (num, den)]
        return control.tf(*coeffs) if dt is None else control.tf(*coeffs, dt)

    T = values["T"]
    G = control.c2d(tf(plant, s), T, "zoh")
    delay = control.tf([1], [1] + [0] * values["d"], T)
    return float(np.max(np.abs(control.feedback(G, tf(env, z, T) * delay).poles())))


def bench_build(args):
    print(f"\n1. Building a new loop (Loop + characteristic_polynomial + affine_parameters + first "
          f"classify with kernel generation), empty kernel cache; target < {BUILD_TARGET:g} s")
    print(f"   cold: fresh subprocess per run ({args.build_runs} run(s), no warm-up); "
          f"warm: in this process ({args.warm_runs} runs after a warm-up)")
    print(f"  {'loop':<14} {'zoh':<19} {'cold build':>11} {'import':>8} {'subprocess':>11} "
          f"{'warm build':>11}  {'target':<6} verdict vs python-control")
    worst, failed = 0.0, False
    for name in LOOPS:
        spec = _spec(name)
        try:
            cold = [_build_cold(spec) for _ in range(args.build_runs)]
            _build_warm(spec)
        except (subprocess.CalledProcessError, TypeError, ValueError) as exc:
            # A loop the library cannot build is a result here (a FAIL), not the end of the run.
            text = (exc.stderr or "").strip().splitlines()[-1:] if isinstance(
                exc, subprocess.CalledProcessError) else [f"{type(exc).__name__}: {exc}"]
            print(f"  {name:<14} ERROR (FAIL): {text[0] if text else exc}")
            failed = True
            continue
        build = statistics.median(r["build_s"] for _, r in cold)
        imported = statistics.median(r["import_s"] for _, r in cold)
        wall = statistics.median(w for w, _ in cold)
        fresh = all(r["fresh"] for _, r in cold)
        warm_runs = [_build_warm(spec) for _ in range(args.warm_runs)]
        warm = statistics.median(t for t, _ in warm_runs)
        loop = warm_runs[-1][1]
        code = loop.classify()
        radius = _python_control_radius(spec)
        agrees = (code == 1) == (radius < 1) and abs(radius - 1) > NEAR_ONE
        worst = max(worst, build, warm)
        print(f"  {name:<14} {cold[0][1]['zoh']:<19} {fmt(build):>11} {fmt(imported):>8} "
              f"{fmt(wall):>11} {fmt(warm):>11}  {_verdict(max(build, warm) < BUILD_TARGET):<6} "
              f"code {code:+d}, radius {radius:.6f}: {'agree' if agrees else 'DISAGREE'}"
              + ("" if fresh else "  (kernel NOT written to the empty cache!)"))
    print(f"   target: build < {BUILD_TARGET:g} s -> {_verdict(worst < BUILD_TARGET and not failed)} "
          f"(slowest median {fmt(worst)}; the cold subprocess adds the interpreter and import)")


# --------------------------------------------------------------------------
# 2. Grid classification


def _paper_loop():
    import symstab

    return symstab.load_loop(REPO / "examples" / "loops" / "paper.toml")


def bench_classify(args, oracles):
    import control

    import symstab
    from symstab.numeric.engine.roots import MARGINAL, STABLE

    loop = _paper_loop()
    m, b, T = M_DEV, B_DEV, T_DEV
    K, B = np.meshgrid(np.linspace(*ALPHA_WINDOW, N_GRID) * m / T**2,
                       np.linspace(*BETA_WINDOW, N_GRID) * m / T)
    n_points = K.size
    rng = np.random.default_rng(args.seed)
    subset = rng.choice(n_points, size=min(args.pc_points, n_points), replace=False)
    k_flat, b_flat = K.ravel(), B.ravel()

    Gd = control.c2d(control.tf([1], [m, b, 0]), T, "zoh")
    zc = control.tf([1, 0], [1], T)
    delay = control.tf([1], [1] + [0] * D_GRID, T)

    def pc_full(K_w, B_w, M_w):
        G = control.c2d(control.tf([1], [m, b, 0]), T, "zoh")
        return control.feedback(G, oracles.eq1_virtual_environment(zc, K_w, B_w, M_w, T) * delay)

    def pc_hoisted(K_w, B_w, M_w):
        return control.feedback(Gd, oracles.eq1_virtual_environment(zc, K_w, B_w, M_w, T) * delay)

    print(f"\n2. Classification of a {N_GRID} x {N_GRID} (B, K) grid of the paper's device, d = {D_GRID}, "
          f"K in [0, {ALPHA_WINDOW[1] * m / T**2:g}] N/m, B in [{BETA_WINDOW[0] * m / T:g}, "
          f"{BETA_WINDOW[1] * m / T:g}] N s/m")
    print(f"   python-control timed per point on {len(subset)} random grid points (seed {args.seed}); "
          f"~ = extrapolated to the grid")
    print(f"  {'method':<46} {'grid total':>11} {'per point':>10} {'vs Loop':>9}")
    kernel_ratios, pc_ratios = [], []
    for M_w in MASSES:
        print(f" M = {M_w:g} kg")
        kw = dict(K=K, B=B, M=M_w, d=D_GRID)

        def convert(K_w, B_w, M_w=M_w):
            v = symstab.dimensionless_values(m=m, b=b, T=T, K_w=K_w, B_w=B_w, M_w=M_w, Td=D_GRID * T)
            return v["alpha"], v["beta"], v["gamma"], v["delta"], v["d"]

        start = time.perf_counter()
        alpha, beta, gamma, delta, d = np.vectorize(convert)(K, B)
        t_convert = time.perf_counter() - start
        # gamma, delta and d are the same at every point: pass them as scalars.
        dkw = dict(alpha=alpha, beta=beta, gamma=float(gamma.flat[0]), delta=float(delta.flat[0]),
                   d=int(d.flat[0]))
        codes, paper_codes = loop.classify(**kw), symstab.classify(**dkw)
        t_loop, t_paper = (statistics.median(t) for t in _times_interleaved(
            [lambda kw=kw: loop.classify(**kw), lambda dkw=dkw: symstab.classify(**dkw)],
            args.runs))
        per_loop = t_loop / n_points
        kernel_ratios.append(t_loop / t_paper)
        print(f"  {'Loop.classify (per-loop kernel)':<46} {fmt(t_loop):>11} {fmt(per_loop):>10} "
              f"{'1x':>9}")
        print(f"  {'symstab.classify (paper kernel, alpha..delta)':<46} {fmt(t_paper):>11} "
              f"{fmt(t_paper / n_points):>10} {_ratio(t_paper / t_loop):>9}  "
              f"(+ {fmt(t_convert)} once: dimensionless_values per point)")

        builds = {"c2d in": pc_full, "Gd once": pc_hoisted}
        for build in builds.values():
            for k in subset[:3]:
                build(k_flat[k], b_flat[k], M_w).poles()
        per = {name: [] for name in builds}
        radii = {name: [] for name in builds}
        for k in subset:
            for name, build in builds.items():
                start = time.perf_counter()
                poles = build(k_flat[k], b_flat[k], M_w).poles()
                per[name].append(time.perf_counter() - start)
                radii[name].append(np.max(np.abs(poles)))
        for name in builds:
            per_pc = statistics.median(per[name])
            pc_ratios.append(per_pc / per_loop)
            print(f"  {'python-control per point (' + name + ')':<46} {'~' + fmt(per_pc * n_points):>11} "
                  f"{fmt(per_pc):>10} {_ratio(per_pc / per_loop):>9}")

        flat, paper_flat = codes.ravel(), paper_codes.ravel()
        differ = np.flatnonzero(flat != paper_flat)
        print(f"   Loop.classify vs symstab.classify: {n_points - differ.size}/{n_points} verdicts agree "
              f"(stable {np.count_nonzero(flat == STABLE)}, marginal {np.count_nonzero(flat == MARGINAL)})")
        for k in differ[:5]:
            print(f"     differ at K = {k_flat[k]:.6g}, B = {b_flat[k]:.6g}: Loop {int(flat[k]):+d}, "
                  f"paper {int(paper_flat[k]):+d}")
        r_pc = np.array(radii["c2d in"])
        sub = flat[subset]
        decided = (np.abs(r_pc - 1.0) > NEAR_ONE) & (sub != MARGINAL)
        agree = np.count_nonzero(((sub == STABLE) == (r_pc < 1.0)) & decided)
        print(f"   Loop.classify vs python-control on the subset: {agree}/{np.count_nonzero(decided)} agree "
              f"({np.count_nonzero(~decided)} left out: marginal or |radius - 1| <= {NEAR_ONE:g})")
    worst_kernel, worst_pc = max(kernel_ratios), min(pc_ratios)
    print(f"   target: Loop.classify within {KERNEL_TARGET:g}x of symstab.classify -> "
          f"{_verdict(worst_kernel <= KERNEL_TARGET)} (Loop / paper: "
          + ", ".join(f"{r:.2f}x" for r in kernel_ratios) + ")")
    print(f"   target: >= {PC_TARGET:,.0f}x python-control per point -> {_verdict(worst_pc >= PC_TARGET)} "
          f"(worst {worst_pc:,.0f}x)")


# --------------------------------------------------------------------------
# 3. Limits and stable intervals


def _rel(a, b):
    """|a - b| relative to the larger magnitude (0 when both are 0)."""
    scale = max(abs(a), abs(b))
    return 0.0 if scale == 0 else abs(a - b) / scale


def bench_limits(args):
    import symstab

    loop = _paper_loop()
    m, b, T = M_DEV, B_DEV, T_DEV
    delta = b * T / m
    warmup = 0 if args.quick else 1
    print(f"\n3. Limits in the (B, K) plane and stable K intervals, paper's loop (median of "
          f"{args.limits_runs} run(s){' after a warm-up' if warmup else ''})")
    print("   stable_intervals('K') vs alpha_intervals at B = 1/4, 1/2, 3/4 of the stable B range "
          "(timed at 1/2); lower ends (0, or a minimum stiffness) compared in units of K_max")
    print(f"  {'d':>3} {'M':>7} {'Loop.limits':>12} {'symstab.limits':>15} {'ratio':>7} "
          f"{'stable_intervals':>17} {'alpha_intervals':>16}  {'K_max (N/m)':<12}  "
          f"largest relative difference")
    worst_all = 0.0
    for d in LIMIT_DELAYS:
        for M_w in MASSES:
            gamma = M_w / m
            t_loop, t_paper = (statistics.median(t) for t in _times_interleaved(
                [lambda d=d, M_w=M_w: loop.limits(d=d, M=M_w),
                 lambda d=d, gamma=gamma: symstab.limits(gamma=gamma, d=d, delta=delta)],
                args.limits_runs, warmup))
            lim, ref = loop.limits(d=d, M=M_w), symstab.limits(gamma=gamma, d=d, delta=delta)
            k_max = ref.alpha_max * m / T**2
            numbers = {
                "K_max": (lim.y_max, k_max),
                "B at K_max": (lim.x_at_y_max, ref.beta_at_alpha_max * m / T),
                "B_min": (lim.x_min, ref.beta_left * m / T),
                "B_max": (lim.x_max, ref.beta_right * m / T),
                "area": (lim.area, ref.z_width * m**2 / T**3),
            }
            diffs = {k: _rel(*v) for k, v in numbers.items()}
            betas = [ref.beta_left + f * (ref.beta_right - ref.beta_left) for f in (0.25, 0.5, 0.75)]
            t_int, t_ref_int = (statistics.median(t) for t in _times_interleaved(
                [lambda d=d, M_w=M_w, betas=betas:
                 loop.stable_intervals("K", B=betas[1] * m / T, M=M_w, d=d),
                 lambda ref=ref, betas=betas: ref.region.alpha_intervals(betas[1])],
                args.limits_runs, warmup))
            ends = []
            for beta in betas:
                got = loop.stable_intervals("K", B=beta * m / T, M=M_w, d=d)
                want = [(lo * m / T**2, hi * m / T**2) for lo, hi in ref.region.alpha_intervals(beta)]
                if len(got) != len(want):
                    ends.append(np.inf)
                    print(f"     B = {beta * m / T:.6g}: Loop {got} vs paper {want}")
                    continue
                ends += [abs(g[0] - w[0]) / k_max for g, w in zip(got, want, strict=True)]
                ends += [_rel(g[1], w[1]) for g, w in zip(got, want, strict=True)]
            diffs["K intervals"] = max(ends, default=0.0)
            worst = max(diffs, key=diffs.get)
            worst_all = max(worst_all, diffs[worst])
            print(f"  {d:>3} {M_w:>7g} {fmt(t_loop):>12} {fmt(t_paper):>15} {t_loop / t_paper:>6.1f}x "
                  f"{fmt(t_int):>17} {fmt(t_ref_int):>16}  {lim.y_max:<12.6g}  "
                  + ", ".join(f"{k} {v:.1e}" for k, v in diffs.items()))
    print(f"   Loop vs symstab.limits: largest relative difference {worst_all:.1e} (one engine: "
          f"symstab.limits is Loop.limits at m = T = 1; the difference is the units' rounding, "
          f"amplified to about sqrt(eps) in B at K_max, the argmax of a flat top; the K intervals "
          f"come from the one line engine in both units)")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=None, help="timed runs of part 2 (default 7)")
    parser.add_argument("--build-runs", type=int, default=None,
                        help="cold builds (fresh subprocesses) per loop (default 3)")
    parser.add_argument("--warm-runs", type=int, default=None, help="warm builds per loop (default 5)")
    parser.add_argument("--pc-points", type=int, default=None,
                        help="grid points timed with python-control per M (default 200)")
    parser.add_argument("--limits-runs", type=int, default=None, help="runs of part 3 (default 3)")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--parts", default="123", help="which parts to run, e.g. 13 (default 123)")
    parser.add_argument("--quick", action="store_true",
                        help="smoke run: 3 runs, 1 cold and 2 warm builds, 50 python-control points, "
                             "1 run of part 3")
    args = parser.parse_args()
    quick = dict(runs=3, build_runs=1, warm_runs=2, pc_points=50, limits_runs=1)
    full = dict(runs=7, build_runs=3, warm_runs=5, pc_points=200, limits_runs=3)
    for key, value in (quick if args.quick else full).items():
        if getattr(args, key) is None:
            setattr(args, key, value)

    import control

    start = time.perf_counter()
    print(f"symstab.Loop benchmarks{' (--quick)' if args.quick else ''}: medians after a warm-up, "
          f"time.perf_counter")
    print(f"python {platform.python_version()}, numpy {np.__version__}, python-control {control.__version__}, "
          f"{platform.machine()}, {os.cpu_count()} CPUs")
    print(f"device: m = {M_DEV}, b = {B_DEV}, T = {T_DEV}; environment VE(z) = {PAPER_ENVIRONMENT}")
    print("load average (1, 5, 15 min) at start: " + ", ".join(f"{x:.2f}" for x in os.getloadavg()))
    with tempfile.TemporaryDirectory(prefix="symstab-bench-cache-") as cache:
        # Parts 2 and 3 write the paper loop's kernel here, not under ~/.cache.
        os.environ["SYMSTAB_CACHE_DIR"] = cache
        if "1" in args.parts:
            bench_build(args)
        if "2" in args.parts:
            bench_classify(args, _oracles())
        if "3" in args.parts:
            bench_limits(args)
    print(f"\ntotal benchmark time {time.perf_counter() - start:.1f} s; load average at end: "
          + ", ".join(f"{x:.2f}" for x in os.getloadavg()))


if __name__ == "__main__":
    main()
