"""Tests of the time-domain simulator :mod:`symstab.numeric.paper.simulate`.

Oracles, none of them the simulator's own code:

* the exact ZOH step of ``m x'' + b x' = f`` from python-control's ``c2d``,
  scipy's ``cont2discrete`` and a 40-digit mpmath evaluation of the closed
  forms;
* eq. (1) of the paper written out by hand;
* :func:`oracle_trajectory`: a plain Python loop in *physical* units (plant
  discretised by scipy, force of eq. (1) with ``K_w, B_w, M_w``, a delay line
  of ``d`` samples), optionally with an encoder quantizer and the velocity
  filter as the module docstring specifies them; it never goes through
  Table I's scaling;
* the exact closed-form motion of a device under Coulomb friction;
* for stability: :func:`symstab.classify` / :func:`symstab.spectral_radius`
  (independent of the simulator: polynomial roots) and python-control's
  closed-loop poles (:func:`oracles.python_control_closed_loop`).
"""

import math
import time

import control
import mpmath
import numpy as np
import pytest
import scipy.signal

import symstab
from symstab._generated import kernels
from symstab.numeric.paper.curves import minus_one_line
from symstab.numeric.paper.simulate import simulate, stability_map
from symstab.numeric.simulation.simulator import (
    PAPER_ENCODER_RESOLUTION,
    Nonidealities,
    default_horizon,
)

from conftest import PAPER_B, PAPER_DELTA, PAPER_M, PAPER_T, assert_message_names
from oracles import python_control_closed_loop

PAPER_DEVICE = symstab.Device(m=PAPER_M, b=PAPER_B, T=PAPER_T)


# --------------------------------------------------------------------------
# Independent oracles
# --------------------------------------------------------------------------

def zoh_plant(m, b, T, *, lag_bandwidth=None):
    """``(Ad, Bd)`` of ``m x'' + b x' = f`` (state ``(x, v)``) under a ZOH, by scipy.

    With ``lag_bandwidth`` (Hz) the applied force ``a`` follows the held
    command ``u`` through ``a' = w (u - a)``, ``w = 2 pi lag_bandwidth``: the
    state is ``(x, v, a)`` and the step is exact for the continuous lag.
    """
    if lag_bandwidth is None:
        A = np.array([[0.0, 1.0], [0.0, -b / m]])
        B = np.array([[0.0], [1.0 / m]])
    else:
        w = 2 * math.pi * lag_bandwidth
        A = np.array([[0.0, 1.0, 0.0], [0.0, -b / m, 1.0 / m], [0.0, 0.0, -w]])
        B = np.array([[0.0], [0.0], [w]])
    n = A.shape[0]
    Ad, Bd, *_ = scipy.signal.cont2discrete((A, B, np.eye(n), np.zeros((n, 1))), T, method="zoh")
    return Ad, Bd[:, 0]


def oracle_trajectory(*, K_w, B_w, M_w, d, m, b, T, x0, v0, steps, quantum=None, cutoff=None,
                      lag_bandwidth=None):
    """Positions ``x(0..steps)`` of the sampled loop, written from the paper.

    Physical units throughout (``v0`` in m/s or rad/s).  Every period the
    position is sampled (rounded to ``quantum`` if given), the environment of
    eq. (1) computes ``f(k) = -(K_w xs(k) + B_w (xs(k) - xs(k-1)) / T + M_w
    (xs(k) - 2 xs(k-1) + xs(k-2)) / T**2)`` with the history ``xs(-1) =
    xs(-2) = xs(0)``; the device receives ``f(k - d)`` (zero before ``k =
    d``: an empty delay line) through a ZOH.  With ``cutoff`` (Hz) the damper
    and the mass see ``vf(k) = a vf(k-1) + (1 - a) (xs(k) - xs(k-1)) / T``,
    ``a = exp(-2 pi cutoff T)``, ``vf(-1) = 0``: ``f = -(K_w xs + B_w vf(k) +
    M_w (vf(k) - vf(k-1)) / T)`` (the module docstring's filter).
    """
    Ad, Bd = zoh_plant(m, b, T, lag_bandwidth=lag_bandwidth)
    sample = (lambda x: quantum * round(x / quantum)) if quantum else (lambda x: x)
    pole = math.exp(-2 * math.pi * cutoff * T) if cutoff else None
    state = np.zeros(Ad.shape[0])
    state[0], state[1] = x0, v0
    x1 = x2 = sample(x0)
    v_filtered = 0.0
    forces, out = [], [x0]
    for k in range(steps):
        xs = sample(state[0])
        if pole is None:
            f = -(K_w * xs + B_w * (xs - x1) / T + M_w * (xs - 2 * x1 + x2) / T**2)
        else:
            v_new = pole * v_filtered + (1 - pole) * (xs - x1) / T
            f = -(K_w * xs + B_w * v_new + M_w * (v_new - v_filtered) / T)
            v_filtered = v_new
        forces.append(f)
        x2, x1 = x1, xs
        held = forces[k - d] if k >= d else 0.0
        state = Ad @ state + Bd * held
        out.append(state[0])
    return np.array(out)


def physical(alpha, beta, gamma, m, T):
    """Table I backwards: ``(K_w, B_w, M_w)``."""
    return dict(K_w=alpha * m / T**2, B_w=beta * m / T, M_w=gamma * m)


def relative_max_difference(actual, expected):
    """``max |actual - expected| / max |expected|`` over a trajectory."""
    return float(np.max(np.abs(np.asarray(actual) - expected)) / np.max(np.abs(expected)))


# --------------------------------------------------------------------------
# The plant step and the environment force (NumPy kernels)
# --------------------------------------------------------------------------

PLANT_DELTAS = (1e-6, 1e-3, PAPER_DELTA, 0.3, 1.0, 5.0)


def _closed_forms_mp(delta):
    """phi01, phi11, gamma0, gamma1 at 40 digits, from the ZOH integrals by hand.

    exp(A) with A = [[0, 1], [0, -delta]]: Phi[0,1] = (1 - e^-delta) / delta,
    Phi[1,1] = e^-delta; Gamma_u = int_0^1 exp(A s) ds [0, 1]:
    Gamma_u[0] = (delta - 1 + e^-delta) / delta^2, Gamma_u[1] = (1 - e^-delta) / delta.
    """
    with mpmath.workdps(40):
        dl = mpmath.mpf(delta)
        e = mpmath.exp(-dl)
        return [(1 - e) / dl, e, (dl - 1 + e) / dl**2, (1 - e) / dl]


@pytest.mark.parametrize("delta", PLANT_DELTAS, ids=[f"delta={x:g}" for x in PLANT_DELTAS])
def test_plant_step_coefficients_match_zoh_discretisation(delta):
    """phi01, phi11, gamma0, gamma1 vs c2d, cont2discrete and 40-digit mpmath, to 1e-12.

    m = T = 1 and b = delta, so the state (x, v) is Table I's (x, v T) and
    the force f is f T^2 / m.  Which reference is the oracle: all three are
    asserted.  Measured, scipy's expm of the augmented matrix (used by both
    c2d and cont2discrete) does *not* lose digits at delta = 1e-6: it is
    within 2.2e-16 of the mpmath values at every delta here, and the kernel
    within 1.6e-16.  The mpmath values are the primary oracle; the scipy ones
    are compared to them too, so a failure says which side drifted.
    """
    b = delta
    sys_c = control.ss([[0.0, 1.0], [0.0, -b]], [[0.0], [1.0]], [[1.0, 0.0]], [[0.0]])
    sys_d = control.c2d(sys_c, 1.0, "zoh")
    Ad, Bd = np.asarray(sys_d.A), np.asarray(sys_d.B)[:, 0]
    Ad2, Bd2 = zoh_plant(1.0, b, 1.0)
    exact = _closed_forms_mp(delta)
    kernel = [float(c) for c in kernels.plant_step_coefficients(delta)]
    names = ("phi01", "phi11", "gamma0", "gamma1")
    refs = {"python-control c2d": [Ad[0, 1], Ad[1, 1], Bd[0], Bd[1]],
            "scipy cont2discrete": [Ad2[0, 1], Ad2[1, 1], Bd2[0], Bd2[1]]}
    failures = []
    for name, value, ref in zip(names, kernel, exact, strict=True):
        err = float(abs((mpmath.mpf(value) - ref) / ref))
        if not err <= 1e-12:
            failures.append(f"kernel {name} = {value!r} vs mpmath {mpmath.nstr(ref, 20)}: {err:.3g}")
    for label, values in refs.items():
        for name, value, ref in zip(names, values, exact, strict=True):
            err = float(abs((mpmath.mpf(float(value)) - ref) / ref))
            if not err <= 1e-12:
                failures.append(f"{label} {name} = {value!r} vs mpmath {mpmath.nstr(ref, 20)}: "
                                f"{err:.3g} (reference inaccurate)")
            kerr = abs(kernel[names.index(name)] - float(value)) / abs(float(value))
            if not kerr <= 1e-12:
                failures.append(f"kernel {name} vs {label}: relative difference {kerr:.3g}")
    # The kernel assumes Phi[0,0] = 1 and Phi[1,0] = 0: the references must agree.
    assert Ad[0, 0] == pytest.approx(1.0, abs=1e-15) and Ad[1, 0] == pytest.approx(0.0, abs=1e-15)
    assert not failures, "\n".join(failures)


def test_plant_step_matches_state_space_update():
    """plant_step(x, vT, fT^2/m, delta) = Ad (x, v) + Bd f on seeded random points.

    Ad, Bd from scipy (m = T = 1, b = delta); the error is measured relative
    to the size of the terms, |x| + |Ad01 v| + |Bd0 f| (a cancelling sum
    has no relative accuracy of its own).
    """
    rng = np.random.default_rng(11)
    n = 300
    delta = 10 ** rng.uniform(-6, np.log10(5.0), n)
    x, v, f = (rng.uniform(-10, 10, n) for _ in range(3))
    x_next, v_next = kernels.plant_step(x, v, f, delta)
    worst = (0.0, None)
    for k in range(n):
        Ad, Bd = zoh_plant(1.0, delta[k], 1.0)
        ref = Ad @ np.array([x[k], v[k]]) + Bd * f[k]
        scale = np.abs(Ad) @ np.abs([x[k], v[k]]) + np.abs(Bd * f[k])
        err = max(abs(x_next[k] - ref[0]) / scale[0], abs(v_next[k] - ref[1]) / scale[1])
        worst = max(worst, (err, k), key=lambda t: t[0])
    k = worst[1]
    assert worst[0] <= 1e-12, (f"plant_step off by {worst[0]:.3g} (relative to the terms) at "
                               f"delta={delta[k]!r}, x={x[k]!r}, v={v[k]!r}, f={f[k]!r}")


def test_environment_force_is_eq1():
    """environment_force = -(alpha x_k + beta (x_k - x_km1) + gamma (x_k - 2 x_km1 + x_km2)).

    Eq. (1) times T^2/m, written here by hand; compared relative to the size
    of the terms (the force itself may cancel).
    """
    rng = np.random.default_rng(5)
    n = 5000
    xk, xk1, xk2 = (rng.uniform(-5, 5, n) for _ in range(3))
    alpha, beta, gamma = rng.uniform(-1, 5, n), rng.uniform(-2, 3, n), rng.uniform(-0.9, 3, n)
    got = kernels.environment_force(xk, xk1, xk2, alpha, beta, gamma)
    expected = -(alpha * xk + beta * (xk - xk1) + gamma * (xk - 2 * xk1 + xk2))
    scale = (np.abs(alpha * xk) + np.abs(beta) * (np.abs(xk) + np.abs(xk1))
             + np.abs(gamma) * (np.abs(xk) + 2 * np.abs(xk1) + np.abs(xk2)))
    err = np.abs(got - expected) / scale
    k = int(np.argmax(err))
    assert err[k] <= 1e-14, f"environment_force off by {err[k]:.3g} of its terms at point {k}"
    # Scalars, and the sign: a positive spring displacement gives a restoring force.
    assert kernels.environment_force(1.0, 1.0, 1.0, 2.0, 0.0, 0.0) == -2.0
    assert kernels.environment_force(1.0, 0.0, 0.0, 0.0, 3.0, 0.0) == -3.0
    assert kernels.environment_force(1.0, 0.0, 0.0, 0.0, 0.0, 0.5) == -0.5


# --------------------------------------------------------------------------
# Ideal loop: trajectory and decay rate
# --------------------------------------------------------------------------

#: (alpha, beta, gamma, d, x0, v0 T): stable and unstable, every term active.
TRAJECTORY_POINTS = [
    (0.3, 0.5, 0.5, 0, 0.7, -0.01),
    (0.9, 0.8, 0.0, 0, 1.0, 0.02),      # unstable (alpha_max = 0.69 at gamma = 0)
    (0.1, 0.3, -0.4, 1, -0.3, 0.0),
    (0.05, 0.2, -0.3, 3, 0.7, -0.01),   # unstable (rho = 1.07)
    (0.02, 0.1, 1.0, 10, 2.0, 0.05),
    (0.0, 0.2, 0.3, 4, 1.0, 0.01),      # no spring: drifts on the z = 1 mode
]


@pytest.mark.parametrize("point", TRAJECTORY_POINTS,
                         ids=[f"a={p[0]}-b={p[1]}-g={p[2]}-d={p[3]}" for p in TRAJECTORY_POINTS])
def test_ideal_trajectory_matches_independent_recursion(point):
    """200 steps on the paper's device equal the physical-units recursion to 1e-10.

    The simulator's state is (x, v T), its history starts at x0 and its delay
    line is empty; the oracle gets v0 = (v T) / T in rad/s.  Measured: within
    3e-14 of max |x|.
    """
    alpha, beta, gamma, d, x0, v0T = point
    run = simulate(alpha=alpha, beta=beta, gamma=gamma, d=d, delta=PAPER_DELTA, steps=200,
                   x0=x0, v0=v0T, record=True)
    ref = oracle_trajectory(**physical(alpha, beta, gamma, PAPER_M, PAPER_T), d=d, m=PAPER_M,
                            b=PAPER_B, T=PAPER_T, x0=x0, v0=v0T / PAPER_T, steps=200)
    assert run.positions.shape == (201,)
    err = relative_max_difference(run.positions, ref)
    assert err <= 1e-10, f"simulated trajectory differs from the recursion by {err:.3g} of max |x|"


def test_ideal_trajectory_matches_recursion_on_random_devices():
    """Seeded random devices (m, b, T), environments and delays; 150 steps to 1e-10."""
    rng = np.random.default_rng(3)
    worst = 0.0
    for _ in range(12):
        m = 10 ** rng.uniform(np.log10(0.005), np.log10(0.5))
        T = 10 ** rng.uniform(np.log10(2.5e-4), np.log10(4e-3))
        delta = 10 ** rng.uniform(-4, 0)
        b = delta * m / T
        d = int(rng.integers(0, 13))
        alpha, beta, gamma = rng.uniform(0, 0.5 / (d + 1)), rng.uniform(-0.1, 1), rng.uniform(-0.9, 1.5)
        x0, v0T = rng.uniform(-1, 1), rng.uniform(-0.05, 0.05)
        run = simulate(alpha=alpha, beta=beta, gamma=gamma, d=d, delta=delta, steps=150, x0=x0,
                       v0=v0T, record=True)
        assert not run.diverged
        ref = oracle_trajectory(**physical(alpha, beta, gamma, m, T), d=d, m=m, b=b, T=T, x0=x0,
                                v0=v0T / T, steps=150)
        err = relative_max_difference(run.positions, ref)
        worst = max(worst, err)
        assert err <= 1e-10, (f"m={m!r} b={b!r} T={T!r} d={d} alpha={alpha!r} beta={beta!r} "
                              f"gamma={gamma!r}: differs by {err:.3g} of max |x|")
    print(f"random devices: worst trajectory difference {worst:.3g} of max |x|")


def _decay_points():
    """Per delay, a few points around alpha_max at beta_at_alpha_max (both sides)."""
    out = []
    for d, gamma in ((0, 0.0), (3, 0.5), (10, -0.25)):
        lim = symstab.limits(gamma=gamma, d=d, delta=PAPER_DELTA)
        for fa, fb in ((0.5, 1.0), (0.9, 1.0), (1.05, 1.0), (1.2, 1.0), (0.3, 0.3)):
            out.append((d, gamma, fa * lim.alpha_max, fb * lim.beta_at_alpha_max))
    return out


def _growth_per_step(positions, window):
    """exp(slope) of log(max |x| per window) over the second half of the windows, per step."""
    x = np.abs(positions)
    n = len(x) // window
    peaks = x[: n * window].reshape(n, window).max(axis=1)
    late = np.arange(n // 2, n)
    slope = np.polyfit(late, np.log(peaks[late]), 1)[0]
    return math.exp(slope / window)


def test_simulated_growth_equals_spectral_radius():
    """Growth per step of max |x| over late windows = spectral radius, to 1e-3.

    Stable and unstable points at d = 0, 3, 10 (radii 0.83 to 1.055).  The
    horizon is ~150 e-foldings of the radius (capped at 30000 steps), windows
    1/30 of it, fitted over the second half.  The radius is checked against
    two independent computations: :func:`symstab.spectral_radius` (companion
    eigenvalues of the derived polynomial) and python-control's closed-loop
    poles.  Measured: worst 1.2e-4 against both.
    """
    lines, worst = [], 0.0
    for d, gamma, alpha, beta in _decay_points():
        rho = symstab.spectral_radius(alpha=alpha, beta=beta, gamma=gamma, d=d, delta=PAPER_DELTA)
        loop = python_control_closed_loop(alpha=alpha, beta=beta, gamma=gamma, d=d, delta=PAPER_DELTA,
                                          m=PAPER_M, T=PAPER_T)
        rho_control = float(np.max(np.abs(control.poles(loop))))
        assert rho == pytest.approx(rho_control, rel=1e-6), (d, gamma, alpha, beta)
        steps = int(min(30000, 150 / abs(math.log(rho))))
        run = simulate(alpha=alpha, beta=beta, gamma=gamma, d=d, delta=PAPER_DELTA, steps=steps,
                       record=True)
        assert not run.diverged
        assert bool(run.stable) == (rho < 1)
        fitted = _growth_per_step(run.positions, max(20, steps // 30))
        err = abs(fitted - rho) / rho
        worst = max(worst, err)
        lines.append(f"d={d} gamma={gamma} alpha={alpha:.4g} beta={beta:.4g}: rho={rho:.6f} "
                     f"fitted={fitted:.6f} rel {err:.1e}")
    print("\n".join(lines))
    assert worst <= 1e-3, "\n".join(lines)


# --------------------------------------------------------------------------
# The acceptance criterion: simulated maps = exact classification
# --------------------------------------------------------------------------

AGREEMENT_DELAYS = (0, 1, 5, 10)
AGREEMENT_GAMMAS = (-0.75, -0.5, -0.25, 0.0, 0.5, 1.0, 1.5, 2.2)
#: 50 x 50 (was 100 x 100, 4x the CPU): a cell is still 1/50 of the window, so the
#: crossed band is a few percent of each map and a wrong verdict anywhere else shows.
GRID_N = 50
ARC_SAMPLES = 200000


def _agreement_grid(gamma, d):
    lim = symstab.limits(gamma=gamma, d=d, delta=PAPER_DELTA)
    if lim.alpha_max is None:
        return np.linspace(0.0, 1.0 / (d + 1), GRID_N), np.linspace(-0.1, 2.0 / (d + 1), GRID_N)
    h = lim.beta_max - lim.beta_min
    return (np.linspace(0.0, 1.15 * lim.alpha_max, GRID_N),
            np.linspace(lim.beta_min - 0.05 * h, lim.beta_max + 0.05 * h, GRID_N))


def crossed_cells(alpha, beta, gamma, d, delta):
    """Cells (half a grid step around each point) that contain a boundary point.

    The arc from the generated boundary kernel on ARC_SAMPLES points of
    (0, pi), indexed into cells; the line alpha = 0 (z = 1); the line
    alpha + 2 beta = c (z = -1).  Asserts the arc sampling is dense enough:
    consecutive samples inside the window never skip a cell.
    """
    n_a, n_b = len(alpha), len(beta)
    da, db = alpha[1] - alpha[0], beta[1] - beta[0]
    crossed = np.zeros((n_a, n_b), dtype=bool)
    theta = np.linspace(0.0, np.pi, ARC_SAMPLES + 2)[1:-1]
    a, b = kernels.boundary(theta, gamma, d, delta)
    i = np.round((a - alpha[0]) / da)
    j = np.round((b - beta[0]) / db)
    inside = (i >= 0) & (i < n_a) & (j >= 0) & (j < n_b)
    where = np.flatnonzero(inside)
    ii, jj = i[inside].astype(int), j[inside].astype(int)
    consecutive = np.diff(where) == 1
    jumps = np.maximum(np.abs(np.diff(ii)), np.abs(np.diff(jj)))[consecutive]
    assert jumps.size == 0 or jumps.max() <= 1, (
        f"arc sampling too coarse: consecutive samples {jumps.max()} cells apart")
    crossed[ii, jj] = True
    lo_a, hi_a = alpha - da / 2, alpha + da / 2
    lo_b, hi_b = beta - db / 2, beta + db / 2
    crossed[(lo_a <= 0.0) & (0.0 <= hi_a), :] = True
    c = minus_one_line(gamma=gamma, d=d, delta=delta)
    lo = lo_a[:, None] + 2 * lo_b[None, :]
    hi = hi_a[:, None] + 2 * hi_b[None, :]
    crossed |= (lo <= c) & (c <= hi)
    return crossed


def test_simulated_maps_agree_with_exact_classification():
    """32 maps of 50 x 50: the simulated verdict = classify() off the crossed cells.

    d in {0, 1, 5, 10}, eight virtual masses, the paper's device, no
    non-idealities, the default horizon.  The eight maps of a delay run in
    one broadcast :func:`simulate` call (the per-point loop
    :func:`stability_map` runs, on 20000 points: a quarter less CPU than
    eight calls of 2500).  Measured on 100 x 100 maps (this machine, 2 cores):
    0 mismatches outside the crossed cells; 10807 crossed cells in all (the
    simulator's author counted 10808 with his own cell rule); 1835
    mismatches inside them: 1828 on the alpha = 0 row where classify() says
    MARGINAL (a root exactly at z = 1) and the bounded simulation says
    stable; 4 more on that row at d = 10, beta in (-delta, 0), where
    classify() says STABLE (radius 1 - 4e-12) and the simulation unstable;
    3 next to the arc with radius 1 + 3e-7 .. 1 + 1.5e-5 that the horizon
    does not resolve.  25 s with other jobs running (53 s before the simulator's
    in-place ideal step).
    """
    start = time.perf_counter()
    total_crossed = total_inside = total_outside = inside_alpha0 = 0
    lines = []
    for d in AGREEMENT_DELAYS:
        grids = [_agreement_grid(gamma, d) for gamma in AGREEMENT_GAMMAS]
        planes = [np.meshgrid(alpha, beta, indexing="ij") for alpha, beta in grids]
        run = simulate(alpha=np.stack([A for A, _ in planes]),
                       beta=np.stack([B for _, B in planes]),
                       gamma=np.array(AGREEMENT_GAMMAS)[:, None, None], d=d, delta=PAPER_DELTA)
        assert run.stable.shape == (len(AGREEMENT_GAMMAS), GRID_N, GRID_N)
        assert run.steps == default_horizon(d)
        with np.errstate(divide="ignore", invalid="ignore"):
            growth = np.where(run.diverged, np.inf, run.amplitude[3] / run.amplitude[2])
        for k, (gamma, (alpha, beta)) in enumerate(zip(AGREEMENT_GAMMAS, grids, strict=True)):
            code = symstab.classify(alpha=alpha[:, None], beta=beta[None, :], gamma=gamma, d=d,
                                    delta=PAPER_DELTA)
            exact = code == symstab.STABLE
            crossed = crossed_cells(alpha, beta, gamma, d, PAPER_DELTA)
            mismatch = run.stable[k] != exact
            outside = int(np.count_nonzero(mismatch & ~crossed))
            inside = int(np.count_nonzero(mismatch & crossed))
            total_crossed += int(crossed.sum())
            total_inside += inside
            total_outside += outside
            inside_alpha0 += int(np.count_nonzero(mismatch[0] & (code[0] == symstab.MARGINAL)))
            line = (f"d={d:2d} gamma={gamma:5.2f}: crossed {int(crossed.sum()):4d}, mismatches "
                    f"inside {inside:3d}, outside {outside}")
            if outside:
                ia, ib = np.nonzero(mismatch & ~crossed)
                line += "; outside at " + ", ".join(
                    f"(alpha={alpha[p]:.5g}, beta={beta[q]:.5g}, sim={bool(run.stable[k, p, q])}, "
                    f"growth={growth[k, p, q]:.6g})"
                    for p, q in list(zip(ia, ib, strict=True))[:5])
            lines.append(line)
    summary = (f"32 maps: {total_crossed} crossed cells, {total_inside} mismatches inside them "
               f"({inside_alpha0} on the alpha = 0 row where classify is MARGINAL), "
               f"{total_outside} outside; {time.perf_counter() - start:.0f} s")
    print("\n".join(lines + [summary]))
    assert total_outside == 0, "\n".join(lines + [summary])


# --------------------------------------------------------------------------
# Non-idealities
# --------------------------------------------------------------------------

#: Stable points (rho 0.82 .. 0.98) for the non-ideal trajectory tests.
NONIDEAL_POINTS = [
    (0.3, 0.5, 0.5, 0),
    (0.02, 0.15, -0.3, 3),
    (0.01, 0.1, 0.0, 10),
]


@pytest.mark.parametrize("quantum", [1e-3, PAPER_ENCODER_RESOLUTION], ids=["q=1e-3", "q=paper"])
@pytest.mark.parametrize("point", NONIDEAL_POINTS, ids=[f"d={p[3]}" for p in NONIDEAL_POINTS])
def test_encoder_quantization_matches_quantized_recursion(point, quantum):
    """The environment sees positions rounded to the encoder's quantum.

    The simulator equals the oracle with a quantizer to 1e-10 of max |x|,
    while the unquantized oracle differs by far more (so the check can tell
    the two apart).  x0 = 0.01 rad, 400 steps.
    """
    alpha, beta, gamma, d = point
    x0, v0T = 0.01, 1e-4
    run = simulate(alpha=alpha, beta=beta, gamma=gamma, d=d, delta=None, device=PAPER_DEVICE,
                   nonideal=Nonidealities(encoder_resolution=quantum), steps=400, x0=x0, v0=v0T,
                   record=True)
    common = dict(**physical(alpha, beta, gamma, PAPER_M, PAPER_T), d=d, m=PAPER_M, b=PAPER_B,
                  T=PAPER_T, x0=x0, v0=v0T / PAPER_T, steps=400)
    quantized = oracle_trajectory(**common, quantum=quantum)
    ideal = oracle_trajectory(**common)
    err = relative_max_difference(run.positions, quantized)
    separation = relative_max_difference(ideal, quantized)
    assert separation > 1e-6, f"quantization too weak to test here ({separation:.3g})"
    assert err <= 1e-10, (f"differs from the quantized recursion by {err:.3g} of max |x| "
                          f"(the ideal recursion differs from it by {separation:.3g})")


def test_quantization_with_spring_only_uses_rounded_position():
    """beta = gamma = 0, d = 0: x(k+1) = x(k) + phi01 v(k) + g0 (-alpha round(x(k)/q) q).

    The velocity is not recorded, so it is recovered from the plant's own
    recursion v(k+1) = phi11 v(k) + g1 f(k), with the coefficients from
    python-control's c2d (m = T = 1, b = delta) -- not from the simulator.
    """
    q = 2e-3
    alpha, x0, v0T = 0.05, 0.0137, 3e-4
    sys_d = control.c2d(control.ss([[0.0, 1.0], [0.0, -PAPER_DELTA]], [[0.0], [1.0]],
                                   [[1.0, 0.0]], [[0.0]]), 1.0, "zoh")
    phi01, phi11 = sys_d.A[0, 1], sys_d.A[1, 1]
    g0, g1 = sys_d.B[0, 0], sys_d.B[1, 0]
    run = simulate(alpha=alpha, beta=0.0, gamma=0.0, d=0, delta=None, device=PAPER_DEVICE,
                   nonideal=Nonidealities(encoder_resolution=q), steps=300, x0=x0, v0=v0T,
                   record=True)
    x = run.positions

    def residuals(rounded):
        v, out = v0T, []
        for k in range(300):
            f = -alpha * (q * np.round(x[k] / q) if rounded else x[k])
            out.append(x[k + 1] - (x[k] + phi01 * v + g0 * f))
            v = phi11 * v + g1 * f
        return np.max(np.abs(out)) / np.max(np.abs(x))

    assert residuals(True) <= 1e-12, f"rounded-force residual {residuals(True):.3g} of max |x|"
    # ... and the unrounded position does not explain the run (the check can fail).
    assert residuals(False) > 1e-6, f"unrounded-force residual only {residuals(False):.3g}"


@pytest.mark.parametrize("point", NONIDEAL_POINTS, ids=[f"d={p[3]}" for p in NONIDEAL_POINTS])
def test_velocity_filter_matches_recursion(point):
    """A 50 Hz velocity filter (alone, and with the paper's encoder) as the docstring states it.

    Damper and mass see the first-order low-passed backward difference, the
    mass term differencing the filtered velocity; 400 steps to 1e-10.
    """
    alpha, beta, gamma, d = point
    x0, v0T = 0.01, 1e-4
    common = dict(**physical(alpha, beta, gamma, PAPER_M, PAPER_T), d=d, m=PAPER_M, b=PAPER_B,
                  T=PAPER_T, x0=x0, v0=v0T / PAPER_T, steps=400, cutoff=50.0)
    for quantum in (None, PAPER_ENCODER_RESOLUTION):
        run = simulate(alpha=alpha, beta=beta, gamma=gamma, d=d, delta=None, device=PAPER_DEVICE,
                       nonideal=Nonidealities(encoder_resolution=quantum, velocity_cutoff=50.0),
                       steps=400, x0=x0, v0=v0T, record=True)
        ref = oracle_trajectory(**common, quantum=quantum)
        err = relative_max_difference(run.positions, ref)
        assert err <= 1e-10, f"quantum={quantum}: differs from the recursion by {err:.3g}"


def test_velocity_cutoff_near_nyquist_approaches_ideal():
    """Raising the cut-off towards 1/(2T) brings the trajectory towards the ideal one.

    A first-order filter cannot vanish below Nyquist: at 0.499/T its pole is
    exp(-2 pi 0.499) = 0.0435, so the trajectory is not ideal, only close.
    Interior points (0.3 alpha_max, 0.5 beta_at_alpha_max), 1000 steps:
    the difference shrinks monotonically with the cut-off, and at 0.499/T it
    is below the pole itself.  Measured at 0.1/T, 0.25/T, 0.4/T, 0.499/T:
    d=0: 0.43, 0.092, 0.029, 0.015; d=3: 0.10, 0.021, 0.0069, 0.0035;
    d=10: 0.034, 0.0074, 0.0025, 0.0013 (gamma = 0); gamma = 0.5, d = 3: 0.0054 at 0.499/T.
    """
    lines = []
    for d, gamma in ((0, 0.0), (3, 0.0), (10, 0.0), (3, 0.5), (3, -0.3)):
        lim = symstab.limits(gamma=gamma, d=d, delta=PAPER_DELTA)
        alpha, beta = 0.3 * lim.alpha_max, 0.5 * lim.beta_at_alpha_max
        kw = dict(alpha=alpha, beta=beta, gamma=gamma, d=d, steps=1000, x0=0.01, record=True)
        ideal = simulate(delta=PAPER_DELTA, **kw).positions
        diffs = []
        for fc in (0.1, 0.25, 0.4, 0.499):
            run = simulate(delta=None, device=PAPER_DEVICE,
                           nonideal=Nonidealities(velocity_cutoff=fc / PAPER_T), **kw)
            diffs.append(relative_max_difference(run.positions, ideal))
        lines.append(f"d={d} gamma={gamma}: " + ", ".join(f"{x:.3g}" for x in diffs))
        pole = math.exp(-2 * math.pi * 0.499)
        assert all(a > b for a, b in zip(diffs, diffs[1:], strict=False)), lines[-1]
        assert diffs[-1] < pole, lines[-1]
    print("\n".join(lines))


def test_fast_actuator_follows_the_exact_continuous_lag():
    """A 1 MHz actuator is close to ideal, but not identical: it is a lag.

    A continuous first-order lag of time constant tau = 0.16 us changes the
    trajectory by roughly tau / T = 1.6e-4 per period, amplified by the loop
    (measured 5e-5 .. 0.07 of max |x| against the ideal loop over 400
    periods; the last point is unstable).  The oracle is the exact 3-state
    (x, v, applied force) system, which the simulator steps exactly (see
    the next test).
    """
    for alpha, beta, gamma, d in NONIDEAL_POINTS[:3] + [(0.9, 0.8, 0.0, 0)]:
        ref = oracle_trajectory(**physical(alpha, beta, gamma, PAPER_M, PAPER_T), d=d, m=PAPER_M,
                                b=PAPER_B, T=PAPER_T, x0=0.01, v0=1e-4 / PAPER_T, steps=400,
                                lag_bandwidth=1e6)
        run = simulate(alpha=alpha, beta=beta, gamma=gamma, d=d, delta=None, device=PAPER_DEVICE,
                       steps=400, x0=0.01, v0=1e-4, record=True,
                       nonideal=Nonidealities(actuator_bandwidth=1e6))
        ideal = simulate(alpha=alpha, beta=beta, gamma=gamma, d=d, delta=PAPER_DELTA, steps=400,
                         x0=0.01, v0=1e-4, record=True).positions
        err = relative_max_difference(run.positions, ref)
        assert err <= 5e-3, f"d={d}: a 1 MHz actuator differs from the exact lag by {err:.3g}"
        assert err < relative_max_difference(ref, ideal), "closer to the ideal loop than the lag"


def test_actuator_lag_is_the_exact_continuous_lag_at_any_substeps():
    """The device behind its lag is stepped exactly, whatever the number of sub-steps.

    Oracle: the 3-state system (x, v, applied force) with a' = w (u - a),
    discretised exactly by scipy.  The simulator steps the same system on
    its state space (:mod:`symstab.numeric.simulation.friction`, the lag as the
    loop's actuator), exact per sub-step: measured 3e-15 to 2.4e-14 of max
    |x| at 1, 20 and 320 sub-steps (the earlier scheme drove each sub-step
    with the lag's mean, held: 1.5e-4 / 9.2e-6 / 6e-7 at 20 / 80 / 320).
    """
    for alpha, beta, gamma, d in ((0.3, 0.5, 0.5, 0), (0.01, 0.1, 0.0, 10)):
        ref = oracle_trajectory(**physical(alpha, beta, gamma, PAPER_M, PAPER_T), d=d, m=PAPER_M,
                                b=PAPER_B, T=PAPER_T, x0=0.01, v0=1e-4 / PAPER_T, steps=400,
                                lag_bandwidth=200.0)
        for n in (1, 20, 320):
            run = simulate(alpha=alpha, beta=beta, gamma=gamma, d=d, delta=None,
                           device=PAPER_DEVICE, steps=400, x0=0.01, v0=1e-4, record=True,
                           nonideal=Nonidealities(actuator_bandwidth=200.0, substeps=n))
            error = relative_max_difference(run.positions, ref)
            assert error <= 1e-11, f"d={d}, {n} sub-steps: {error:.3g}"


# Coulomb friction: m v' = -b v - Fc (v > 0) from v(0) = v0 > 0 gives
#   v(t) = (v0 + Fc/b) exp(-b t / m) - Fc/b,
#   x(t) = x0 + (m/b)(v0 + Fc/b)(1 - exp(-b t / m)) - (Fc/b) t,
# the device stops at t_stop = (m/b) ln(1 + b v0 / Fc), at x0 + m v0 / b - (Fc/b) t_stop.
FRICTION = 0.01          # N m
FRICTION_V0 = 1.0        # rad/s
FRICTION_X0 = 0.2        # rad


def _coulomb_motion(t):
    m, b, fc, v0 = PAPER_M, PAPER_B, FRICTION, FRICTION_V0
    return FRICTION_X0 + (m / b) * (v0 + fc / b) * (1 - np.exp(-b * t / m)) - (fc / b) * t


def _coulomb_stop():
    m, b, fc, v0 = PAPER_M, PAPER_B, FRICTION, FRICTION_V0
    t_stop = (m / b) * math.log(1 + b * v0 / fc)
    return t_stop, FRICTION_X0 + m * v0 / b - (fc / b) * t_stop


@pytest.mark.parametrize("substeps", [4, 20, 50])
@pytest.mark.parametrize("stiction", [None, 2 * FRICTION], ids=["Fs=Fc", "Fs=2Fc"])
def test_coulomb_friction_stops_device_at_analytic_time(substeps, stiction):
    """No environment, v0 = 1 rad/s, Fc = 0.01 N m: stop at t_stop = 0.5707 s, then at rest.

    From the sampled positions: the last sample that moved is k_stop - 1, so
    the simulated stop lies in ((k_stop - 1) T, k_stop T]; it must lie in
    [t_stop, t_stop + T/n) (the sub-step that would reverse ends at rest).
    Before the stop the motion is exact (constant force on every sub-step):
    1e-10 of the travel; the rest position within (Fc/m)(T/n)^2 of the
    analytic one; afterwards the position is exactly constant (over 429 periods).
    """
    t_stop, x_stop = _coulomb_stop()
    steps = 1000
    run = simulate(alpha=0.0, beta=0.0, gamma=0.0, d=0, delta=None, device=PAPER_DEVICE,
                   nonideal=Nonidealities(coulomb_friction=FRICTION, stiction=stiction,
                                          substeps=substeps),
                   steps=steps, x0=FRICTION_X0, v0=FRICTION_V0 * PAPER_T, record=True)
    x = run.positions
    moved = np.flatnonzero(np.diff(x) != 0)
    assert moved.size, "the device never moved"
    k_stop = int(moved[-1]) + 1
    assert k_stop < steps - 400, f"the device did not stop (last move at sample {k_stop})"
    assert np.all(x[k_stop:] == x[k_stop]), "the device did not stay exactly at rest"
    assert k_stop * PAPER_T >= t_stop and (k_stop - 1) * PAPER_T < t_stop + PAPER_T / substeps, (
        f"stopped between samples {k_stop - 1} and {k_stop}; analytic t_stop = {t_stop / PAPER_T:.4f} T")
    travel = x_stop - FRICTION_X0
    k = np.arange(k_stop)
    err = np.max(np.abs(x[:k_stop] - _coulomb_motion(k * PAPER_T))) / travel
    assert err <= 1e-10, f"motion before the stop off by {err:.3g} of the travel"
    bound = (FRICTION / PAPER_M) * (PAPER_T / substeps) ** 2
    assert abs(x[k_stop] - x_stop) <= bound, (
        f"rest position {x[k_stop]!r} vs analytic {x_stop!r} (bound {bound:.3g})")
    assert bool(run.stable)


@pytest.mark.parametrize("kind", ["coulomb_friction", "actuator_bandwidth"])
def test_single_substep_keeps_the_nonideality(kind):
    """substeps=1 is allowed (>= 1) and must not switch friction or the lag off.

    With one sub-step per period the device under Coulomb friction must
    still stop (within one period of t_stop = 0.5707 s), and a 50 Hz
    actuator must still change the trajectory.
    """
    if kind == "coulomb_friction":
        t_stop, _ = _coulomb_stop()
        run = simulate(alpha=0.0, beta=0.0, gamma=0.0, d=0, delta=None, device=PAPER_DEVICE,
                       nonideal=Nonidealities(coulomb_friction=FRICTION, substeps=1),
                       steps=2000, x0=FRICTION_X0, v0=FRICTION_V0 * PAPER_T, record=True)
        x = run.positions
        k_after = math.ceil(t_stop / PAPER_T) + 1
        assert np.all(x[k_after:] == x[k_after]), (
            f"with substeps=1 the device is still moving after t_stop: x goes from "
            f"{x[k_after]!r} to {x[-1]!r} (frictionless travel ends at "
            f"{FRICTION_X0 + PAPER_M * FRICTION_V0 / PAPER_B!r})")
    else:
        kw = dict(alpha=0.3, beta=0.5, gamma=0.5, d=0, steps=200, x0=0.01, record=True)
        ideal = simulate(delta=PAPER_DELTA, **kw).positions
        run = simulate(delta=None, device=PAPER_DEVICE,
                       nonideal=Nonidealities(actuator_bandwidth=50.0, substeps=1), **kw)
        diff = relative_max_difference(run.positions, ideal)
        two = simulate(delta=None, device=PAPER_DEVICE,
                       nonideal=Nonidealities(actuator_bandwidth=50.0, substeps=2), **kw)
        assert diff > 1e-3, (
            f"with substeps=1 a 50 Hz actuator leaves the trajectory ideal (difference {diff:.3g}; "
            f"with substeps=2 it is {relative_max_difference(two.positions, ideal):.3g})")


def test_stiction_holds_below_breakaway_and_releases_above():
    """At rest under a spring force between Fc and Fs the device never moves; above Fs it does.

    K_w x0 = 0.01 * 12800 * 0.01 = 1.28 N m at alpha = 0.01, x0 = 0.01 rad.
    """
    kw = dict(alpha=0.01, beta=0.0, gamma=0.0, d=0, delta=None, device=PAPER_DEVICE, steps=500,
              x0=0.01, v0=0.0, record=True)
    spring = 0.01 * PAPER_M / PAPER_T**2 * 0.01
    held = simulate(nonideal=Nonidealities(coulomb_friction=0.5 * spring, stiction=1.5 * spring), **kw)
    assert np.all(held.positions == 0.01)
    released = simulate(nonideal=Nonidealities(coulomb_friction=0.5 * spring, stiction=0.9 * spring),
                        **kw)
    assert released.positions[1] < 0.01, "a force above the breakaway force did not move the device"


def test_quantization_and_filter_lower_alpha_max_at_40_ms():
    """QF (paper's encoder + 50 Hz filter) at Td = 40 ms does not raise the simulated alpha_max.

    40 x 40 maps, alpha in [0, 1.3 alpha_max], beta in [beta_min, 1.3 beta_max],
    x0 = 0.01 rad, default horizon (44000 periods), gamma in {-0.5, 0, 0.5, 1},
    ideal and QF.  All four gammas run in one broadcast :func:`simulate` call
    per case (the same per-point loop :func:`stability_map` uses; 13 s instead
    of about 35 s).  The ideal simulated alpha_max must be the exact
    classification's on the grid.  Measured QF / ideal alpha_max:
    0.931, 0.897, 0.897, 0.897; beta_max: 0.963, 0.929, 0.930, 0.963.
    """
    d = PAPER_DEVICE.delay_samples(40e-3)
    assert d == 40
    gammas = (-0.5, 0.0, 0.5, 1.0)
    n = 40
    grids = []
    for gamma in gammas:
        lim = symstab.limits(gamma=gamma, d=d, delta=PAPER_DELTA)
        grids.append(np.meshgrid(np.linspace(0.0, 1.3 * lim.alpha_max, n),
                                 np.linspace(lim.beta_min, 1.3 * lim.beta_max, n), indexing="ij"))
    A = np.stack([g[0] for g in grids])
    B = np.stack([g[1] for g in grids])
    G = np.broadcast_to(np.array(gammas)[:, None, None], A.shape)
    qf = Nonidealities(encoder_resolution=PAPER_ENCODER_RESOLUTION, velocity_cutoff=50.0)
    ideal = simulate(alpha=A, beta=B, gamma=G, d=d, delta=PAPER_DELTA, x0=0.01)
    noisy = simulate(alpha=A, beta=B, gamma=G, d=d, delta=None, device=PAPER_DEVICE, nonideal=qf,
                     x0=0.01)
    lines = []
    for k, gamma in enumerate(gammas):
        exact = symstab.classify(alpha=A[k], beta=B[k], gamma=gamma, d=d, delta=PAPER_DELTA) \
            == symstab.STABLE
        a_ideal, b_ideal = A[k][ideal.stable[k]].max(), B[k][ideal.stable[k]].max()
        assert a_ideal == A[k][exact].max(), f"gamma={gamma}: ideal alpha_max off the exact grid one"
        assert noisy.stable[k].any(), f"gamma={gamma}: nothing stable with QF"
        a_qf, b_qf = A[k][noisy.stable[k]].max(), B[k][noisy.stable[k]].max()
        lines.append(f"gamma={gamma}: alpha_max QF/ideal = {a_qf / a_ideal:.3f}, "
                     f"beta_max QF/ideal = {b_qf / b_ideal:.3f}")
        assert a_qf <= a_ideal, lines[-1]
    print("\n".join(lines))


# --------------------------------------------------------------------------
# Bad input and divergence
# --------------------------------------------------------------------------

_T = PAPER_T
BAD_NONIDEAL = [
    ("encoder_resolution", dict(encoder_resolution=-1e-5)),
    ("encoder_resolution", dict(encoder_resolution=0.0)),
    ("velocity_cutoff", dict(velocity_cutoff=1 / (2 * _T))),
    ("velocity_cutoff", dict(velocity_cutoff=2 / _T)),
    ("coulomb_friction", dict(coulomb_friction=-0.01)),
    ("stiction", dict(coulomb_friction=0.01, stiction=0.005)),
    ("substeps", dict(coulomb_friction=0.01, substeps=0)),
    ("substeps", dict(actuator_bandwidth=100.0, substeps=2.5)),
]


@pytest.mark.parametrize("name, fields", BAD_NONIDEAL,
                         ids=[f"{n}-{i}" for i, (n, _) in enumerate(BAD_NONIDEAL)])
def test_bad_nonideality_names_the_field(name, fields):
    with pytest.raises((ValueError, TypeError)) as excinfo:
        simulate(alpha=0.1, beta=0.5, gamma=0.0, d=0, delta=None, device=PAPER_DEVICE,
                 nonideal=Nonidealities(**fields), steps=100)
    assert_message_names(excinfo, name)


BAD_CALLS = [
    ("steps", dict(steps=0)),
    ("steps", dict(steps=-5)),
    ("steps", dict(steps=100.0)),
    ("steps", dict(steps="100")),
    ("device", dict(nonideal=Nonidealities(encoder_resolution=1e-5))),
    ("delta", dict(delta=0.1, device=PAPER_DEVICE)),
    ("delta", dict(delta=float("nan"))),
    ("delta", dict(delta=None)),
    ("alpha", dict(alpha=float("nan"))),
    ("alpha", dict(alpha=[0.1, float("nan")])),
    ("beta", dict(beta=float("inf"))),
    ("gamma", dict(gamma="0.5")),
    ("d", dict(d=-1)),
    ("d", dict(d=float("nan"))),
    # Issue 43: a fraction of a period is simulated, but not with Coulomb friction.
    ("coulomb_friction", dict(d=1.5, device=PAPER_DEVICE, delta=None,
                              nonideal=Nonidealities(coulomb_friction=1e-3))),
]


@pytest.mark.parametrize("name, change", BAD_CALLS,
                         ids=[f"{n}-{i}" for i, (n, _) in enumerate(BAD_CALLS)])
def test_bad_simulate_input_names_the_parameter(name, change):
    kw = dict(alpha=0.1, beta=0.5, gamma=0.0, d=0, delta=PAPER_DELTA, steps=100)
    kw.update(change)
    with pytest.raises((ValueError, TypeError)) as excinfo:
        simulate(**kw)
    assert_message_names(excinfo, name)


def test_bad_stability_map_input_names_the_parameter():
    with pytest.raises((ValueError, TypeError)) as excinfo:
        stability_map(alpha=[0.0, float("nan")], beta=[0.1, 0.2], gamma=0.0, d=0, delta=PAPER_DELTA,
                      steps=100)
    assert_message_names(excinfo, "alpha")
    with pytest.raises((ValueError, TypeError)) as excinfo:
        stability_map(alpha=[0.0, 0.1], beta=[0.1, 0.2], gamma=float("nan"), d=0, delta=PAPER_DELTA,
                      steps=100)
    assert_message_names(excinfo, "gamma")


def test_diverging_run_is_flagged_and_finite():
    """alpha = 50 overflows: diverged, unstable, no NaN/inf in the positions.

    The docstring: an overflowing point is frozen at 0 and its amplitude set
    to inf.  Together with it, a stable point in the same call is untouched,
    and an extreme point (alpha = beta = 1e308, whose force overflows to inf
    in one step) is caught the same way.
    """
    with np.errstate(over="ignore", invalid="ignore"):
        run = simulate(alpha=[50.0, 0.1, 1e308], beta=[0.0, 0.5, 1e308], gamma=0.0, d=0,
                       delta=PAPER_DELTA, steps=400, record=True)
    assert run.diverged.tolist() == [True, False, True]
    assert run.stable.tolist() == [False, True, False]
    assert np.all(np.isfinite(run.positions)), "NaN or inf in positions"
    assert not np.any(np.isnan(run.amplitude))
    assert np.all(np.isinf(run.amplitude[:, 0]) == [True] * 4)
    assert np.all(run.positions[-50:, [0, 2]] == 0.0), "diverged points are not frozen at 0"
    ref = simulate(alpha=0.1, beta=0.5, gamma=0.0, d=0, delta=PAPER_DELTA, steps=400, record=True)
    assert np.array_equal(run.positions[:, 1], ref.positions)
    with np.errstate(over="ignore", invalid="ignore"):
        sm = stability_map(alpha=[0.1, 50.0], beta=[0.5], gamma=0.0, d=0, delta=PAPER_DELTA, steps=400)
    assert sm.stable.tolist() == [[True], [False]]
    assert not np.any(np.isnan(sm.growth)) and sm.growth[1, 0] == np.inf


# --------------------------------------------------------------------------
# Initial state, kinds of the arguments, memory
# --------------------------------------------------------------------------

#: A stable point (radius 0.735) and an unstable one (radius 1.004), d = 0.
STABLE_POINT = dict(alpha=0.1, beta=0.5, gamma=0.0, d=0, delta=PAPER_DELTA)
UNSTABLE_POINT = dict(alpha=0.1, beta=-0.01, gamma=0.0, d=0, delta=PAPER_DELTA)


def test_the_two_points_are_what_their_names_say():
    """python-control's poles, independent of symstab: one inside, one outside the circle."""
    for point, stable in ((STABLE_POINT, True), (UNSTABLE_POINT, False)):
        poles = python_control_closed_loop(**point, m=PAPER_M, T=PAPER_T).poles()
        radius = float(np.max(np.abs(poles)))
        assert (radius < 0.99) if stable else (radius > 1.001), radius


@pytest.mark.parametrize("x0", [0.0, -0.0, 1e-101, 1e100, -1e51, 1e300])
def test_x0_outside_its_range_is_refused(x0):
    """x0 = 0 never moves (every cell read stable); 1e100 starts at the divergence threshold."""
    for run in (lambda: simulate(**STABLE_POINT, steps=100, x0=x0),
                lambda: stability_map(alpha=[0.1], beta=[0.5], gamma=0.0, d=0, delta=PAPER_DELTA,
                                      steps=100, x0=x0)):
        with pytest.raises(ValueError) as excinfo:
            run()
        assert_message_names(excinfo, "x0")
        assert "1e-100 <= |x0| <= 1e+50" in str(excinfo.value)


@pytest.mark.parametrize("x0", [1e-100, -1e-100, 1e50, -1e50, 1.0])
def test_x0_at_the_ends_of_its_range_gives_the_true_verdict(x0):
    """The verdicts at the ends of the allowed range equal the poles' (test above)."""
    run = simulate(alpha=[STABLE_POINT["alpha"], UNSTABLE_POINT["alpha"]],
                   beta=[STABLE_POINT["beta"], UNSTABLE_POINT["beta"]], gamma=0.0, d=0,
                   delta=PAPER_DELTA, steps=2000, x0=x0)
    assert run.stable.tolist() == [True, False]
    assert not run.diverged.any()


@pytest.mark.parametrize("field, value", [
    ("friction_compensation", "no"),
    ("friction_compensation", 1),
    ("encoder_resolution", "1e-5"),
    ("velocity_cutoff", [50.0]),
    ("coulomb_friction", True),
    ("stiction", "0.1"),
    ("actuator_bandwidth", 1j),
    ("substeps", 2.0),
    ("substeps", "20"),
])
def test_nonidealities_of_the_wrong_kind_raise_type_error(field, value):
    fields = {"coulomb_friction": 0.01} if field in ("friction_compensation", "stiction") else {}
    fields[field] = value
    with pytest.raises(TypeError) as excinfo:
        Nonidealities(**fields)
    assert_message_names(excinfo, field)


def test_friction_compensation_must_be_a_bool_not_a_truthy_string():
    """"no" is truthy: it used to switch compensation on."""
    with pytest.raises(TypeError, match="friction_compensation must be True or False"):
        Nonidealities(coulomb_friction=0.01, friction_compensation="no")
    assert Nonidealities(coulomb_friction=0.01, friction_compensation=np.bool_(True)).friction_compensation


@pytest.mark.parametrize("name, change, expected", [
    ("nonideal", dict(nonideal={"encoder_resolution": 1e-5}), "Nonidealities"),
    ("delta", dict(delta="abc", device=PAPER_DEVICE), "delta"),
    ("progress", dict(progress=1), "callable"),
    ("device", dict(device="paper", delta=None), "Device"),
])
def test_simulate_arguments_of_the_wrong_kind_raise_type_error(name, change, expected):
    kw = dict(alpha=0.1, beta=0.5, gamma=0.0, d=0, delta=PAPER_DELTA, steps=100)
    kw.update(change)
    with pytest.raises(TypeError) as excinfo:
        simulate(**kw)
    assert_message_names(excinfo, name)
    assert expected in str(excinfo.value)


def test_stability_map_progress_of_the_wrong_kind_raises_type_error():
    with pytest.raises(TypeError) as excinfo:
        stability_map(alpha=[0.1], beta=[0.5], gamma=0.0, d=0, delta=PAPER_DELTA, steps=100,
                      progress=1)
    assert_message_names(excinfo, "progress")


def test_recording_beyond_the_memory_limit_is_refused_before_running(monkeypatch):
    """200000 recorded periods of 10 points need 16 MB: over a 1 MiB limit, refused at once."""
    monkeypatch.setenv("SYMSTAB_MEMORY_LIMIT", "1M")
    start = time.perf_counter()
    with pytest.raises(ValueError) as excinfo:
        simulate(alpha=np.full(10, 0.1), beta=0.5, gamma=0.0, d=0, delta=PAPER_DELTA,
                 steps=200000, record=True)
    assert time.perf_counter() - start < 1.0, "the run started before the memory check"
    assert "SYMSTAB_MEMORY_LIMIT" in str(excinfo.value)
    assert "200000 periods" in str(excinfo.value)


def _small_chunks(monkeypatch, budget):
    from symstab import _resources
    from symstab.numeric.simulation import simulator as module

    monkeypatch.setattr(module, "chunk_slices",
                        lambda n, size: _resources.chunk_slices(n, size, budget=budget))


def test_chunked_map_equals_one_chunk_and_reports_progress_in_order(monkeypatch):
    """The same verdicts and growth, bit for bit, in 7 chunks as in one."""
    alpha, beta = np.linspace(0.0, 0.05, 21), np.linspace(-0.05, 0.3, 20)
    kw = dict(alpha=alpha, beta=beta, gamma=0.5, d=3, delta=PAPER_DELTA, steps=600)
    whole = stability_map(**kw)
    _small_chunks(monkeypatch, budget=8 * (3 + 1 + 22) * 60)   # 60 points per chunk
    seen = []
    chunked = stability_map(**kw, progress=seen.append)
    assert np.array_equal(whole.stable, chunked.stable)
    assert np.array_equal(whole.growth, chunked.growth)
    assert 0 < whole.stable.sum() < whole.stable.size
    assert seen == sorted(seen) and seen[-1] == 600 and len(seen) > 7 * 50


def test_chunked_map_memory_does_not_grow_with_the_working_set(monkeypatch):
    """Peak traced memory per grid point: chunks keep it near the size of the result.

    At d = 40 the working state is 63 floats (504 bytes) per point; the
    result and the grid copies are about 15 floats (120 bytes).  In chunks of
    256 KiB the peak stays under 200 bytes per point plus the chunk.
    """
    import tracemalloc

    _small_chunks(monkeypatch, budget=256 * 1024)
    alpha, beta = np.linspace(0.0, 0.01, 100), np.linspace(0.0, 0.2, 100)
    # Once per process the paper's loop is derived (SymPy, a few MB): not per point.
    stability_map(alpha=alpha[:2], beta=beta[:2], gamma=0.0, d=40, delta=PAPER_DELTA, steps=48)
    tracemalloc.start()
    try:
        stability_map(alpha=alpha, beta=beta, gamma=0.0, d=40, delta=PAPER_DELTA, steps=48)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert peak < 200 * alpha.size * beta.size + 2 * 256 * 1024, peak


def test_steps_beyond_the_limit_are_refused_naming_it(monkeypatch):
    """steps = 1e9 ran for hours (about 30 us a period); the limit is named with its variable."""
    with pytest.raises(ValueError) as excinfo:
        simulate(**STABLE_POINT, steps=1_000_000_000)
    assert_message_names(excinfo, "steps")
    assert "10000000" in str(excinfo.value) and "SYMSTAB_MAX_STEPS" in str(excinfo.value)
    monkeypatch.setenv("SYMSTAB_MAX_STEPS", "50")
    with pytest.raises(ValueError, match="from 8 to 12000"):   # the default horizon at d = 0
        simulate(**STABLE_POINT, steps=12001)
    assert simulate(**STABLE_POINT, steps=12000).steps == 12000


def test_simulation_prints_its_verdicts_not_its_arrays():
    """Issue 13: result objects print their content, readably."""
    from symstab.numeric.paper.simulate import simulate
    run = simulate(alpha=np.array([[0.1, 5.0]]), beta=0.5, gamma=0.0, d=1, delta=PAPER_DELTA)
    text = repr(run)
    assert "array(" not in text
    assert text == (f"Simulation(2 points (1 x 2), {run.steps} steps: 1 stable, "
                    "1 unstable of which 1 diverged)")


def test_a_fractional_delay_is_simulated_as_the_oracles_loop():
    """Issue 43: the paper's simulator takes ``d = 10.5``; its verdicts are those of the
    state-space oracle's spectral radius (Van Loan's block exponential, nothing of symstab),
    on the points of a grid whose radius is not within 1e-3 of 1."""
    from oracles import fractional_delay_radius

    alpha = np.linspace(0.0, 3e-3, 7)
    beta = np.linspace(-0.002, 0.03, 7)
    found = stability_map(alpha=alpha, beta=beta, gamma=0.0, d=10.5, delta=PAPER_DELTA)
    checked = 0
    for i, a in enumerate(alpha):
        for j, b in enumerate(beta):
            # Table I's units: m = T = 1, b = delta; VE = K + B (1 - 1/z).
            radius = fractional_delay_radius([1.0], [1.0, PAPER_DELTA, 0.0], [a + b, -b],
                                             [1.0, 0.0], 1.0, 10, 0.5)
            if abs(radius - 1) > 1e-3:
                assert found.stable[i, j] == (radius < 1), (a, b, radius)
                checked += 1
    assert checked > 30 and found.stable.any() and not found.stable.all()


def test_a_fraction_next_to_a_whole_delay_gives_its_verdicts():
    """A fraction of a period just above a whole sample (1e-7) runs from the sampled history
    (the loop's fractional plant), the whole delay from the device's state: different starts
    of the same motion, and the same verdicts on a stable and an unstable point."""
    alpha, beta = np.array([1e-3, 4e-3]), np.array([0.01, 0.01])
    whole = simulate(alpha=alpha, beta=beta, gamma=0.0, d=3, delta=PAPER_DELTA, steps=4000)
    near = simulate(alpha=alpha, beta=beta, gamma=0.0, d=3 + 1e-7, delta=PAPER_DELTA,
                    steps=4000)
    assert list(whole.stable) == list(near.stable) == [True, False]
