"""The oracles of the symstab tests: one home for every reference they compare with.

Independent of symstab's derivation:

* first principles -- the paper's printed eqs. (1), (2) and (4) (believed
  correct), evaluated with mpmath: :func:`eq4_pulse_transfer_function`,
  :func:`eq1_virtual_environment` (and :func:`eq1_virtual_environment_tf`,
  its coefficients as a python-control transfer function), :func:`loop_gain_parts`,
  :func:`first_principles_chi` (the loop polynomial),
  :func:`first_principles_boundary_point`, :func:`first_principles_theta_max`;
* python-control -- :func:`python_control_closed_loop`, the closed loop of
  Fig. 2 from ``control.c2d`` and ``control.feedback``;
* the sampled state space -- :func:`fractional_delay_radius`, the paper's
  loop with a delay of a fraction of a period, from ``scipy.linalg.expm``;
* the lifted quadratic form of passivity with a fractional delay, an
  ``N x N`` eigenvalue per frequency (:func:`lifted_least_damping`);
* the seeded parameter points they are compared on (:func:`random_loop_points`);
* ``mpmath.polyroots`` started from numpy's roots (:func:`polyroots`).

And a reference that is *not* independent: symstab's own derivation
evaluated with mpmath numbers at the caller's precision
(:func:`loop_coefficients_mp`, :func:`boundary_point_mp`, :func:`chi_mp`),
the 30- to 60-digit reference for the float kernels, here so that every test
evaluates it the same way (always mpmath numbers, never Python floats); and
per point its 30-digit coefficients with numpy's roots
(:func:`coefficients_at`, :func:`unstable_root_count`,
:func:`stable_alpha_intervals`: the audit's reference, from
:mod:`paper_checks.regions`), the slow reference of the root engine.

Fixtures, shared command runs and assertion helpers are in ``conftest.py``.
Both modules are imported by name (``from oracles import ...``) from every
test folder (``pythonpath`` in pyproject.toml).
"""

import functools
import math

import mpmath
import numpy as np
import sympy as sp

from symstab.paper_checks.regions import (  # noqa: F401
    coefficients_at,
    stable_alpha_intervals,
    unstable_root_count,
)
from symstab.symbolic import model
from symstab.symbolic.boundary import boundary
from symstab.symbolic.loop import characteristic_polynomial

# --------------------------------------------------------------------------
# First-principles oracle: the paper's eqs. (1), (2), (4)
# --------------------------------------------------------------------------

def eq4_pulse_transfer_function(z, m, b, T, exp=sp.exp):
    """Z[ZOH G(s)] as printed in the paper's eq. (4) (line 171 of the text).

    ``((e^{-bT/m} - 1 + bT/m) z + 1 - (1 + bT/m) e^{-bT/m})
    / ((z - 1) b^2/m (z - e^{-bT/m}))``.
    Pass ``exp=mpmath.exp`` for numbers.
    """
    e = exp(-b * T / m)
    return (((e - 1 + b * T / m) * z + 1 - (1 + b * T / m) * e)
            / ((z - 1) * b**2 / m * (z - e)))


def eq1_virtual_environment(z, K_w, B_w, M_w, T):
    """VE(z) as printed in the paper's eq. (1)."""
    return K_w + B_w * (z - 1) / (T * z) + M_w * (z - 1) ** 2 / (T**2 * z**2)


def eq1_virtual_environment_tf(K_w, B_w, M_w, T):
    """VE(z) of eq. (1) as one python-control transfer function, sample period ``T``.

    Eq. (1), ``K_w + B_w (z - 1)/(T z) + M_w (z - 1)^2/(T^2 z^2)``, written
    by hand over its common denominator ``T^2 z^2``:
    ``((K_w T^2 + B_w T + M_w) z^2 - (B_w T + 2 M_w) z + M_w) / (T^2 z^2)``.
    One ``control.tf`` from these coefficients costs a fraction of building
    it by python-control's transfer-function arithmetic (a few milliseconds
    a call, thousands of calls in the suite); ``test_oracles.py`` checks it
    equals :func:`eq1_virtual_environment` at complex ``z``.
    """
    import control

    numerator = [K_w * T**2 + B_w * T + M_w, -(B_w * T + 2 * M_w), M_w]
    return control.tf(numerator, [T**2, 0.0, 0.0], T)


def loop_gain_parts(z, d, delta):
    """``(A, B, C)`` with eq. (2)'s Delta(z) = 1 + alpha A + beta B + gamma C.

    Eq. (2) with eqs. (1) and (4) in Table I's variables: the loop is
    invariant under the scaling of Table I, so m = T = 1, b = delta,
    K_w = alpha, B_w = beta, M_w = gamma.
    """
    one = mpmath.mpf(1)
    base = z ** (-d) * eq4_pulse_transfer_function(z, one, delta, one, exp=mpmath.exp)
    return base, base * (z - 1) / z, base * (z - 1) ** 2 / z**2


def first_principles_chi(alpha, beta, gamma, d, delta):
    """Loop polynomial from the printed eqs. (1), (2), (4), divided by delta**2 (mpmath).

    With m = T = 1 and b = delta, eq. (4) is ``G(z) = (n1 z + n0) /
    (delta**2 (z - 1)(z - E))`` with ``E = exp(-delta)``, ``n1 = E - 1 +
    delta``, ``n0 = 1 - (1 + delta) E``, and eq. (1) is ``VE(z) = (alpha
    z**2 + beta z (z - 1) + gamma (z - 1)**2) / z**2``; 1 + VE z^-d G = 0
    times ``z**(d+2) (z - 1)(z - E)`` is ``z**(d+2) (z - 1)(z - E) + V(z)
    (n1 z + n0) / delta**2``.  At delta = 0, ``n1 / delta**2 = n0 /
    delta**2 = 1/2``.  Coefficients highest first, at the caller's mpmath
    precision (computed with the digits that n1 and n0 cancel added).
    """
    extra = int(3 * max(0.0, -math.log10(delta))) if delta > 0 else 0
    with mpmath.workdps(mpmath.mp.dps + extra):
        a, b, g, dl = (mpmath.mpf(x) for x in (alpha, beta, gamma, delta))
        E = mpmath.exp(-dl)
        if dl == 0:
            h1 = h0 = mpmath.mpf(1) / 2
        else:
            h1, h0 = (E - 1 + dl) / dl**2, (1 - (1 + dl) * E) / dl**2
        coeffs = [mpmath.mpf(1), -(1 + E), E] + [mpmath.mpf(0)] * (d + 2)
        v2, v1, v0 = a + b + g, -(b + 2 * g), g
        for k, c in enumerate((v2 * h1, v2 * h0 + v1 * h1, v1 * h0 + v0 * h1, v0 * h0)):
            coeffs[-4 + k] += c
    return [+c for c in coeffs]


def first_principles_chi_float(alpha, beta, gamma, d, delta, dps=30):
    """:func:`first_principles_chi` at ``dps`` digits, rounded once to floats."""
    with mpmath.workdps(dps):
        return np.array([float(c) for c in first_principles_chi(alpha, beta, gamma, d, delta)])


def first_principles_radius(alpha, beta, gamma, d, delta, dps=40):
    """Largest root modulus of :func:`first_principles_chi`, by ``mpmath.polyroots`` at ``dps`` digits.

    For points on the edge of a region where two roots meet (a double root
    at z = 1 at a sliver's corner), ``np.roots`` of rounded coefficients is
    ``sqrt(eps)``, about 1e-8, off; this is not.
    """
    with mpmath.workdps(dps):
        coefficients = first_principles_chi(alpha, beta, gamma, d, delta)
        roots = polyroots(coefficients, maxsteps=100, extraprec=2 * dps)
        return float(max(abs(r) for r in roots))


def polyroots(coefficients, *, maxsteps, extraprec):
    """``mpmath.polyroots`` of ``coefficients`` (highest first), started from numpy's roots.

    Durand-Kerner converges to the same roots, to mpmath's tolerance at the
    working precision, from any distinct start; from numpy's roots it takes
    a few steps instead of dozens (8 times faster at degree 44).
    """
    start = [mpmath.mpc(complex(r)) for r in np.roots([float(c) for c in coefficients])]
    return mpmath.polyroots(coefficients, maxsteps=maxsteps, extraprec=extraprec,
                            roots_init=start)


def delta_of_z(z, *, alpha, beta, gamma, d, delta):
    """Eq. (2): Delta(z) = 1 + VE(z) z^-d Z[ZOH G] in Table I's variables."""
    A, B, C = loop_gain_parts(z, d, delta)
    return 1 + alpha * A + beta * B + gamma * C


def first_principles_boundary_point(theta, gamma, d, delta):
    """(alpha, beta) with Delta(exp(j theta)) = 0, by Cramer's rule on Re and Im."""
    theta, gamma, delta = mpmath.mpf(theta), mpmath.mpf(gamma), mpmath.mpf(delta)
    A, B, C = loop_gain_parts(mpmath.expj(theta), d, delta)
    R = -(1 + gamma * C)
    det = A.real * B.imag - A.imag * B.real
    return ((R.real * B.imag - R.imag * B.real) / det,
            (A.real * R.imag - A.imag * R.real) / det)


def first_principles_alpha(theta, gamma, d, delta):
    return first_principles_boundary_point(theta, gamma, d, delta)[0]


def first_principles_theta_max(gamma, d, delta, *, dps=40, n=None):
    """First theta in (0, pi) where the first-principles alpha(theta) turns negative.

    A fine scan (spacing well below a quarter period of sin(d theta)) finds the
    first sign change; mpmath refines it on alpha itself, which is O(1), so the
    stopping rule |alpha| < eps is a tight one.  Returns None if alpha < 0 at the
    first grid point or never changes sign.
    """
    with mpmath.workdps(dps):
        f = lambda t: first_principles_alpha(t, gamma, d, delta)  # noqa: E731
        n = n or max(1000, 32 * (d + 1))
        prev_t, prev = None, None
        for k in range(1, n):
            t = mpmath.pi * k / n
            value = f(t)
            if prev is None and value < 0:
                return None
            if prev is not None and prev > 0 > value:
                return mpmath.findroot(f, (prev_t, t), solver="anderson")
            prev_t, prev = t, value
        return None


# --------------------------------------------------------------------------
# python-control oracle
# --------------------------------------------------------------------------

def python_control_closed_loop(*, alpha, beta, gamma, d, delta, m, T):
    """Closed loop of Fig. 2 built with python-control from physical values.

    G(s) = 1/(m s^2 + b s) discretised with a ZOH by ``control.c2d``; VE(z)
    of eq. (1); a delay of ``d`` samples; negative feedback, so the poles are
    the roots of 1 + G(z) VE(z) z^-d (eq. (2)).
    """
    import control

    b = delta * m / T
    K_w, B_w, M_w = alpha * m / T**2, beta * m / T, gamma * m
    G = control.c2d(control.tf([1], [m, b, 0]), T, "zoh")
    VE = eq1_virtual_environment_tf(K_w, B_w, M_w, T)
    delay = control.tf([1], [1] + [0] * d, T)
    return control.feedback(G, VE * delay)


def python_control_parts(loop, values):
    """python-control's ``(P(z), VE(z), z**-d)`` of a :class:`symstab.Loop` at ``values``.

    ``G(s)`` and ``VE(z)`` with the values substituted by SymPy, turned into
    ``control.tf`` from their coefficients; ``G`` sampled by ``control.c2d(...,
    "zoh")``.  The closed loop is ``control.feedback(P, VE * delay)``.
    """
    import control

    s, z = sp.symbols("s z")
    num, den = _substituted_coefficients(loop.plant, s, _values_of(loop.plant, values))
    plant = control.tf(list(num), list(den))
    T = float(values["T"])
    sampled = control.c2d(plant, T, "zoh")
    num, den = _substituted_coefficients(loop.environment, z,
                                         _values_of(loop.environment, values))
    environment = control.tf(list(num), list(den), T)
    delay = control.tf([1.0], [1.0] + [0.0] * int(values["d"]), T)
    return sampled, environment, delay


# --------------------------------------------------------------------------
# State-space oracle of a fractional loop delay (d + eps) T
# --------------------------------------------------------------------------

def _held_input_integral(A, B, t):
    """``(e^{A t}, int_0^t e^{A s} ds B)`` by Van Loan's block exponential of ``[[A, B], [0, 0]] t``."""
    import scipy.linalg

    n, m = B.shape
    block = np.zeros((n + m, n + m))
    block[:n, :n], block[:n, n:] = A, B
    exponential = scipy.linalg.expm(block * t)
    return exponential[:n, :n], exponential[:n, n:]


def _realisation(num, den):
    """``(A, B, C, D)`` of ``num / den`` (coefficients highest first, proper): the controllable form.

    ``A``'s first row is ``-den[1:] / den[0]``, ones below its diagonal; ``B``
    the first unit vector; ``C`` the numerator's remainder after the direct
    term ``D`` (as ``scipy.signal.tf2ss``, whose import costs 1.7 s).
    """
    den = np.trim_zeros(np.asarray(den, float), "f")
    num = np.trim_zeros(np.asarray(num, float), "f")
    if num.size > den.size:
        raise ValueError("the transfer function must be proper")
    a = den / den[0]
    b = np.concatenate([np.zeros(den.size - num.size), num]) / den[0]
    n = den.size - 1
    A, B = np.zeros((n, n)), np.zeros((n, 1))
    if n:
        A[0], B[0, 0] = -a[1:], 1.0
        A[1:, :-1] = np.eye(n - 1)
    C = (b[1:] - b[0] * a[1:])[None, :]
    return A, B, C, np.array([[b[0]]])


def fractional_delay_closed_loop(plant_num, plant_den, env_num, env_den, T, d, eps):
    """The closed loop's state matrix of a loop whose command waits ``(d + eps) T``.

    Built from the physics, independently of symstab's modified z-transform:
    the plant ``G(s) = plant_num / plant_den`` (s-coefficients, highest first,
    strictly proper) realised (:func:`_realisation`) as ``x' = A x + B u``,
    ``y = C x``; the command held over a period reaches it ``eps T`` late
    inside the period, so over ``[kT, (k+1)T)`` the input is ``u[k-d-1]`` for
    the first ``eps T`` and ``u[k-d]`` after::

        x[k+1] = Phi x[k] + Gamma0 u[k-d] + Gamma1 u[k-d-1],
        Phi = e^{A T},  Gamma0 = int_0^{(1-eps)T} e^{A s} ds B,
        Gamma1 = e^{A (1-eps) T} int_0^{eps T} e^{A s} ds B.

    The environment ``VE(z) = env_num / env_den`` (z-coefficients, proper) is
    a discrete state space fed with the sampled position ``y[k] = C x[k]``,
    its force ``f[k]``; the command is ``u[k] = -f[k]``, and the register
    ``(f[k-1], ..., f[k-d-1])`` holds the whole samples of delay.

    Returns
    -------
    ndarray
        The square state matrix of ``(x, x_VE, register)``: its eigenvalues
        are the closed loop's poles (with one more at 0 when ``eps = 0``,
        the register's last, unused, entry).
    """
    A, B, C, D = _realisation(plant_num, plant_den)
    if np.any(D != 0):
        raise ValueError("the plant must be strictly proper (y[k] = C x[k])")
    Ae, Be, Ce, De = _realisation(env_num, env_den)
    Phi, _ = _held_input_integral(A, B, T)
    Phi_late, gamma0 = _held_input_integral(A, B, (1 - eps) * T)
    gamma1 = Phi_late @ _held_input_integral(A, B, eps * T)[1]
    n, ne = A.shape[0], Ae.shape[0]
    size = n + ne + d + 1
    x, e, first = slice(0, n), slice(n, n + ne), n + ne
    unit = np.eye(size)
    # The force f[k] = Ce x_VE[k] + De C x[k], a row over the state.
    force = np.zeros(size)
    force[x], force[e] = (De @ C).ravel(), Ce.ravel()
    # u[k-d] = -f[k-d]: the force now (d = 0) or the register's entry d - 1;
    # u[k-d-1] = -f[k-d-1]: its entry d.
    recent = force if d == 0 else unit[first + d - 1]
    M = np.zeros((size, size))
    M[x, x] = Phi
    M[x] -= np.outer(gamma0.ravel(), recent) + np.outer(gamma1.ravel(), unit[first + d])
    M[e, e], M[e, x] = Ae, Be @ C
    M[first] = force
    M[first + 1:, first:size - 1] = np.eye(d)
    return M


def fractional_plant_response(plant_num, plant_den, T, eps, z):
    """``P_eps(z)``, the plant whose held command arrives ``eps T`` late, from the state space.

    With :func:`fractional_delay_closed_loop`'s ``Phi``, ``Gamma0`` and
    ``Gamma1`` (Van Loan's block exponential, SciPy), the sampled output
    over the held command is ``C (z I - Phi)^-1 (Gamma0 + Gamma1 / z)``.
    """
    A, B, C, D = _realisation(plant_num, plant_den)
    if np.any(D != 0):
        raise ValueError("the plant must be strictly proper (y[k] = C x[k])")
    Phi, _ = _held_input_integral(A, B, T)
    Phi_late, gamma0 = _held_input_integral(A, B, (1 - eps) * T)
    gamma1 = Phi_late @ _held_input_integral(A, B, eps * T)[1]
    resolvent = np.linalg.solve(z * np.eye(A.shape[0]) - Phi, gamma0 + gamma1 / z)
    return complex((C @ resolvent).item())


def fractional_delay_radius(plant_num, plant_den, env_num, env_den, T, d, eps):
    """Largest modulus of the eigenvalues of :func:`fractional_delay_closed_loop`."""
    matrix = fractional_delay_closed_loop(plant_num, plant_den, env_num, env_den, T, d, eps)
    return float(np.max(np.abs(np.linalg.eigvals(matrix))))


def loop_coefficients(loop, values):
    """``(plant_num, plant_den, env_num, env_den)`` of a :class:`symstab.Loop` at ``values``.

    The plant's s-coefficients and the environment's z-coefficients, highest
    first, from the loop's expressions with ``values`` substituted by SymPy
    (as :func:`python_control_parts` reads them).
    """
    s, z = sp.symbols("s z")
    plant = _substituted_coefficients(loop.plant, s, _values_of(loop.plant, values))
    environment = _substituted_coefficients(loop.environment, z,
                                            _values_of(loop.environment, values))
    return (*plant, *environment)


def fractional_delay_oracle(loop, values):
    """``tau -> (spectral radius, angle of the largest root)`` of ``loop`` at a delay of ``tau`` samples.

    From :func:`fractional_delay_closed_loop` (the state-space discretisation,
    nothing of symstab's derivation) at ``values`` with the delay replaced.
    """
    coefficients = loop_coefficients(loop, values)
    T = float(values["T"])

    def at(tau):
        d = int(math.floor(tau))
        roots = np.linalg.eigvals(fractional_delay_closed_loop(*coefficients, T, d, tau - d))
        k = int(np.argmax(np.abs(roots)))
        return float(abs(roots[k])), float(abs(np.angle(roots[k])))

    return at


# --------------------------------------------------------------------------
# Passivity with a fractional loop delay: the lifted quadratic form
# --------------------------------------------------------------------------

def lifted_least_damping(H, theta, T, m, N):
    """The least passive damping at ``theta`` of a force held from ``(k + m/N) T``, by lifting.

    Independent of symstab's 2x2 reduction.  The force ``f_k = (H x)_k``
    (``H`` the environment behind its whole samples of delay, ``x_k =
    x(kT)``) is held on ``[(k + m/N) T, (k + 1 + m/N) T)``.  Each period is
    cut into ``N`` sub-intervals of ``T/N`` with the position's increments
    ``u_{k,i}`` on them; the velocity is free inside each, so the least
    friction work ``b int v**2`` for given increments is ``b sum u**2 / (T/N)``
    (Cauchy-Schwarz), and ``f_k`` works on the sub-intervals ``i >= m`` of
    period ``k`` and ``i < m`` of period ``k + 1``.  With ``x_{k+1} - x_k =
    sum_i u_{k,i}``, ``F = G 1^T U``, ``G = H/(z - 1)``, Parseval turns the
    port's energy into ``(b N/T) |U|**2 + U^H P U`` per frequency with ``P =
    conj(G) 1 w^T`` (``w_i = z`` for ``i < m``, 1 after): passive at ``theta``
    if and only if ``b >= -(T/N) lambda_min((P + P^H)/2)``.

    Parameters
    ----------
    H : complex or ndarray
        ``H(e^{j theta})`` at each angle (from the environment's own
        coefficients or python-control), away from ``theta = 0``.
    theta : float or ndarray
        The angles, in (0, pi].
    T : float
        The sample period.
    m, N : int
        The fraction ``eps = m / N``; ``m = 0`` is Colgate and Schenkel's bound.

    Returns
    -------
    ndarray
        The least passive damping at each angle.
    """
    theta = np.atleast_1d(np.asarray(theta, dtype=float))
    z = np.exp(1j * theta)
    G = np.broadcast_to(np.asarray(H, dtype=complex), theta.shape) / (z - 1)
    w = np.where(np.arange(N)[None, :] < m, z[:, None], 1.0)          # (angles, N)
    P = np.conj(G)[:, None, None] * np.ones((1, N, 1)) * w[:, None, :]
    hermitian = 0.5 * (P + np.conj(np.swapaxes(P, 1, 2)))
    return -(T / N) * np.linalg.eigvalsh(hermitian)[:, 0]


def first_crossing(at, start, step=1 / 32, stop=None):
    """The first delay from ``start`` at which ``at(tau)[0]`` (a radius) reaches 1, to 1e-12 of a sample.

    A grid of ``step`` then bisection; ``stop``: the delay past which no
    crossing is an error.
    """
    low = start
    while at(low + step)[0] < 1:
        low += step
        assert stop is None or low < stop, "no crossing found"
    high = low + step
    while high - low > 1e-12 * max(1.0, high):
        middle = (low + high) / 2
        low, high = (middle, high) if at(middle)[0] < 1 else (low, middle)
    return (low + high) / 2


def impulse_norm(num, den, dt):
    """sqrt(sum h[k]**2) by scipy's impulse response, long enough for the tail to vanish."""
    import scipy.signal

    steps = 4096
    while True:
        _, (h,) = scipy.signal.dimpulse((num, den, dt), n=steps)
        energy = np.cumsum(h.ravel() ** 2)
        if energy[-1] == 0 or energy[-1] - energy[steps // 2] < 1e-17 * energy[-1]:
            return math.sqrt(energy[-1])
        steps *= 2


def force_noise_of(loop, values, q):
    """The force RMS of an encoder of quantum ``q`` at ``values``: python-control's closed loop
    ``VE z**-d / (1 + VE z**-d P)`` (:func:`python_control_parts`), its impulse response summed
    (:func:`impulse_norm`), times ``q / sqrt(12)``."""
    plant, environment, delay = python_control_parts(loop, values)
    closed = environment * delay / (1 + environment * delay * plant)
    return q / math.sqrt(12.0) * impulse_norm(closed.num[0][0], closed.den[0][0],
                                              float(values["T"]))


def _values_of(expression, values):
    """``(symbol, value, type)`` of the ``values`` that ``expression`` reads, in a fixed order.

    The type too: ``1 == 1.0``, but SymPy substitutes the two differently.
    """
    return tuple(sorted(((symbol, values[str(symbol)], type(values[str(symbol)]))
                         for symbol in expression.free_symbols if str(symbol) in values),
                        key=lambda item: str(item[0])))


@functools.lru_cache(maxsize=4096)
def _substituted_coefficients(expression, variable, items):
    """``(numerator, denominator)`` coefficients in ``variable`` of ``expression`` at ``items``.

    SymPy's substitution, ``together`` and ``Poly``, remembered: a sampling
    oracle asks again for the same plant at every cell of a draw and for the
    same environment at every draw of a cell.
    """
    num, den = sp.fraction(sp.together(expression.subs({symbol: value
                                                        for symbol, value, _ in items})))
    return (tuple(float(c) for c in sp.Poly(num, variable).all_coeffs()),
            tuple(float(c) for c in sp.Poly(den, variable).all_coeffs()))


# --------------------------------------------------------------------------
# Points for the oracles
# --------------------------------------------------------------------------

def random_loop_points(seed, n, *, delta_range=(1e-4, 1.0)):
    """Seeded random parameter points, physical and dimensionless.

    delta log-uniform in ``delta_range``, d in 0..12, gamma in [-0.9, 2.5],
    alpha in [-1, 5], beta in [-2, 3]; m log-uniform in [0.005, 0.5] and T
    log-uniform in [0.25, 4] ms (haptic devices; far outside, python-control's
    own polynomial arithmetic loses digits once K_w = alpha m / T^2 ~ 1e9).
    """
    rng = np.random.default_rng(seed)
    lo, hi = np.log10(delta_range[0]), np.log10(delta_range[1])
    points = []
    for _ in range(n):
        points.append(dict(
            delta=float(10 ** rng.uniform(lo, hi)),
            d=int(rng.integers(0, 13)),
            gamma=float(rng.uniform(-0.9, 2.5)),
            alpha=float(rng.uniform(-1.0, 5.0)),
            beta=float(rng.uniform(-2.0, 3.0)),
            m=float(10 ** rng.uniform(np.log10(0.005), np.log10(0.5))),
            T=float(10 ** rng.uniform(np.log10(2.5e-4), np.log10(4e-3))),
        ))
    return points


def dimensionless(point):
    return {k: point[k] for k in ("alpha", "beta", "gamma", "d", "delta")}


# --------------------------------------------------------------------------
# symstab's derivation at high precision (a reference, not an independent oracle)
# --------------------------------------------------------------------------

def mpf_args(*values):
    return tuple(mpmath.mpf(v) for v in values)


@functools.lru_cache(maxsize=None)
def _coefficient_function(d):
    args = (model.alpha, model.beta, model.gamma, model.delta, model.Gamma)
    return sp.lambdify(args, characteristic_polynomial().coeffs(d), modules="mpmath")


def loop_coefficients_mp(*, alpha, beta, gamma, d, delta):
    """``characteristic_polynomial().coeffs(d)`` at a point, in mpmath (current dps)."""
    a, b, g, dl = mpf_args(alpha, beta, gamma, delta)
    return _coefficient_function(d)(a, b, g, dl, mpmath.exp(dl))


def chi_mp(z, coeffs):
    """Return ``(chi(z), sum |c_k| |z|^k)`` for coefficients highest first."""
    value, size, radius = mpmath.mpf(0), mpmath.mpf(0), abs(z)
    for c in coeffs:
        value = value * z + c
        size = size * radius + abs(c)
    return value, size


def roots_outside_unit_circle_mp(coeffs, *, dps=60, n=1024, max_n=2**16):
    """How many roots of the polynomial ``coeffs`` (highest first) lie outside |z| = 1.

    The argument principle at ``dps`` digits: the winding number of
    ``chi(e^{j theta})`` over ``n`` equal steps counts the roots inside; each
    step must turn the phase by less than pi / 4, else the grid is doubled
    (up to ``max_n``; past it, or on a value within its rounding of 0, a
    root is on the circle to this precision and ``ValueError`` is raised).
    Independent of the code under test: no root finder, no Schur-Cohn.
    """
    with mpmath.workdps(dps):
        c = [mpmath.mpf(x) for x in coeffs]
        while c and c[0] == 0:
            c = c[1:]
        while n <= max_n:
            phases = []
            for k in range(n):
                value, size = chi_mp(mpmath.expjpi(mpmath.mpf(2 * k) / n), c)
                if abs(value) <= size * mpmath.mpf(10) ** (10 - dps):
                    raise ValueError("a root is on the unit circle to this precision")
                phases.append(mpmath.arg(value))
            phases.append(phases[0])
            steps = [(b - a + mpmath.pi) % (2 * mpmath.pi) - mpmath.pi
                     for a, b in zip(phases, phases[1:], strict=False)]
            if max(abs(s) for s in steps) < mpmath.pi / 4:
                inside = int(mpmath.nint(sum(steps) / (2 * mpmath.pi)))
                return len(c) - 1 - inside
            n *= 2
    raise ValueError(f"the phase of chi on the circle was not resolved on {max_n} points")


@functools.lru_cache(maxsize=None)
def boundary_functions():
    """mpmath functions alpha(theta, gamma, d, delta, Gamma), beta(...) of boundary()."""
    bd = boundary()
    args = (model.theta, model.gamma, model.d, model.delta, model.Gamma)
    return (sp.lambdify(args, bd.alpha, modules="mpmath"),
            sp.lambdify(args, bd.beta, modules="mpmath"))


def boundary_point_mp(theta, gamma, d, delta):
    """(alpha, beta) of symstab's boundary() at a point, in mpmath (current dps)."""
    fa, fb = boundary_functions()
    t, g, dl = mpf_args(theta, gamma, delta)
    return fa(t, g, d, dl, mpmath.exp(dl)), fb(t, g, d, dl, mpmath.exp(dl))


def loop_arc_mp(loop, theta, *, dps=50):
    """The arc of a :class:`symstab.Loop`'s default plane from its model, at ``dps`` digits.

    ``1 + VE(z) G(z) z**-d = 0`` at ``z = exp(j theta)`` solved for the
    plane's ``(x, y)`` by Cramer's rule on its real and imaginary parts,
    with the loop's default values as exact binary numbers: ``G`` from the
    loop's symbolic pulse transfer function (or, for a plant discretised
    numerically, the matrix exponential at ``dps`` digits), ``VE`` the
    environment as written.  Nothing is rounded to doubles: this is the
    reference the arc's accuracy is measured against, coefficients'
    rounding included.

    Returns
    -------
    list of (mpf, mpf)
    """
    from symstab.symbolic.discretize import numeric_zoh

    z = model.z
    x, y = loop.plane
    values = dict(loop.defaults)
    d = int(values.pop("d"))
    with mpmath.workdps(dps):
        symbols = {s.name: s for s in loop.environment.free_symbols | loop.plant.free_symbols}
        exact = {symbols[k]: sp.Rational(float(v)) for k, v in values.items()
                 if k in symbols and k not in (x, y)}
        environment = loop.environment.subs(exact)
        if loop.zoh_method == "residues":
            pulse = sp.lambdify(z, loop.pulse_transfer_function().subs(exact), "mpmath")
        else:
            num, den = sp.fraction(sp.together(loop.plant.subs(exact)))
            p_n, p_d = numeric_zoh([mpmath.mpf(sp.Rational(c).p) / sp.Rational(c).q
                                    for c in sp.Poly(num, model.s).all_coeffs()],
                                   [mpmath.mpf(sp.Rational(c).p) / sp.Rational(c).q
                                    for c in sp.Poly(den, model.s).all_coeffs()],
                                   mpmath.mpf(float(values["T"])), dps=dps)

            def pulse(w):
                return mpmath.polyval(p_n, w) / mpmath.polyval(p_d, w)
        X, Y = symbols[x], symbols[y]
        parts = [sp.lambdify(z, e, "mpmath") for e in
                 (environment.subs({X: 0, Y: 0}), sp.diff(environment, X), sp.diff(environment, Y))]
        out = []
        for t in theta:
            w = mpmath.expj(t if isinstance(t, mpmath.mpf) else mpmath.mpf(float(t)))
            g = pulse(w) * w**(-d)
            a0, cx, cy = 1 + parts[0](w) * g, parts[1](w) * g, parts[2](w) * g
            det = cx.real * cy.imag - cy.real * cx.imag
            out.append(((-a0.real * cy.imag + cy.real * a0.imag) / det,
                        (-cx.real * a0.imag + a0.real * cx.imag) / det))
        return out


def theta_max_box_sample(seed, n):
    """Seeded ``(gamma, d, delta)`` with an arc, in the box of issue 12.

    gamma in [-1, 3] (one draw in five a heavy virtual mass up to 1e6),
    d in 0..200 (half of them in 0..12), delta log-uniform in [1e-6, 1].
    """
    rng = np.random.default_rng(seed)
    points = []
    while len(points) < n:
        delta = float(10 ** rng.uniform(-6, 0))
        d = int(rng.choice([int(rng.integers(0, 13)), int(rng.integers(0, 201))]))
        gamma = float(rng.uniform(-1, 3)) if rng.uniform() < 0.8 else float(10 ** rng.uniform(0, 6))
        if gamma + 1 + delta * (d + 1) > 0:
            points.append((gamma, d, delta))
    return points


def simulated_loop_radius(K, B, *, d, f_c=None, f_a=None, M=0.0, m=None, b=None, T=None):
    """Spectral radius of the simulated linear loop, by python-control.

    The velocity estimate is the backward difference ``(x[k] - x[k-1])/T``,
    filtered by ``v_f[k] = a v_f[k-1] + (1 - a) v[k]`` with ``a = exp(-2 pi
    f_c T)``; the force is ``K x + B v_f + M (v_f[k] - v_f[k-1])/T`` (the
    paper's force law with its velocity filter, written here as transfer
    functions from the description, not from the simulator's loop).
    The actuator is ``1/(tau s + 1)`` with ``tau = 1/(2 pi f_a)``, before the
    plant, inside the hold.
    """
    import control

    from symstab.numeric.paper.device import PAPER_DEVICE

    m = PAPER_DEVICE.m if m is None else m
    b = PAPER_DEVICE.b if b is None else b
    T = PAPER_DEVICE.T if T is None else T

    plant = control.tf([1], [m, b, 0])
    if f_a is not None:
        plant = plant * control.tf([1], [1 / (2 * math.pi * f_a), 1])
    G = control.c2d(plant, T, "zoh")
    z = control.tf([1, 0], [1], T)
    difference = (z - 1) / (T * z)
    if f_c is None:
        VE = K + B * difference + M * difference * difference
    else:
        a = math.exp(-2 * math.pi * f_c * T)
        velocity = (1 - a) * z / (z - a) * difference
        VE = K + B * velocity + M * difference * velocity
    delay = control.tf([1], [1] + [0] * d, T)
    poles = control.poles(control.feedback(G, VE * delay))
    return float(np.max(np.abs(poles)))


def dense_maximum(f, low, high, *, points=11, levels=7):
    """The largest ``f`` over [low, high] by nested grids (no optimiser): ``(x, f(x))``.

    A first grid of ``points`` points over the range, then grids of five
    points, each spanning a step of the one before on each side of its best
    point (so halving the step), until the step is ``(2 / (points -
    1))**(levels - 1)`` of the first's: the resolution of ``levels`` grids of
    ``points`` points zoomed the same way.  The optimum of a design may be a
    kink (a stable set shrinking to a sliver and vanishing): that last step
    keeps a steep side within 1e-4.  ``f`` returns ``-inf`` where there is
    nothing to maximise.

    Each grid's ends and middle are points of the grid before (the best and
    its two neighbours), so ``f`` (a certified answer near a kink takes
    seconds) is called once per distinct point, twice per halving: 39 calls
    for the defaults, where eleven-point grids (the same first grid and
    resolution) took 59.
    """
    best_value, best = -math.inf, None
    ends = low, high
    finest = (high - low) / (points - 1) * (2 / (points - 1)) ** (levels - 1)
    seen = {}

    def value(v):
        if v not in seen:
            seen[v] = f(v)
        return seen[v]

    grid = np.linspace(low, high, points)
    while True:
        if best is not None:
            # The best point so far is the middle of this grid, up to rounding: itself.
            i = int(np.argmin(np.abs(grid - best)))
            if abs(grid[i] - best) <= 1e-9 * (grid[-1] - grid[0]):
                grid[i] = best
        found = [value(float(v)) for v in grid]
        k = int(np.argmax(found))
        if found[k] > best_value:
            best_value, best = found[k], float(grid[k])
        if best is None:
            return None, -math.inf
        step = grid[1] - grid[0]
        if step <= finest * (1 + 1e-9):
            return best, best_value
        # The next grid spans a step of this one on each side of the best point, at most
        # to the ends; a side inside this grid is its point there (evaluated already).
        j = int(np.argmin(np.abs(grid - best)))
        low = float(grid[j - 1]) if j > 0 else max(ends[0], best - step)
        high = float(grid[j + 1]) if j < len(grid) - 1 else min(ends[1], best + step)
        grid = np.linspace(low, high, 5)


def coulomb_friction_run(model, *, K, B, T, d, steps, x0, coulomb, stiction):
    """Sampled positions of a loop whose mass has Coulomb friction, integrated event by event.

    An independent reference for the simulator's sub-steps: scipy's DOP853
    at rtol 1e-12 between events, the events located by scipy (the mass's
    velocity reaching 0; the force on a held mass reaching the stiction
    force).  ``model`` is the physics written out by hand:
    ``rhs(state, u, friction)`` (friction on the mass, in the direction of
    its motion), ``velocity(state)``, ``net(state, u)`` (the force on the
    mass at rest besides friction), ``stop(state)`` (the state with the
    mass's velocity 0) and ``start(x0)`` (everything at rest at x0).  The
    environment is ``K x + B (x[k] - x[k-1]) / T``, the command ``u[k] =
    -f[k - d]`` held over the period, as in the simulator.
    """
    from scipy.integrate import solve_ivp

    state = model["start"](x0)
    moving, direction = False, 0.0
    samples, forces = [model["position"](state)], []
    previous = samples[0]
    for k in range(steps):
        x = samples[-1]
        forces.append(K * x + B * (x - previous) / T)
        previous = x
        u = -forces[k - d] if k >= d else 0.0
        t = 0.0
        while t < T:
            if not moving:
                net = model["net"](state, u)
                if abs(net) > stiction:
                    moving, direction = True, math.copysign(1.0, net)
                    continue

                def slip(_, y, u=u):
                    return abs(model["net"](y, u)) - stiction
                slip.terminal, slip.direction = True, 1
                run = solve_ivp(lambda _, y, u=u: model["rhs"](y, u, model["net"](y, u)),
                                (t, T), state, method="DOP853", rtol=1e-12, atol=1e-18,
                                events=slip)
                state = model["stop"](run.y[:, -1])
                if run.status == 1:
                    moving, direction = True, math.copysign(1.0, model["net"](state, u))
            else:
                def halt(_, y):
                    return model["velocity"](y)
                # Only a crossing against the motion: a breakaway starts at v = 0.
                halt.terminal, halt.direction = True, -direction
                run = solve_ivp(lambda _, y, u=u, f=coulomb * direction: model["rhs"](y, u, f),
                                (t, T), state, method="DOP853", rtol=1e-12, atol=1e-18,
                                events=halt)
                state = run.y[:, -1]
                if run.status == 1:
                    state = model["stop"](state)
                    moving = False
            t = run.t[-1]
        samples.append(model["position"](state))
    return np.array(samples)
