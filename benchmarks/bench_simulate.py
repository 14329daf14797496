"""Throughput of the plant simulator against a per-point scipy.signal.dlsim loop (run by hand).

    python benchmarks/bench_simulate.py [--runs 5] [--dlsim-points 40]

1. symstab.numeric.paper.simulate.simulate on a 100 x 100 (alpha, beta) grid at d = 10 on
   the paper's device, ideal loop, 8000 periods: point-steps per second
   (median of ``--runs``).
2. The obvious alternative, side by side in the same run: for each point of
   a random subset of the same grid, the closed loop as a discrete
   state-space system (companion form of the characteristic polynomial,
   built outside the timing) simulated by ``scipy.signal.dlsim`` from an
   initial state for the same number of periods; point-steps per second,
   median over the subset.

3. The same grid through ``PAPER_LOOP.simulate`` (:meth:`symstab.Loop.simulate`,
   the simulator of any loop: the derived P(z)'s difference equation), in
   the same run: its rate and its ratio to (1).
4. (3) with a force quantum of 1 mN m: the run, the certified root counts
   and the force-pulse response whose l1 norm is the verdict's floor at the
   stable points; its cost over (3).
5. (3) with a delay that varies, uniform on the whole samples 8..12
   (``delays=("uniform", 8, 12)``, run one period at a time): its rate and
   its ratio to (3), the fixed delay run in blocks.

Prints the rates and their ratios (targets: >= 5e7 point-steps/s, >= 100x
over dlsim).
"""

import argparse
import os
import statistics
import time

import numpy as np
import scipy.signal

import symstab
from symstab.numeric.paper.simulate import simulate
from symstab.numeric.paper.stability import loop_coefficients
from symstab.numeric.simulation.simulator import Nonidealities


def _companion(coeffs):
    """A discrete state-space system whose poles are the roots of ``coeffs``."""
    c = np.asarray(coeffs, dtype=float) / coeffs[0]
    n = len(c) - 1
    A = np.zeros((n, n))
    A[0, :] = -c[1:]
    A[np.arange(1, n), np.arange(n - 1)] = 1.0
    B = np.zeros((n, 1))
    B[0, 0] = 1.0
    C = np.zeros((1, n))
    C[0, -1] = 1.0
    return A, B, C, np.zeros((1, 1))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=5)
    parser.add_argument("--dlsim-points", type=int, default=40)
    parser.add_argument("--steps", type=int, default=8000)
    args = parser.parse_args()
    dev, d = symstab.PAPER_DEVICE, 10
    alpha = np.linspace(0.0, 0.025, 100)
    beta = np.linspace(-0.01, 0.2, 100)
    A, B = np.meshgrid(alpha, beta, indexing="ij")
    print(f"numpy {np.__version__}, scipy {scipy.__version__}, {os.cpu_count()} CPUs; "
          f"OPENBLAS_CORETYPE {'set' if 'OPENBLAS_CORETYPE' in os.environ else 'not set'}")
    print(f"grid 100 x 100, d = {d}, delta = {dev.delta:.6g}, {args.steps} periods")

    simulate(alpha=A, beta=B, gamma=0.0, d=d, delta=dev.delta, steps=200)  # warm-up
    times = []
    for _ in range(args.runs):
        start = time.perf_counter()
        simulate(alpha=A, beta=B, gamma=0.0, d=d, delta=dev.delta, steps=args.steps)
        times.append(time.perf_counter() - start)
    ours = A.size * args.steps / statistics.median(times)

    rng = np.random.default_rng(0)
    pick = rng.choice(A.size, size=args.dlsim_points, replace=False)
    u = np.zeros(args.steps)
    rates = []
    for k in pick:
        coeffs = loop_coefficients(alpha=A.flat[k], beta=B.flat[k], gamma=0.0, d=d, delta=dev.delta)
        system = _companion(coeffs) + (1.0,)
        x0 = np.ones(len(coeffs) - 1)
        start = time.perf_counter()
        scipy.signal.dlsim(system, u, x0=x0)
        rates.append(args.steps / (time.perf_counter() - start))
    theirs = statistics.median(rates)

    loop = symstab.load_loop(os.path.join(os.path.dirname(__file__), "..", "examples", "loops",
                                          "paper.toml"))
    K, Bw = dev.stiffness(A), dev.damping(B)
    loop.simulate(K=K, B=Bw, d=d, M=0.0, steps=200)   # warm-up (derivation, kernels)
    loop_times = []
    for _ in range(args.runs):
        start = time.perf_counter()
        loop.simulate(K=K, B=Bw, d=d, M=0.0, steps=args.steps)
        loop_times.append(time.perf_counter() - start)
    any_loop = A.size * args.steps / statistics.median(loop_times)
    quantum = Nonidealities(force_resolution=1e-3)
    quantum_times = []
    for _ in range(args.runs):
        start = time.perf_counter()
        loop.simulate(K=K, B=Bw, d=d, M=0.0, steps=args.steps, nonideal=quantum)
        quantum_times.append(time.perf_counter() - start)
    varying_times = []
    for _ in range(args.runs):
        start = time.perf_counter()
        loop.simulate(K=K, B=Bw, M=0.0, steps=args.steps, delays=("uniform", 8, 12))
        varying_times.append(time.perf_counter() - start)
    varying = A.size * args.steps / statistics.median(varying_times)
    print(f"  symstab.numeric.paper.simulate (all points at once)   {ours:10.3g} point-steps/s "
          f"(median {statistics.median(times):.2f} s per run)")
    print(f"  scipy.signal.dlsim per point            {theirs:10.3g} point-steps/s "
          f"(median over {args.dlsim_points} points)")
    print(f"  Loop.simulate (paper.toml, any loop's)  {any_loop:10.3g} point-steps/s "
          f"(median {statistics.median(loop_times):.2f} s per run)")
    print(f"  ratio {ours / theirs:,.0f}x  (targets: >= 5e7 point-steps/s, >= 100x)")
    print(f"  Loop.simulate / the paper's simulator: {any_loop / ours:.2f}")
    print(f"  Loop.simulate with a 1 mN m force quantum: median "
          f"{statistics.median(quantum_times):.2f} s per run, "
          f"{statistics.median(quantum_times) / statistics.median(loop_times):.2f}x the ideal run")
    print(f"  Loop.simulate with a varying delay (uniform 8..12) {varying:10.3g} point-steps/s "
          f"(median {statistics.median(varying_times):.2f} s per run, "
          f"{statistics.median(varying_times) / statistics.median(loop_times):.2f}x the fixed d)")


if __name__ == "__main__":
    main()
