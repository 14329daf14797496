"""Robust regions (:mod:`symstab.numeric.analysis.robust`): stable for every value of a box.

Oracles: python-control's ``c2d`` (the plant's pulse transfer function,
independent of symstab's residues and interval matrix exponential) with the
environment's polynomials written out here and numpy's eigenvalues of the
companion matrix (the closed-loop poles); the line engine's nominal stable
intervals for a box of zero width.
"""

import numpy as np
import pytest
import sympy as sp

import symstab
from symstab.symbolic.discretize import interval_zoh

control = pytest.importorskip("control")

PAPER = "examples/loops/paper.toml"


@pytest.fixture(scope="module")
def paper():
    return symstab.load_loop(PAPER)


@pytest.fixture(scope="module")
def nominal_area_d10(paper):
    """The paper's nominal stable area at d = 10, M = 0 by scipy's quad (two tests read it)."""
    return _nominal_area(paper, paper.region("B", "K", d=10, M=0.0).x_range, d=10, M=0.0)


def _in_w(coefficients):
    """Coefficients in z (highest first) -> in w = z - 1 (highest first), exactly."""
    w = sp.Symbol("w")
    n = len(coefficients) - 1
    expr = sum(sp.Rational(float(c)) * (w + 1) ** (n - i) for i, c in enumerate(coefficients))
    return [float(c) for c in sp.Poly(sp.expand(expr), w).all_coeffs()]


def _c2d(num, den, T):
    """python-control's ZOH pulse transfer function, monic denominator, highest first."""
    sys = control.c2d(control.tf(num, den), T, "zoh")
    n, d = (np.atleast_1d(np.squeeze(np.asarray(c, dtype=float))) for c in (sys.num[0][0],
                                                                            sys.den[0][0]))
    n, d = n / d[0], d / d[0]
    return np.concatenate([np.zeros(len(d) - len(n)), n]), d


@pytest.mark.parametrize("num, den, box", [
    # The paper's plant, m and b +-20 % / +-50 %.
    ([1.0], lambda m, b: [m, b, 0.0], {"m": (0.0102, 0.0154), "b": (0.0162, 0.0486)}),
    # A spring on the mass: complex poles.
    ([1.0], lambda m, b: [m, b, 40.0], {"m": (0.01, 0.02), "b": (0.01, 0.05)}),
    # An actuator lag and a zero: third order.
    (lambda m, b: [1.0, 30.0], lambda m, b: list(np.polymul([1.0 / m, 1.0], [m, b, 0.0])),
     {"m": (0.01, 0.02), "b": (0.02, 0.04)}),
])
def test_interval_zoh_encloses_python_control(num, den, box):
    from mpmath import iv

    T = 1e-3
    rng = np.random.default_rng(3)

    def coefficients(f, m, b):
        return f(m, b) if callable(f) else f

    iv.dps = 30
    try:
        (m0, m1), (b0, b1) = box["m"], box["b"]
        # The plant's coefficients as intervals: each is monotone in m and b here,
        # so its values at the corners bound it.
        corners = [(m, b) for m in (m0, m1) for b in (b0, b1)]
        num_iv = [iv.mpf([min(c), max(c)])
                  for c in zip(*[coefficients(num, *p) for p in corners], strict=True)]
        den_iv = [iv.mpf([min(c), max(c)])
                  for c in zip(*[coefficients(den, *p) for p in corners], strict=True)]
        p_n, p_d = interval_zoh(num_iv, den_iv, iv.mpf(T))
    finally:
        iv.dps = 15
    for _ in range(20):
        m, b = rng.uniform(m0, m1), rng.uniform(b0, b1)
        n, d = _c2d(coefficients(num, m, b), coefficients(den, m, b), T)
        n_w, d_w = _in_w(n), _in_w(d)
        n_w = [0.0] * (len(p_n) - len(n_w)) + n_w
        scales = [np.abs(n).max()] * len(n_w) + [np.abs(d).max()] * len(d_w)
        for value, enclosure, scale in zip(n_w + d_w, p_n + p_d, scales, strict=True):
            width = float(enclosure.b) - float(enclosure.a)
            # python-control's coefficients in z are good to about 1e-13 of the
            # largest (their sums in w too: P_d(1) = 0 comes out as 1e-16).
            slack = 1e-10 * abs(value) + 1e-13 * scale
            assert float(enclosure.a) - slack <= value <= float(enclosure.b) + slack, (
                value, enclosure, width)


def _closed_loop_radius(m, b, T, d, K, B, M=0.0):
    """Largest pole modulus of the paper's loop at (K, B): python-control's plant, numpy's eigenvalues.

    chi = z**d Ve_d P_d + Ve_n P_n with VE = K + B (z - 1)/(T z) + M (z - 1)**2/(T z)**2,
    Ve_n = K T**2 z**2 + B T z (z - 1) + M (z - 1)**2 and Ve_d = T**2 z**2.
    """
    n, p = _c2d([1.0], [m, b, 0.0], T)
    K, B = np.atleast_1d(K), np.atleast_1d(B)
    ve_n = (K[:, None] * T**2 * np.array([1.0, 0, 0]) + B[:, None] * T * np.array([1.0, -1, 0])
            + M * np.array([1.0, -2, 1]))
    direct = np.stack([np.convolve(row, n) for row in ve_n])
    delayed = np.concatenate([T**2 * p, np.zeros(d + 2)])
    chi = np.zeros((len(K), len(delayed)))
    chi += delayed
    chi[:, -direct.shape[1]:] += direct
    chi = chi / chi[:, :1]
    size = chi.shape[1] - 1
    companion = np.zeros((len(K), size, size))
    companion[:, 0, :] = -chi[:, 1:]
    companion[:, np.arange(1, size), np.arange(size - 1)] = 1.0
    return np.abs(np.linalg.eigvals(companion)).max(axis=1)


def _points_in(region, n, rng):
    """``n`` points of the robust set: in its trapezoids (weighted by area), a tenth next to their
    top and bottom sides (1e-9 of the height inside: the sides themselves are not certified)."""
    bands = np.array([(region.edges[i], region.edges[i + 1], *band)
                      for i, bands in enumerate(region.intervals) for band in bands])
    areas = (bands[:, 1] - bands[:, 0]) * ((bands[:, 3] - bands[:, 2]) + (bands[:, 5] - bands[:, 4]))
    r = bands[rng.choice(len(bands), size=n, p=areas / areas.sum())]
    f = rng.random(n)
    x = r[:, 0] + f * (r[:, 1] - r[:, 0])
    lo, hi = r[:, 2] + f * (r[:, 4] - r[:, 2]), r[:, 3] + f * (r[:, 5] - r[:, 3])
    t = rng.random(n)
    edge = rng.random(n) < 0.1
    t[edge] = np.where(rng.random(edge.sum()) < 0.5, 1e-9, 1 - 1e-9)
    return x, lo + t * (hi - lo)


def test_robust_points_are_stable_at_every_value_of_the_box(paper):
    """The acceptance: 2 000 robust points, each stable at 20 values of the box (its corners and
    16 inside).

    (10 000 points until issue 41: 5x the CPU; a set too large by a part of the box shows at
    the points next to its sides, a tenth of them.  100 values of the box until issue 41: with
    the coefficients' radii cut to a quarter and the candidates looked for at the centre only,
    the set grew by a sixth and the 20 values still saw 25 unstable pairs, at two corners.)
    """
    box = {"m": (0.0115, 0.0141), "b": (0.0162, 0.0648)}
    region = paper.robust_region("B", "K", uncertain=box, strips=32, d=10, M=0.0)
    assert not region.empty and 0 < region.area < region.nominal.area
    assert region.contains(*_points_in(region, 200, np.random.default_rng(0))).all()
    rng = np.random.default_rng(1)
    x, y = _points_in(region, 2_000, rng)
    values = [(m, b) for m in box["m"] for b in box["b"]]
    values += list(zip(rng.uniform(*box["m"], 16), rng.uniform(*box["b"], 16), strict=True))
    worst = 0.0
    for m, b in values:
        worst = max(worst, float(_closed_loop_radius(m, b, 1e-3, 10, y, x).max()))
    assert worst < 1.0
    # Not vacuous: the nominal set holds points unstable at a corner of the box.
    nx, ny = np.meshgrid(np.linspace(*region.nominal.x_range, 60), np.linspace(
        *region.nominal.y_range, 60))
    inside = region.nominal.contains(nx, ny)
    radius = _closed_loop_radius(box["m"][0], box["b"][0], 1e-3, 10, ny[inside], nx[inside])
    assert (radius > 1).any()
    assert not region.contains(nx[inside][radius > 1], ny[inside][radius > 1]).any()


def test_robust_over_a_range_of_delays(paper):
    """Uncertain delay and damping: the points are stable at every delay of the range.

    (At 4 values of b, 6 until issue 41: the last delay left uncertified, or the coefficients'
    radii cut to a tenth with the candidates looked for at the centre only, still fail.)
    """
    box = {"b": (0.02, 0.045), "d": (8, 12)}
    region = paper.robust_region("B", "K", uncertain=box, strips=24, M=0.0, m=0.0128)
    assert region.uncertain["d"] == (8, 12)
    rng = np.random.default_rng(2)
    x, y = _points_in(region, 2_000, rng)
    for d in range(8, 13):
        for b in (0.02, 0.045, *rng.uniform(0.02, 0.045, 2)):
            assert _closed_loop_radius(0.0128, b, 1e-3, d, y, x).max() < 1.0
    # Smaller than the set of any one delay of the range.
    for d in (8, 12):
        assert region.area < paper.robust_region("B", "K", uncertain={"b": (0.02, 0.045)},
                                                 strips=24, M=0.0, m=0.0128, d=d).area + 1e-12


@pytest.mark.parametrize("path, d, lines", [
    (PAPER, 10, (-0.02, 0.0, 0.5, 1.0)),
    ("examples/loops/lowpass_velocity.toml", 40, (0.0, 0.05, 0.1)),
])
def test_a_box_of_zero_width_gives_the_nominal_set(path, d, lines):
    """On a line (a strip of zero width) the certified intervals are the line engine's to 1e-6."""
    loop = symstab.load_loop(path)
    b = loop.defaults["b"]
    nominal_set = loop.region("B", "K", d=d)
    height = nominal_set.limits().y_max
    for B in lines:
        found = loop.robust_region("B", "K", uncertain={"b": (b, b)}, x_range=(B, B), rtol=1e-7,
                                   d=d)
        nominal = loop.stable_intervals("K", B=B, d=d)
        robust = found.intervals_at(B)
        assert nominal and robust
        assert len(nominal) == 1
        lo, hi = nominal[0]
        assert abs(robust[0][0] - max(lo, 0.0)) <= 1e-6 * height
        assert abs(robust[-1][1] - hi) <= 1e-6 * height
        # Whatever did not close inside is a sliver.
        gaps = sum(b1 - a1 for (_, a1), (b1, _) in zip(robust[:-1], robust[1:], strict=True))
        assert gaps <= 1e-6 * height


def _nominal_area(loop, x_range, **values):
    """The nominal stable set's area: its stable intervals' lengths integrated (scipy's adaptive
    Gauss-Kronrod cubature, which asks for the lengths at many lines at once: the line engine
    takes them together; quad took one line per call, 6x the CPU, until issue 41)."""
    from scipy.integrate import cubature

    def length(B):
        spans = loop.stable_intervals("K", B=B[:, 0], **values)
        return np.array([sum(hi - lo for lo, hi in line) for line in spans])

    found = cubature(length, [x_range[0]], [x_range[1]], rule="gk21", rtol=1e-12, atol=1e-10,
                     max_subdivisions=10_000)
    area, error = float(found.estimate), float(found.error)
    assert found.status == "converged" and error < 1e-9 * area
    return area


def test_a_box_of_zero_width_gives_the_nominal_set_in_the_plane(paper, nominal_area_d10):
    """The acceptance: with a box of zero width the robust set is the nominal one to 1e-6 (area,
    and the ends of y at 200 random x, as fractions of the set's area and height)."""
    region = paper.robust_region("B", "K", uncertain={"b": (0.0324, 0.0324)}, strips=4096,
                                 rtol=1e-7, d=10, M=0.0)
    assert region.nominal.x_range == paper.region("B", "K", d=10, M=0.0).x_range
    nominal = nominal_area_d10
    assert nominal - 1e-6 * nominal < region.area <= nominal
    height = region.limits().y_max
    rng = np.random.default_rng(7)
    xs = rng.uniform(region.edges[0], region.edges[-1], 200)
    for B, found in zip(xs, paper.stable_intervals("K", B=xs, d=10, M=0.0), strict=True):
        robust = region.intervals_at(B)
        assert len(robust) == len(found) == 1
        assert abs(robust[0][0] - found[0][0]) <= 1e-6 * height
        assert abs(robust[0][1] - found[0][1]) <= 1e-6 * height


def test_a_box_of_zero_width_converges_to_the_nominal_area(paper, nominal_area_d10):
    """With strips narrowing, the area grows to the nominal set's, second order (the trapezoids'
    sides are chords of the boundary)."""
    nominal = nominal_area_d10
    losses = [nominal - paper.robust_region("B", "K", uncertain={"b": (0.0324, 0.0324)}, strips=n,
                                            d=10, M=0.0).area for n in (16, 64, 256)]
    assert 0 < losses[2] < losses[1] < losses[0]
    # A quarter of the strips' width: a sixteenth of the loss, give or take.
    assert losses[1] < losses[0] / 8 and losses[2] < losses[1] / 8
    assert losses[2] < 1e-4 * nominal


def test_a_box_where_the_set_vanishes(paper):
    region = paper.robust_region("B", "K", uncertain={"M": (0.0, 0.019)}, d=10)
    assert region.empty and region.area == 0 and region.polygons == ()
    assert "no common point" in region.reason and "M in [0, 0.019]" in region.reason
    limits = paper.limits("B", "K", uncertain={"M": (0.0, 0.019)}, d=10)
    assert limits.empty and limits.reason == region.reason
    # A box whose centre is unstable.
    assert "centre is empty" in paper.robust_region("B", "K", uncertain={"M": (0.0, 0.05)},
                                                    d=10).reason


def test_robust_limits_and_polygons(paper):
    region = paper.robust_region("B", "K", uncertain={"b": (0.0162, 0.0648)}, strips=32, d=10,
                                 M=0.0)
    limits = paper.limits("B", "K", uncertain={"b": (0.0162, 0.0648)}, strips=32, d=10, M=0.0)
    assert limits.region.intervals == region.intervals and limits.area == region.area
    # K_max grows with b: the robust one is at most the smallest b's.
    assert limits.y_max <= paper.limits("B", "K", b=0.0162, d=10, M=0.0).y_max
    shoelace = sum(0.5 * abs(np.dot(p[:, 0], np.roll(p[:, 1], -1))
                             - np.dot(p[:, 1], np.roll(p[:, 0], -1))) for p in region.polygons)
    assert shoelace == pytest.approx(region.area, rel=1e-12)
    assert limits.intervals_at(limits.x_at_y_max)[-1][1] == pytest.approx(limits.y_max)


@pytest.mark.parametrize("uncertain, strips, rtol, match", [
    ({"K": (1.0, 2.0)}, 8, 1e-6, "axis"),
    ({"q": (1.0, 2.0)}, 8, 1e-6, "not a parameter"),
    ({"b": (0.05, 0.01)}, 8, 1e-6, "low <= high"),
    ({"d": (12, 8)}, 8, 1e-6, "low <= high"),
    ({"b": (0.01, 0.05)}, 0, 1e-6, "strips"),
    ({"b": (0.01, 0.05)}, 8, 0.5, "rtol"),
    ({"T": (0.0, 1e-3)}, 8, 1e-6, "period"),
])
def test_bad_input_is_refused_by_name(paper, uncertain, strips, rtol, match):
    with pytest.raises((TypeError, ValueError), match=match):
        paper.robust_region("B", "K", uncertain=uncertain, strips=strips, rtol=rtol, d=10)



def test_the_robust_region_has_its_own_entry_and_region_uncertain_is_deprecated(paper):
    """``robust_region(loop, ...)`` is the entry, ``Loop.robust_region`` its method; the old
    ``Loop.region(uncertain=...)`` still answers, one release, with a DeprecationWarning."""
    from symstab.numeric.analysis.robust import robust_region
    from symstab.numeric.engine.results import RobustRegion

    box = {"b": (0.0162, 0.0648)}
    found = paper.robust_region("B", "K", uncertain=box, strips=4, d=10, M=0.0)
    assert isinstance(found, RobustRegion)
    assert robust_region(paper, "B", "K", uncertain=box, strips=4, d=10, M=0.0).intervals \
        == found.intervals
    with pytest.warns(DeprecationWarning, match="use Loop.robust_region"):
        old = paper.region("B", "K", uncertain=box, strips=4, d=10, M=0.0)
    assert isinstance(old, RobustRegion) and old.intervals == found.intervals

def test_uncertain_must_be_a_box(paper):
    with pytest.raises(TypeError, match="uncertain"):
        paper.robust_region("B", "K", uncertain={"b": 0.03}, d=10)
    with pytest.raises(TypeError, match="uncertain"):
        paper.robust_region("B", "K", uncertain={}, d=10)


@pytest.mark.parametrize("path, box, d", [
    (PAPER, {"m": (0.0115, 0.0141), "b": (0.0162, 0.0648)}, 10),
    ("examples/loops/lowpass_velocity.toml", {"b": (0.02, 0.045), "f_c": (30.0, 70.0)}, 40),
])
def test_the_disks_hold_the_polynomial(path, box, d):
    """Each part of chi at any theta of the interval and any value of the box lies in its disk.

    The part's true value from python-control's plant and the loop's
    environment polynomials; the disk is the value and slope at the middle
    (midpoint coefficients) with the second-derivative bound, the
    coefficients' radii and the rounding.
    """
    from symstab.numeric.analysis.robust import _Enclosures, _parts_on_arc

    loop = symstab.load_loop(path)
    fixed = {k: v for k, v in loop.defaults.items() if k not in box and k not in ("B", "K", "d")}
    enclosures = _Enclosures(loop, "B", "K", box, fixed)
    k = loop.environment_delay
    shift = d + k
    rng = np.random.default_rng(5)
    theta_c = np.concatenate([rng.uniform(0, np.pi, 40), [1e-4, np.pi - 1e-4]])
    h = theta_c * 0 + 0.01
    value, slope, second, coefficient, rounding, _ = _parts_on_arc(
        enclosures, shift, theta_c, h, np.zeros(len(theta_c), dtype=np.int64))
    symbols = {str(s): s for s in loop.symbols.values()}
    ve_n, ve_d = loop.environment_parts
    worst = 0.0
    for _ in range(12):
        q = {name: rng.uniform(lo, hi) for name, (lo, hi) in box.items()}
        at = {**fixed, **q}
        n, p = _c2d([1.0], [at["m"], at["b"], 0.0], at["T"])
        sub = {symbols[name]: v for name, v in at.items()}
        parts = []
        for slope_of in (None, "B", "K"):
            def coefficients(c, slope_of=slope_of, sub=sub):
                c = [sp.diff(e, symbols[slope_of]) if slope_of else e for e in c]
                return np.array([float(e.subs(sub).subs({symbols["B"]: 0, symbols["K"]: 0}))
                                 for e in c])
            delayed = np.convolve(coefficients(ve_d)[:len(ve_d) - k], p)
            direct = np.convolve(coefficients(ve_n), n)
            parts.append((delayed, direct))
        u = rng.uniform(-1, 1, len(theta_c))
        theta = theta_c + u * h
        z = np.exp(1j * theta)
        for j, (delayed, direct) in enumerate(parts):
            true = z**shift * np.polyval(delayed, z) + np.polyval(direct, z)
            near = value[:, j] + slope[:, j] * (theta - theta_c)
            bound = 0.5 * (theta - theta_c) ** 2 * second[:, j] + coefficient[:, j] + rounding[:, j]
            scale = np.abs(delayed).sum() + np.abs(direct).sum()
            excess = np.abs(true - near) - bound
            # python-control's coefficients are good to about 1e-13 of the largest.
            assert (excess <= 1e-12 * scale).all(), (j, excess.max() / scale)
            worst = max(worst, float((np.abs(true - near) / np.maximum(bound, 1e-300)).max()))
    # The bound is not vacuous: some points use a good part of it.
    assert worst > 0.05


def test_an_uncertain_period(paper):
    """T in a box (the plant's and the environment's): the points are stable at its ends and inside."""
    # 4 strips (8 until issue 41: 2.5x the CPU, in mpmath's interval exponential of T).
    region = paper.robust_region("B", "K", uncertain={"T": (0.8e-3, 1.2e-3)}, strips=4, d=10, M=0.0)
    assert not region.empty
    x, y = _points_in(region, 500, np.random.default_rng(4))
    for T in (0.8e-3, 1.0e-3, 1.2e-3, 0.93e-3):
        assert _closed_loop_radius(0.0128, 0.0324, T, 10, y, x).max() < 1.0


def test_a_box_where_the_coefficients_are_unbounded_is_refused_by_name(paper):
    # The box's lower corner is a negative mass: said by a warning, then refused.
    with pytest.warns(symstab.NonPhysicalPlantWarning, match="m = -0.01"), \
            pytest.raises(ValueError, match=r"uncertain: m in \[-0.01, 0.02\]: the leading"):
        paper.robust_region("B", "K", uncertain={"m": (-0.01, 0.02)}, strips=8, d=10)


def test_the_failing_set_holds_every_zero_and_every_failing_point():
    """``_failing`` against brute force: the zero of P + y Y when P and Y are parallel (where
    B**2 - 4 A c cancels to noise), and random points with |P + y Y| <= a + b |y|."""
    from symstab.numeric.analysis.robust import _failing

    rng = np.random.default_rng(7)
    n = 20_000
    Y = rng.normal(size=n) + 1j * rng.normal(size=n)
    zero = rng.uniform(-2, 2, n)
    P = -zero * Y
    for ratio in (3e-8, 1e-8, 1e-12):
        inside = np.zeros(n, dtype=bool)
        for lo, hi in _failing(P, Y, ratio * np.abs(P) + 1e-300, np.zeros(n)):
            inside |= (lo <= zero) & (zero <= hi)
        assert inside.all(), ratio
    P = rng.normal(size=n) + 1j * rng.normal(size=n)
    a, b = rng.uniform(0, 1, n), rng.uniform(0, 2, n) * np.abs(Y)
    y = rng.uniform(-5, 5, n)
    fails = np.abs(P + y * Y) <= a + b * np.abs(y)
    inside = np.zeros(n, dtype=bool)
    for lo, hi in _failing(P, Y, a, b):
        inside |= (lo <= y) & (y <= hi)
    assert fails.any() and (inside | ~fails).all()


@pytest.mark.parametrize("path, box, d, h, narrow_width", [
    (PAPER, {"m": (0.0115, 0.0141), "b": (0.0162, 0.0648)}, 10, 1e-2, 20.0),
    (PAPER, {"b": (0.0324, 0.0325)}, 10, 1e-4, 0.05),
    (PAPER, {"b": (0.0324, 0.0324)}, 10, 3e-3, 1.0),
    ("examples/loops/lowpass_velocity.toml", {"b": (0.02, 0.045), "f_c": (30.0, 70.0)}, 40, 1e-3,
     20.0),
])
def test_every_zero_of_a_cell_is_in_its_set(path, box, d, h, narrow_width):
    """At any theta of the interval and any value of the box, the point of the plane where chi
    vanishes (python-control's plant, the loop's environment, a 2 x 2 solve) has its t on a
    trapezoid around it inside the set the cell returns (capsule and strip together)."""
    from symstab.numeric.analysis.robust import _Enclosures, _excluded, _Pieces

    loop = symstab.load_loop(path)
    fixed = {k: v for k, v in loop.defaults.items() if k not in box and k not in ("B", "K", "d")}
    enclosures = _Enclosures(loop, "B", "K", box, fixed)
    k = loop.environment_delay
    shift = d + k
    symbols = {str(s): s for s in loop.symbols.values()}
    ve_n, ve_d = loop.environment_parts
    rng = np.random.default_rng(11)
    narrow = checked = 0
    for _ in range(10):
        q = {name: rng.uniform(lo, hi) for name, (lo, hi) in box.items()}
        at = {**fixed, **q}
        n, p = _c2d([1.0], [at["m"], at["b"], 0.0], at["T"])
        sub = {symbols[name]: v for name, v in at.items()}
        parts, scale = [], 0.0
        for slope_of in (None, "B", "K"):
            def coefficients(c, slope_of=slope_of, sub=sub):
                c = [sp.diff(e, symbols[slope_of]) if slope_of else e for e in c]
                return [float(e.subs(sub).subs({symbols["B"]: 0, symbols["K"]: 0})) for e in c]
            delayed = np.convolve(coefficients(ve_d)[:len(ve_d) - k], p)
            direct = np.convolve(coefficients(ve_n), n)
            parts.append((delayed, direct))
            scale = max(scale, np.abs(delayed).sum() + np.abs(direct).sum())
        theta_c = rng.uniform(0, np.pi, 60)
        theta = theta_c + rng.uniform(-1, 1, 60) * h
        z = np.exp(1j * theta)
        a0, ax, ay = (z**shift * np.polyval(dl, z) + np.polyval(dr, z) for dl, dr in parts)
        det = ax.real * ay.imag - ax.imag * ay.real
        x = (a0.imag * ay.real - a0.real * ay.imag) / det
        y = (a0.real * ax.imag - a0.imag * ax.real) / det
        assert np.abs(a0 + x * ax + y * ay).max() < 1e-9 * scale * (1 + np.abs(x) + np.abs(y)).max()
        # How far python-control's own rounding (1e-12 of the coefficients, as above) can move the
        # point: its error over the map's smallest singular value.
        sigma = np.array([np.linalg.svd([[u.real, v.real], [u.imag, v.imag]], compute_uv=False)[-1]
                          for u, v in zip(ax, ay, strict=True)])
        moved = 1e-12 * scale * (1 + np.abs(x) + np.abs(y)) / sigma
        # A trapezoid around each point: random slopes, the point at a random t.
        wx = 0.02 * (1 + np.abs(x))
        height = 0.5 * (1 + np.abs(y))
        f, t_true = rng.uniform(0.1, 0.9, 60), rng.uniform(0.05, 0.95, 60)
        x0 = x - f * wx
        lo_slope, height_slope = rng.normal(0, 1, 60) * height / wx, rng.uniform(-0.5, 0.5, 60) * height / wx
        d_at = height
        lo_at = y - t_true * d_at
        lo0, d0 = lo_at - lo_slope * f * wx, d_at - height_slope * f * wx
        x1 = x0 + wx
        piece = _Pieces(x0, x1, lo0, lo0 + d0, lo0 + lo_slope * wx, lo0 + lo_slope * wx + d0
                        + height_slope * wx)
        pieces, _, _, _ = _excluded(enclosures, shift, theta_c, theta_c * 0 + h,
                                    np.zeros(60, dtype=np.int64), piece)
        slack = moved * (1 + np.abs(lo_slope) + np.abs(height_slope)) / np.minimum(
            piece.hi0 - piece.lo0, piece.hi1 - piece.lo1) + 1e-12
        inside = np.zeros(60, dtype=bool)
        width = np.zeros(60)
        for lo, hi in pieces:
            inside |= (lo - slack <= t_true) & (t_true <= hi + slack)
            width += np.maximum(np.minimum(hi, 100.0) - np.maximum(lo, -100.0), 0.0)
        keep = np.isfinite(x) & np.isfinite(y) & (d0 > 0) & (piece.hi1 > piece.lo1)
        assert inside[keep].all(), np.flatnonzero(keep & ~inside)
        checked += keep.sum()
        narrow += (keep & (width < narrow_width)).sum()
    # Not vacuous: many cells exclude all but a band a few trapezoids wide of the t in [-100,
    # 100] (with a narrow box and theta-interval, locate the zero to a few per cent of one).
    assert checked > 300 and narrow > checked / 4


@pytest.mark.parametrize("uncertain, values, match", [
    ({"Td": (-0.001, 0.002)}, {}, r"uncertain\['Td'\] bounds must be .* >= 0"),
    ({"Td": (0.003, 0.002)}, {}, r"uncertain\['Td'\]: \(low, high\) must have low <= high"),
    ({"Td": (float("nan"), 0.002)}, {}, r"uncertain\['Td'\] bounds"),
    ({"Td": (0.001, 1e6)}, {}, "SYMSTAB_MAX_DELAY"),
    ({"d": (1.5, 1e9)}, {}, "SYMSTAB_MAX_DELAY"),
    ({"d": (1, 2), "Td": (0.001, 0.002)}, {}, "give the delay range once"),
    ({"Td": (0.001, 0.002), "T": (0.9e-3, 1.1e-3)}, {}, "over a fixed period"),
    ({"T": (0.9e-3, 1.1e-3)}, {"Td": 0.0025}, "over a fixed period"),
])
def test_a_bad_delay_range_is_refused_by_name(paper, uncertain, values, match):
    """A delay range (seconds or samples) is checked before any work: negative, NaN, reversed,
    beyond the delay limit, given twice, or in seconds over an uncertain period (its fraction
    of a period would vary over the box)."""
    with pytest.raises(ValueError, match=match):
        paper.robust_region("B", "K", uncertain=uncertain, strips=2, **values)


def _n_eps_oracle(num, den, T, eps, z):
    """``N_eps(z) = P_eps(z) z det(z I - Phi)`` from the state space (tests/oracles.py's
    realisation and Van Loan's block exponential), not symstab's cofactors."""
    from oracles import _held_input_integral, _realisation

    A, B, C, _ = _realisation(num, den)
    Phi, _ = _held_input_integral(A, B, T)
    late, gamma0 = _held_input_integral(A, B, (1 - eps) * T)
    gamma1 = late @ _held_input_integral(A, B, eps * T)[1]
    n = len(A)
    out = []
    for zk in z:
        resolvent = np.linalg.solve(zk * np.eye(n) - Phi, gamma0 + gamma1 / zk)
        out.append((C @ resolvent).item() * zk * np.linalg.det(zk * np.eye(n) - Phi))
    return np.array(out)


@pytest.mark.parametrize("num, den", [
    ([1.0], [0.0128, 0.0324, 0.0]),                                    # the paper's plant
    ([1.0], [0.0128, 0.0324, 40.0]),                                   # complex poles
    ([1.0], list(np.polymul([0.0128, 0.0324, 0.0], [0.00016, 1.0]))),  # an actuator lag
])
def test_interval_fractional_zoh_encloses_the_state_space(num, den):
    """Over an interval of eps, N_eps's enclosure holds the state-space N_eps at every eps of it
    (on the unit circle, off its integrator's z = 1, and at 1 +- 0.5), and z P_d is interval_zoh's P_d times z."""
    from mpmath import iv

    from symstab.symbolic.discretize import interval_fractional_zoh

    T = 1e-3
    z = np.concatenate([np.exp(1j * np.linspace(0.05, np.pi, 9)), [0.5, 1.5]])
    w = z - 1.0
    iv.dps = 30
    try:
        at = interval_fractional_zoh([iv.mpf(c) for c in num], [iv.mpf(c) for c in den],
                                     iv.mpf(T))
        p_n, p_d = interval_zoh([iv.mpf(c) for c in num], [iv.mpf(c) for c in den], iv.mpf(T))
        checked = 0
        for lo, hi in ((0.0, 1.0), (0.2, 0.3), (0.7, 0.7001), (0.999, 1.0)):
            n_eps, z_p_d = at(iv.mpf([lo, hi]))
            mid = np.array([float(c.mid) for c in n_eps])
            rad = np.array([float(c.delta) / 2 for c in n_eps])
            powers = np.abs(w)[:, None] ** np.arange(len(mid) - 1, -1, -1)
            reach = powers @ rad
            for eps in np.linspace(lo, hi, 5):
                true = _n_eps_oracle(num, den, T, eps, z)
                error = np.abs(np.polyval(mid, w) - true)
                assert (error <= reach + 1e-9 * np.abs(true).max()).all(), (lo, hi, eps)
                checked += 1
            # Not vacuous: over a narrow interval each coefficient's radius is within a few
            # times its spread over the interval (the oracle's coefficients in w, by solving
            # at four real w; the cofactors' sums add the radii of terms that move together).
            if hi - lo <= 0.1:
                nodes = np.array([-0.5, 0.5, 1.0, 2.0])[:len(mid)]
                vandermonde = nodes[:, None] ** np.arange(len(mid) - 1, -1, -1)
                coefficients = np.array([np.linalg.solve(vandermonde, _n_eps_oracle(
                    num, den, T, e, nodes + 1.0).real) for e in np.linspace(lo, hi, 9)])
                spread = np.ptp(coefficients, axis=0) / 2
                assert (rad <= 8 * spread + 1e-9 * np.abs(mid).max()).all(), rad / spread
            shifted = [iv.mpf(0)] * 1 + list(p_d)
            for a, b in zip(z_p_d, [x + y for x, y in zip(list(p_d) + [iv.mpf(0)], shifted,
                                                           strict=True)], strict=True):
                assert abs(float(a.mid) - float(b.mid)) <= 1e-25
        # eps = 1 is one more whole sample: N_1 = P_n.
        n_one, _ = at(iv.mpf(1))
        assert all(abs(float(a.mid) - float(b.mid)) <= 1e-25 for a, b in zip(
            n_one, p_n, strict=True))
    finally:
        iv.dps = 15
    assert checked == 20


@pytest.fixture(scope="module")
def over_delays(paper):
    """The paper's loop robust over Td in [1.5, 2.5] ms (a continuum: two fractional pieces)."""
    return paper.robust_region("B", "K", uncertain={"Td": (0.0015, 0.0025)}, strips=8,
                               rtol=1e-4, M=0.0)


def _radii(loop, values, points, delays):
    """The spectral radius at each point and delay (samples): tests/oracles.py's state-space
    closed loop with the fraction of a period inside the period (Van Loan's exponential)."""
    from oracles import fractional_delay_oracle

    x, y = loop.plane
    points = list(points)
    out = np.zeros((len(points), len(delays)))
    for i, (px, py) in enumerate(points):
        at = fractional_delay_oracle(loop, {**values, x: px, y: py})
        out[i] = [at(tau)[0] for tau in delays]
    return out


@pytest.mark.parametrize("path, uncertain, window", [
    (PAPER, {"Td": (0.0015, 0.0025)}, (1.5, 2.5)),
    ("examples/loops/lowpass_velocity.toml", {"d": (1.25, 2.5)}, (1.25, 2.5)),
])
def test_robust_over_a_continuum_of_delays(path, uncertain, window, paper, over_delays):
    """Every robust point is stable at 201 delays of the range, ends included (the state-space
    oracle); just above the set at each strip's edges some delay of the range is unstable."""
    loop = paper if path == PAPER else symstab.load_loop(path)
    region = over_delays if path == PAPER else loop.robust_region(
        uncertain=uncertain, strips=4, rtol=1e-4)
    assert region.uncertain == uncertain and "d" not in region.at
    values = {**loop.defaults, **region.at}
    delays = np.linspace(*window, 201)
    rng = np.random.default_rng(5)
    x, y = _points_in(region, 16, rng)
    assert _radii(loop, values, zip(x, y, strict=True), delays).max() < 1.0
    # Outside: at a strip's left edge, 0.2 % above the highest robust or marginal band.
    above = []
    for i in range(len(region.edges) - 1):
        tops = [band[1] for band in region.intervals[i] + region.marginal[i]]
        if tops and max(tops) > 0:
            above.append((region.edges[i], max(tops) * 1.002))
    assert len(above) >= 3
    assert (_radii(loop, values, above, delays).max(axis=1) >= 1.0).all()


def test_robust_over_delays_is_inside_the_delay_range_set(paper, over_delays):
    """An inner approximation: at robust points, Loop.delay_range's constant set (stable at
    Td_min with an exact delay margin beyond the width) holds too; and the set is smaller than
    the stable set at the range's ends and at its whole delay."""
    x, y = _points_in(over_delays, 6, np.random.default_rng(7))
    for px, py in zip(x, y, strict=True):
        assert paper.delay_range(delay_range=(0.0015, 0.0025), B=px, K=py, M=0.0).constant
    for d in (1.5, 2, 2.5):
        assert over_delays.area < paper.region("B", "K", d=d, M=0.0).area


def test_a_fractional_delay_is_one_piece_of_zero_width(paper):
    """A fractional nominal delay (d = 2.5, or Td = 2.5 ms) is certified as itself; a range of
    one delay is that delay."""
    box = {"b": (0.03, 0.0325)}
    samples = paper.robust_region("B", "K", uncertain=box, strips=2, d=2.5, M=0.0)
    seconds = paper.robust_region("B", "K", uncertain=box, strips=2, Td=0.0025, M=0.0)
    ranged = paper.robust_region("B", "K", uncertain={**box, "d": (2.5, 2.5)}, strips=2, M=0.0)
    assert samples.intervals == seconds.intervals == ranged.intervals
    assert samples.at["d"] == 2.5 and "d" not in samples.uncertain
    x, y = _points_in(samples, 20, np.random.default_rng(3))
    for b in box["b"]:
        assert _radii(paper, {**paper.defaults, "M": 0.0, "b": b}, zip(x, y, strict=True),
                      [2.5]).max() < 1.0


def test_a_delay_in_seconds_of_whole_samples_is_that_delay(paper):
    """Td = 10 ms at T = 1 ms is d = 10: the same robust set."""
    box = {"b": (0.03, 0.0325)}
    seconds = paper.robust_region("B", "K", uncertain=box, strips=2, Td=0.010, M=0.0)
    samples = paper.robust_region("B", "K", uncertain=box, strips=2, d=10, M=0.0)
    assert seconds.intervals == samples.intervals and seconds.area == samples.area
