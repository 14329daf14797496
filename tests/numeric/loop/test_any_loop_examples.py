"""The example loops of ``examples/loops/`` against python-control (issue 11).

Each example file is loaded with :func:`symstab.load_loop` and compared with
an oracle built here, independently of symstab, from the physics written in
the file's comment: the plant as a numeric continuous ``control.tf`` (or
``control.ss`` from the equations of motion), discretised by
``control.sample_system(G, T, 'zoh')``; the environment as a discrete
``control.tf(..., dt=T)``; the delay ``z**-d``.  The closed-loop poles are the
roots of ``z**d Ve_d P_d + Ve_n P_n``, assembled with ``np.polymul``'s
arithmetic and ``np.polyadd`` from python-control's polynomials, which
:func:`test_oracle_polynomial_is_control_feedback` checks against
``control.feedback(G_zoh, VE * delay).poles()``.  The parameter values are
read from the file with ``tomllib``, not through the loop.

Acceptance of issue 11:

* ``is_stable`` agrees with the oracle on 1,000 random points per example
  (the plane's parameters, over a box around the stable set, at
  d = 0, 1, 4, 10), points with ``| |r| - 1 | < 1e-9`` skipped;
* ``stable_intervals`` agrees with a bisection on the oracle to 1e-6 of the
  interval's scale, ``max(|endpoint|, width)`` (an endpoint at 0, such as
  K = 0 where a root sits at z = 1, has no relative error of its own);
* a plant or environment that is not proper, not rational, or whose plane
  parameters enter non-affinely is refused with a message naming the fault.
"""

import dataclasses
import math
import sys

import numpy as np
import pytest

import symstab

from conftest import REPO

if sys.version_info >= (3, 11):
    import tomllib
else:   # pragma: no cover - Python 3.10
    import tomli as tomllib

control = pytest.importorskip("control")

EXAMPLES = sorted((REPO / "examples" / "loops").glob("*.toml"))
DELAYS = (0, 1, 4, 10)
POINTS_PER_DELAY = 250
#: Oracle radii this close to 1 are too close to call in double precision.
SKIP_BAND = 1e-9
#: stable_intervals endpoints vs the oracle's, relative to max(|endpoint|, width).
INTERVAL_RTOL = 1e-6


# --------------------------------------------------------------------------
# The oracle: each example's physics, numeric, in python-control
# --------------------------------------------------------------------------

def _eq1_environment(p, K, B):
    """K + B (z - 1)/(T z) + M (z - 1)**2/(T z)**2 times T**2 z**2: (num, den) rows."""
    T, M = p["T"], p.get("M", 0.0)
    K, B = np.broadcast_arrays(np.asarray(K, float), np.asarray(B, float))
    num = np.stack([K * T**2 + B * T + M, -B * T - 2 * M + 0 * K, M + 0 * K], axis=-1)
    den = np.broadcast_to([T**2, 0.0, 0.0], num.shape)
    return num, den


def _lowpass_environment(p, K, B):
    """K + B (1 - a)(z - 1)/(T (z - a)), a = exp(-2 pi f_c T), times T (z - a)."""
    T = p["T"]
    a = math.exp(-2 * math.pi * p["f_c"] * T)
    K, B = np.broadcast_arrays(np.asarray(K, float), np.asarray(B, float))
    num = np.stack([K * T + B * (1 - a), -K * T * a - B * (1 - a)], axis=-1)
    den = np.broadcast_to([T, -T * a], num.shape)
    return num, den


def _tustin_environment(p, K, B):
    """K + B (2/T)(z - 1)/(z + 1), times T (z + 1)."""
    T = p["T"]
    K, B = np.broadcast_arrays(np.asarray(K, float), np.asarray(B, float))
    num = np.stack([K * T + 2 * B, K * T - 2 * B], axis=-1)
    den = np.broadcast_to([T, T], num.shape)
    return num, den


def _two_mass_plant(p):
    """X1/F from the equations of motion, as a state-space model.

    States (x1, x2, v1, v2):
    m1 v1' = F - b1 v1 - k_t (x1 - x2) - c_t (v1 - v2),
    m2 v2' = k_t (x1 - x2) + c_t (v1 - v2).
    """
    m1, m2, b1, k, c = p["m1"], p["m2"], p["b1"], p["k_t"], p["c_t"]
    A = [[0, 0, 1, 0],
         [0, 0, 0, 1],
         [-k / m1, k / m1, -(b1 + c) / m1, c / m1],
         [k / m2, -k / m2, c / m2, -c / m2]]
    return control.ss(A, [[0], [0], [1 / m1], [0]], [[1, 0, 0, 0]], [[0]])


@dataclasses.dataclass(frozen=True)
class Oracle:
    plant: object          # values -> continuous control.tf / control.ss
    environment: object    # (values, K, B) -> (num rows, den rows) in z
    zoh_method: str        # what the loop must report: factors of degree <= 2 or not
    affine: frozenset      # parameters chi is affine in, from the physics


EQ1 = frozenset({"K", "B", "M"})

# affine: the environment's gains always; a plant parameter only where the
# pulse transfer function is affine in it after clearing P_d's leading
# coefficient (1/(m s^2) gives T^2 (z + 1) / (2 m (z - 1)^2): m is); every
# exp(-b T/m), exp(-T/tau), exp(-2 pi f_c T) or numeric-path parameter is not.
ORACLES = {
    "paper": Oracle(lambda p: control.tf([1.0], [p["m"], p["b"], 0.0]),
                    _eq1_environment, "residues", EQ1),
    "frictionless": Oracle(lambda p: control.tf([1.0], [p["m"], 0.0, 0.0]),
                           _eq1_environment, "residues", EQ1 | {"m"}),
    "actuator_lag": Oracle(lambda p: control.tf([1.0], np.polymul([p["tau"], 1.0],
                                                                   [p["m"], p["b"], 0.0])),
                           _eq1_environment, "residues", EQ1),
    # s times an irreducible cubic: no closed form worth carrying.
    "two_mass": Oracle(_two_mass_plant, _eq1_environment, "matrix exponential", EQ1),
    "lowpass_velocity": Oracle(lambda p: control.tf([1.0], [p["m"], p["b"], 0.0]),
                               _lowpass_environment, "residues", frozenset({"K", "B"})),
    "tustin_damper": Oracle(lambda p: control.tf([1.0], [p["m"], p["b"], 0.0]),
                            _tustin_environment, "residues", frozenset({"K", "B"})),
    # A complex pair (m + m_h) s^2 + (b + b_h) s + k_h: written with a square root.
    "operator_arm": Oracle(lambda p: control.tf([1.0], [p["m"] + p["m_h"], p["b"] + p["b_h"],
                                                        p["k_h"]]),
                           _eq1_environment, "residues", EQ1),
}


class Example:
    """An example file, its loop (symstab) and its oracle (python-control)."""

    def __init__(self, path):
        self.path = path
        data = tomllib.loads(path.read_text(encoding="utf-8"))
        self.data = data
        self.values = {k: (v["value"] if isinstance(v, dict) else v)
                       for k, v in data["parameters"].items()}
        self.x, self.y = data["plane"]
        assert {self.x, self.y} == {"B", "K"}, "the oracles take the plane (B, K)"
        self.oracle = ORACLES[path.stem]
        self.loop = symstab.load_loop(path)
        T = self.values["T"]
        plant = control.sample_system(self.oracle.plant(self.values), T, "zoh")
        plant = control.tf(plant)
        self.plant_zoh = plant
        self.p_num = np.trim_zeros(np.asarray(plant.num[0][0], float), "f")
        self.p_den = np.asarray(plant.den[0][0], float)
        self.scans = {}

    def kb(self, x_values, y_values):
        """(K, B) from values of the plane's (x, y)."""
        named = {self.x: x_values, self.y: y_values}
        return named["K"], named["B"]

    def environment_tf(self, K, B):
        """VE(z) at one point as a discrete python-control transfer function."""
        num, den = self.oracle.environment(self.values, K, B)
        return control.tf(num, den, self.values["T"])

    def chi(self, K, B, d):
        """The closed loop's polynomial at one point: z**d Ve_d P_d + Ve_n P_n."""
        # The rows of :meth:`environment_tf` as python-control keeps them (a zero numerator
        # over 1), without a control.tf at each of the bisections' thousands of points
        # (most of the oracle's time); test_oracle_polynomial_is_control_feedback checks
        # these poles against control.feedback.
        ve_num, ve_den = (np.asarray(r, float) for r in self.oracle.environment(self.values,
                                                                               K, B))
        if not np.any(ve_num):
            ve_num, ve_den = np.zeros(1), np.ones(1)
        delayed = _polymul(_polymul(ve_den, self.p_den), np.r_[1.0, np.zeros(d)])
        return np.polyadd(delayed, _polymul(ve_num, self.p_num))

    def poles(self, K, B, d):
        """Closed-loop poles at one point: the roots of :meth:`chi`."""
        return np.roots(self.chi(K, B, d))

    def radius(self, x_values, y_values, d):
        K, B = np.broadcast_arrays(*self.kb(np.asarray(x_values, float),
                                            np.asarray(y_values, float)))
        out = _largest_moduli([self.chi(k, b, d)
                               for k, b in zip(K.ravel(), B.ravel(), strict=True)])
        return out.reshape(K.shape)

    def stable(self, x_values, y_values, d):
        return self.radius(x_values, y_values, d) < 1.0


def _polymul(a, b):
    """``np.polymul(a, b)`` of 1-D arrays: the convolution of their poly1d coefficients.

    The same numbers without two ``np.poly1d`` per call (their
    ``np.trim_zeros`` was most of the oracle's time): leading zeros dropped,
    an all-zero polynomial kept as ``[0]``.
    """
    def coefficients(c):
        c = np.atleast_1d(c)
        nonzero = np.flatnonzero(c)
        return c[nonzero[0]:] if nonzero.size else np.zeros(1, dtype=c.dtype)

    return np.convolve(coefficients(a), coefficients(b))


def _largest_moduli(rows):
    """``max |np.roots(row)|`` of each row, the companion matrices of equal degree batched.

    ``np.roots`` of a row with nonzero first and last coefficients is
    ``eigvals`` of the companion whose first row is ``-row[1:] / row[0]``;
    the same matrices in one stacked ``eigvals`` call give the same roots
    without a call per row.  Any other row goes to ``np.roots`` itself.
    """
    out = np.empty(len(rows))
    batches = {}
    for i, row in enumerate(rows):
        if len(row) > 1 and row[0] != 0 and row[-1] != 0 and np.all(np.isfinite(row)):
            batches.setdefault(len(row), []).append(i)
        else:
            out[i] = np.max(np.abs(np.roots(row)))
    for size, members in batches.items():
        table = np.array([rows[i] for i in members])
        companion = np.zeros((len(members), size - 1, size - 1))
        companion[:, np.arange(1, size - 1), np.arange(size - 2)] = 1.0
        companion[:, 0, :] = -table[:, 1:] / table[:, :1]
        out[members] = np.max(np.abs(np.linalg.eigvals(companion)), axis=1)
    return out


@pytest.fixture(scope="module")
def examples():
    """Loaded examples, built once (their derivations in the session's cache)."""
    cache = {}

    def get(path):
        if path not in cache:
            cache[path] = Example(path)
        return cache[path]

    return get


def _ids(paths):
    return [p.stem for p in paths]


def test_examples_are_shipped():
    """The seven loops of issue 11 are there, and each has an oracle here."""
    assert {p.stem for p in EXAMPLES} == set(ORACLES)


# --------------------------------------------------------------------------
# Where the stable set is: a coarse scan, not the lines under test
# --------------------------------------------------------------------------

def _signed_log_grid(scale, n=60):
    """0 and +-scale * 10**k for k in [-6, 4]: the stable set's extent is unknown."""
    magnitudes = abs(scale) * np.logspace(-6, 4, n)
    return np.concatenate([-magnitudes[::-1], [0.0], magnitudes])


def _stable_scan(example, d):
    """The stable points of a signed log grid around the defaults (is_stable, vectorised).

    Only chooses where to sample and which lines to cut; the verdicts there
    are checked against the oracle by the tests.
    """
    if d in example.scans:
        return example.scans[d]
    gx = _signed_log_grid(example.values[example.x] or 1.0)
    gy = _signed_log_grid(example.values[example.y] or 1.0)
    X, Y = np.meshgrid(gx, gy, indexing="ij")
    stable = example.loop.is_stable(**{example.x: X, example.y: Y}, d=d).filled(False)
    assert stable.any(), f"{example.path.stem}: no stable point on the scan at d = {d}"
    example.scans[d] = gx, gy, X[stable], Y[stable]
    return example.scans[d]


def _stable_box(example, d):
    """A box around the stable set at delay ``d``: the scan's stable extent, one grid step out."""
    gx, gy, xs, ys = _stable_scan(example, d)

    def widen(grid, values):
        i, j = np.searchsorted(grid, values.min()), np.searchsorted(grid, values.max())
        lo, hi = grid[max(i - 1, 0)], grid[min(j + 1, len(grid) - 1)]
        return lo - 0.1 * (hi - lo), hi + 0.1 * (hi - lo)

    return widen(gx, xs), widen(gy, ys)


# --------------------------------------------------------------------------
# The files
# --------------------------------------------------------------------------

@pytest.mark.parametrize("path", EXAMPLES, ids=_ids(EXAMPLES))
def test_example_file_is_complete(path, examples):
    """Name, description, a unit for every parameter, an affine default plane."""
    example = examples(path)
    loop, data = example.loop, example.data
    assert data["name"] == path.stem
    assert len(data["description"]) > 20
    assert "#" in path.read_text(encoding="utf-8").splitlines()[0], "a comment block comes first"
    assert set(loop.parameters) == set(example.values), "every parameter has a default value"
    assert set(loop.units) == set(loop.parameters), "every parameter has a unit"
    assert loop.plane == (example.x, example.y)
    assert set(loop.plane) <= set(loop.affine_parameters())
    assert loop.zoh_method == example.oracle.zoh_method
    assert set(loop.affine_parameters()) == example.oracle.affine


@pytest.mark.parametrize("path", EXAMPLES, ids=_ids(EXAMPLES))
def test_default_point_is_stable(path, examples):
    """The file's default values are a stable point, for the loop and the oracle."""
    example = examples(path)
    v = example.values
    assert example.loop.is_stable() is True
    radius = float(example.radius(v[example.x], v[example.y], v["d"]))
    assert radius < 1.0, f"oracle: spectral radius {radius} at the file's defaults"
    assert example.loop.spectral_radius() == pytest.approx(radius, rel=1e-9)


@pytest.mark.parametrize("path", EXAMPLES, ids=_ids(EXAMPLES))
def test_oracle_polynomial_is_control_feedback(path, examples):
    """The oracle's polynomial has the poles of control.feedback(G_zoh, VE z**-d)."""
    example = examples(path)
    rng = np.random.default_rng(11)
    T = example.values["T"]
    for d in (0, 3):
        (x0, x1), (y0, y1) = _stable_box(example, d)
        for xv, yv in zip(rng.uniform(x0, x1, 4), rng.uniform(y0, y1, 4), strict=True):
            K, B = example.kb(xv, yv)
            delay = control.tf([1.0], np.r_[1.0, np.zeros(d)], T)
            closed = control.feedback(example.plant_zoh, example.environment_tf(K, B) * delay)
            expected = np.sort_complex(closed.poles())
            got = np.sort_complex(example.poles(K, B, d))
            assert got.shape == expected.shape
            assert np.max(np.abs(got)) == pytest.approx(np.max(np.abs(expected)), rel=1e-9)


@pytest.mark.parametrize("path", EXAMPLES, ids=_ids(EXAMPLES))
def test_limits_find_the_stable_region(path, examples):
    """limits() in the default plane (at d = 1: d = 40 is slow) reaches the oracle's boundary.

    The oracle is stable just below ``y_max`` at ``x_at_y_max`` and unstable
    just above it; the default x lies in ``[x_min, x_max]``.
    """
    example = examples(path)
    lim = example.loop.limits(d=1)
    assert not lim.empty and np.isfinite(lim.y_max), lim
    assert lim.x_min <= example.values[example.x] <= lim.x_max, lim
    below, above = example.stable(lim.x_at_y_max, lim.y_max - INTERVAL_RTOL * abs(lim.y_max)
                                  * np.array([1.0, -1.0]), 1)
    assert below and not above, f"{lim}: oracle stable below {below}, above {above}"


@pytest.mark.parametrize("path", EXAMPLES, ids=_ids(EXAMPLES))
def test_region_segments_bound_the_stable_set(path, examples):
    """Each z = +-1 piece of the region's boundary has the oracle's stable set on one side only.

    A tenth and nine tenths along each segment, a step of 1e-6 of the
    window off the line: stable (python-control's poles) on one side,
    unstable on the other.  Every example loop has the integrator's z = 1
    line among its pieces (at K = 0).
    """
    example = examples(path)
    region = example.loop.region(d=1)
    assert any(s.root == "z=1" for s in region.segments), region.segments
    span = np.array([np.ptp(region.x_range), np.ptp(region.y_range)])
    for s in region.segments:
        a, b = np.array([s.x0, s.y0]), np.array([s.x1, s.y1])
        direction = (b - a) / span
        normal = np.array([-direction[1], direction[0]]) / np.hypot(*direction) * span
        for t in (0.1, 0.9):
            point = a + t * (b - a)
            sides = [example.stable(*(point + k * 1e-6 * normal), 1) for k in (1, -1)]
            assert sides[0] != sides[1], (s, t, sides)


# --------------------------------------------------------------------------
# Acceptance: is_stable on random points
# --------------------------------------------------------------------------

@pytest.mark.parametrize("path", EXAMPLES, ids=_ids(EXAMPLES))
def test_is_stable_agrees_with_python_control(path, examples):
    example = examples(path)
    rng = np.random.default_rng(20261130)
    checked = skipped = marginal = stable = 0
    wrong = []
    for d in DELAYS:
        (x0, x1), (y0, y1) = _stable_box(example, d)
        xs = rng.uniform(x0, x1, POINTS_PER_DELAY)
        ys = rng.uniform(y0, y1, POINTS_PER_DELAY)
        got = example.loop.is_stable(**{example.x: xs, example.y: ys}, d=d)
        radius = example.radius(xs, ys, d)
        near = np.abs(radius - 1.0) < SKIP_BAND
        masked = np.ma.getmaskarray(got)
        # A marginal verdict is allowed only where the oracle cannot tell either.
        for i in np.flatnonzero(masked & ~near):
            wrong.append(f"d={d} {example.x}={xs[i]!r} {example.y}={ys[i]!r}: marginal, "
                         f"oracle radius {radius[i]!r}")
        marginal += int(masked.sum())
        skipped += int(near.sum())
        use = ~near & ~masked
        verdict = np.ma.getdata(got)
        for i in np.flatnonzero(use & (verdict != (radius < 1.0))):
            wrong.append(f"d={d} {example.x}={xs[i]!r} {example.y}={ys[i]!r}: is_stable "
                         f"{bool(verdict[i])}, oracle radius {radius[i]!r}")
        checked += int(use.sum())
        stable += int((use & (radius < 1.0)).sum())
    summary = (f"{path.stem}: {checked} points compared ({stable} stable), {skipped} within "
               f"{SKIP_BAND} of |r| = 1 skipped, {marginal} marginal verdicts")
    assert not wrong, summary + "; disagreements:\n" + "\n".join(wrong[:20])
    assert checked >= 0.99 * len(DELAYS) * POINTS_PER_DELAY, summary
    # The boxes straddle the boundary: both verdicts are well represented.
    assert 0.1 * checked < stable < 0.9 * checked, summary


# --------------------------------------------------------------------------
# Acceptance: stable_intervals against a bisection on the oracle
# --------------------------------------------------------------------------

def _oracle_intervals(stable_at, lo, hi, n=400, extra=()):
    """Stable intervals of a predicate on [lo, hi]: grid, then bisection of each change.

    ``stable_at`` takes an array of values (the grid, in one call) or one value.
    """
    grid = np.unique(np.concatenate([np.linspace(lo, hi, n), extra]))
    state = np.asarray(stable_at(grid), dtype=bool)
    edges = []
    for i in np.flatnonzero(state[1:] != state[:-1]):
        a, b = grid[i], grid[i + 1]
        for _ in range(100):
            mid = 0.5 * (a + b)
            if mid in (a, b):
                break
            if stable_at(mid) == state[i]:
                a = mid
            else:
                b = mid
        edges.append(0.5 * (a + b))
    out, start = [], lo if state[0] else None
    for edge in edges:
        if start is None:
            start = edge
        else:
            out.append((start, edge))
            start = None
    if start is not None:
        out.append((start, hi))
    return out


def _lines(example):
    """A handful of lines through stable points, each with the box to compare on.

    At each delay: the y-line through the stable point of largest y, the
    y-line at the median stable x, and the x-line at the median stable y.
    """
    lines = []
    for d in (0, 1, 4, 10):
        box = _stable_box(example, d)
        _, _, xs, ys = _stable_scan(example, d)
        top = int(np.argmax(ys))
        lines.append((example.y, example.x, float(xs[top]), d, box[1]))
        lines.append((example.y, example.x, float(np.median(xs)), d, box[1]))
        lines.append((example.x, example.y, float(np.median(ys)), d, box[0]))
    return lines


@pytest.mark.parametrize("path", EXAMPLES, ids=_ids(EXAMPLES))
def test_stable_intervals_agree_with_bisection(path, examples):
    example = examples(path)
    failures = []
    for name, other, other_value, d, (lo, hi) in _lines(example):
        got = example.loop.stable_intervals(name, **{other: other_value}, d=d)

        def stable_at(value, name=name, other=other, other_value=other_value, d=d):
            point = {name: value, other: other_value}
            return example.stable(point[example.x], point[example.y], d)

        # The oracle also looks inside each interval the loop reports, so a
        # stable interval narrower than its grid is not missed.
        inside = [0.5 * (max(a, lo) + min(b, hi)) for a, b in got if b > lo and a < hi]
        expected = _oracle_intervals(stable_at, lo, hi, extra=inside)
        clipped = [(max(a, lo), min(b, hi)) for a, b in got if b > lo and a < hi]
        label = f"{path.stem}: stable_intervals({name!r}, {other}={other_value!r}, d={d})"
        if len(clipped) != len(expected):
            failures.append(f"{label} = {got}; oracle on [{lo:.6g}, {hi:.6g}]: {expected}")
            continue
        for (a, b), (ea, eb) in zip(clipped, expected, strict=True):
            for value, reference in ((a, ea), (b, eb)):
                scale = max(abs(reference), eb - ea)
                if abs(value - reference) > INTERVAL_RTOL * scale:
                    failures.append(f"{label}: endpoint {value!r}, oracle {reference!r} "
                                    f"(error {abs(value - reference) / scale:.1e} of {scale:.3g})")
    assert not failures, "\n".join(failures)


# --------------------------------------------------------------------------
# Issue 18: the stable oracle points Loop.region missed in the actuator lag
# --------------------------------------------------------------------------

ACTUATOR_LAG = REPO / "examples" / "loops" / "actuator_lag.toml"


def _oracle_radii(example, K, B, d, M):
    """The oracle's spectral radius at many points (batched companion eigenvalues).

    The polynomial of :meth:`Example.poles`, ``z**d Ve_d P_d + Ve_n P_n``,
    from the same python-control pulse transfer function, a row per point.
    """
    num, den = example.oracle.environment(dict(example.values, M=M), K, B)

    def times(rows, p):
        out = np.zeros(rows.shape[:-1] + (rows.shape[-1] + len(p) - 1,))
        for k, c in enumerate(p):
            out[..., k:k + rows.shape[-1]] += c * rows
        return out

    delayed = np.concatenate([times(den, example.p_den), np.zeros(den.shape[:-1] + (d,))], axis=-1)
    direct = times(num, example.p_num)
    chi = delayed
    chi[..., -direct.shape[-1]:] += direct
    chi = chi.reshape(-1, chi.shape[-1])
    chi = chi / chi[:, :1]
    n = chi.shape[1] - 1
    companion = np.zeros((len(chi), n, n))
    companion[:, 0, :] = -chi[:, 1:]
    companion[:, np.arange(1, n), np.arange(n - 1)] = 1.0
    return np.max(np.abs(np.linalg.eigvals(companion)), axis=1).reshape(np.shape(K))


def test_actuator_lag_misses_no_stable_point_at_the_corner(examples):
    """At the arc's exact end (B = -b, K = 0) the region held every oracle-stable point.

    The user's example, B = -0.0324, K = 1.1e-4 at M = -0.0125, d = 2, is
    unstable (python-control: radius 1.0000157); stable points 1e-5 to its
    right were missed: the chord from the arc's exact end at theta = 0 to
    its first sample (pi / 1024) was never refined, and the stable set's
    corner lay between that chord and the arc.  Now none is missed.
    """
    example = examples(ACTUATOR_LAG)
    values = dict(d=2, M=-0.0125)
    region = example.loop.region(**values)
    B, K = np.meshgrid(np.linspace(-0.03245, -0.03235, 201), np.linspace(3e-4 / 200, 3e-4, 200))
    radius = _oracle_radii(example, K, B, **values)
    stable = radius < 1 - SKIP_BAND
    assert stable.sum() > 10_000
    inside = region.contains(B, K)
    missed = np.flatnonzero(stable & ~inside)
    assert missed.size == 0, [(B.flat[i], K.flat[i], radius.flat[i]) for i in missed[:5]]
    assert not np.any(inside & (radius > 1 + SKIP_BAND))
    assert float(_oracle_radii(example, np.array(1.1e-4), np.array(-0.0324), **values)) > 1.0
    assert not region.contains(-0.0324, 1.1e-4)


@pytest.mark.parametrize("M, d", [(0.0128, 2), (0.0128, 3), (-0.0128, 2), (-0.0125, 2)])
def test_actuator_lag_points_the_region_misses_are_boundary_pixels(examples, M, d):
    """Every oracle-stable point outside the region lies between a chord of the arc and the arc.

    On a 120 x 120 grid over the stable set, a stable point the region
    leaves out is next to its boundary: the oracle's own boundary, found by
    bisection along the nearest edge's outward normal, lies beyond the
    point by less than the decomposition's stated chord sag
    (``resolution`` times the cell's thinner extent): a boundary pixel
    within the sampled arc's chord error, not a missing sliver.
    """
    example = examples(ACTUATOR_LAG)
    region = example.loop.region(d=d, M=M)
    (cell,) = region.stable
    lo, hi = cell.outer.min(axis=0), cell.outer.max(axis=0)
    B, K = np.meshgrid(np.linspace(lo[0], hi[0], 120), np.linspace(lo[1], hi[1], 120)[1:])
    radius = _oracle_radii(example, K, B, d, M)
    stable = radius < 1 - SKIP_BAND
    missed = np.flatnonzero(stable & ~region.contains(B, K))
    assert missed.size <= 10, missed.size
    scale = np.array([region.x_range[1] - region.x_range[0], region.y_range[1] - region.y_range[0]])
    ring = cell.outer / scale
    sag = region.resolution * float(np.min(np.ptp(ring, axis=0)))
    a, b = ring, np.roll(ring, -1, axis=0)
    for i in missed:
        p = np.array([B.flat[i], K.flat[i]]) / scale
        t = np.clip(np.sum((p - a) * (b - a), axis=1) / np.sum((b - a) ** 2, axis=1), 0, 1)
        gap = np.hypot(*(p - a - t[:, None] * (b - a)).T)
        k = int(np.argmin(gap))
        edge = b[k] - a[k]
        outward = np.array([edge[1], -edge[0]]) / np.hypot(*edge)    # the ring is counter-clockwise
        inner, outer = 0.0, 4 * sag
        at = lambda s, p=p, outward=outward: (p + s * outward) * scale    # noqa: E731
        assert _oracle_radii(example, np.array(at(outer)[1]), np.array(at(outer)[0]), d, M) > 1
        for _ in range(40):
            middle = 0.5 * (inner + outer)
            q = at(middle)
            if _oracle_radii(example, np.array(q[1]), np.array(q[0]), d, M) < 1:
                inner = middle
            else:
                outer = middle
        assert gap[k] + inner <= 2 * sag, (B.flat[i], K.flat[i], gap[k], inner, sag)


# --------------------------------------------------------------------------
# Acceptance: what is refused, and how it is said
# --------------------------------------------------------------------------

PAPER_VE = "K + B*(z - 1)/(T*z)"


@pytest.mark.parametrize("plant, environment, plane, match", [
    # not proper
    ("s**2/(m*s + b)", PAPER_VE, None, r"plant G\(s\) must be proper"),
    ("(m*s**2 + b*s)", PAPER_VE, None, r"plant G\(s\) must be proper"),
    ("1/(m*s**2 + b*s)", "K + B*(z - 1)/T", None, r"environment VE\(z\) must be proper"),
    ("1/(m*s**2 + b*s)", "K*z**2/(z - 1)", None, r"environment VE\(z\) must be proper"),
    # not rational
    ("exp(-tau*s)/(m*s**2 + b*s)", PAPER_VE, None, r"plant G\(s\) must be a rational function of s"),
    ("1/(m*s**2 + b*s)", "K + B*sqrt(z - 1)/(T*z)", None,
     r"environment VE\(z\) must be a rational function of z"),
    # non-affine in the plane's parameters
    ("1/(m*s**2 + b*s)", "K**2 + B*(z - 1)/(T*z)", ("B", "K"),
     r"'K' does not enter the characteristic polynomial affinely"),
    ("1/(m*s**2 + b*s)", "K + K*B*(z - 1)/(T*z)", ("B", "K"),
     r"'B' and 'K' do not enter the characteristic polynomial jointly affinely"),
    ("1/(m*s**2 + b*s)", PAPER_VE, ("m", "K"),
     r"'m' does not enter the characteristic polynomial affinely"),
    # a plant parameter on the numeric path cannot be a plane axis
    ("1/(m*s**2 + b*s + k)", PAPER_VE, ("k", "K"),
     r"'k' does not enter the characteristic polynomial affinely"),
])
def test_refused_with_a_message_naming_the_fault(plant, environment, plane, match):
    with pytest.raises(ValueError, match=match):
        symstab.Loop(plant, environment, plane=plane)


def test_loop_file_with_a_non_affine_plane_names_the_file(tmp_path):
    text = (REPO / "examples" / "loops" / "paper.toml").read_text(encoding="utf-8")
    path = tmp_path / "bad.toml"
    path.write_text(text.replace('plane = ["B", "K"]', 'plane = ["b", "K"]'), encoding="utf-8")
    with pytest.raises(ValueError, match=r"bad\.toml: parameter 'b' does not enter"):
        symstab.load_loop(path)
