"""How far from unstable: the margins of a loop at a stable point.

For a point of a :class:`symstab.Loop` the characteristic polynomial is
``chi(z) = z**s D(z) + N(z)`` (:meth:`symstab.Loop.polynomial`: ``D`` the
environment's and the sampled plant's denominators, ``N`` their
numerators, ``s`` the loop delay ``d``), so the loop's open loop is
``L = VE z**-d P = N / (z**s D)`` and the closed-loop poles are the roots
of ``1 + L``.  :func:`margins` (:meth:`symstab.Loop.margins`) gives, at one stable point:

* the **modulus margin** ``min |1 + L(exp(j theta))|`` over ``theta`` in
  [0, pi], the distance of the Nyquist curve from -1, certified
  (:func:`symstab.numeric.engine.roots.circle_minimum`: a bracket of
  relative width ``rtol`` proved by bounds on the circle, not a grid
  minimum), with its frequency;
* the **gain margins**: at every phase crossover (``L`` real and negative,
  ``Im L = 0``) the factor ``-1 / L`` by which the loop gain can be
  multiplied before that crossing reaches -1 (below 1 for a crossing
  outside the unit disc: the gain may be reduced by that factor);
* the **phase margins**: at every gain crossover (``|L| = 1``) the angle
  ``180 deg + arg L``.  The gain crossovers are the roots of the cosine
  polynomial ``|N|**2 - |D|**2`` (independent of the delay), found as the
  roots of its Chebyshev series, all of them;
* the **parameter margins**: for each parameter named, the stable interval
  through the point along that parameter, the others fixed
  (:meth:`symstab.Loop.stable_intervals`), as distances and as factors;
* the **delay margin**, exact: the smallest added delay, in samples
  (fractional), at which a root reaches the circle, with that crossing's
  frequency (:func:`symstab.numeric.analysis.delays.delay_margin`, from
  the fractional-delay derivation);
* the **delay margin** in whole samples: the smallest number of samples
  ``k`` added to ``d`` at which the loop is no longer stable: the certified
  verdict of :meth:`symstab.Loop.classify` at ``d + k``, from the first
  ``k`` at which a root can have reached the circle (a gain crossover's
  phase margin used up by the delay's phase, ``k theta_c``; from 1 where
  ``|L(-1)| >= 1``) up to ``delay_limit``: what a controller that adds
  whole samples of computation can afford.

The phase crossovers are found by sign changes of ``Im(N conj(D) z**-s)``
on a grid of 32 points per period of its highest harmonic, each refined
by :func:`symstab.numeric.engine.search.bracketed_root`: two crossings
closer together than the grid's step (a tangency of the Nyquist curve to
the real axis) are not separated.
"""

import dataclasses
import math

import numpy as np

from ..._resources import chunk_slices, max_delay
from ..._validate import check_count, check_grid, check_real
from ..engine.polynomial import horner
from ..engine.results import html_table
from ..engine.roots import MARGINAL, STABLE, circle_minimum
from ..engine.search import bracketed_root
from ..loop.evaluation import FRACTION
from .delay_scan import STEPS_PER_SAMPLE, first_crossings

__all__ = ["NyquistCrossing", "ParameterMargin", "Margins", "margins", "MarginMap", "margin_map",
           "first_whole_delays"]

#: Points per period of the highest harmonic of the phase-crossover scan.
_SCAN_PER_HARMONIC = 32
_EPS = np.finfo(float).eps


@dataclasses.dataclass(frozen=True)
class NyquistCrossing:
    """A crossing of the Nyquist curve (of the real axis or the unit circle): its margin, where.

    Attributes
    ----------
    margin : float
        The gain factor (a gain margin) or the angle in degrees (a phase
        margin).
    theta : float
        The angle on the unit circle, rad/sample, in [0, pi].
    frequency : float
        ``theta / (2 pi T)``, Hz.
    """

    margin: float
    theta: float
    frequency: float


@dataclasses.dataclass(frozen=True)
class ParameterMargin:
    """The stable interval through a point along one parameter.

    Attributes
    ----------
    name : str
        The parameter.
    value : float
        Its value at the point.
    low, high : float
        The ends of the stable interval holding the value (``-inf``/``inf``
        when it is unbounded); at the ends the loop is unstable or marginal.
    """

    name: str
    value: float
    low: float
    high: float

    @property
    def below(self):
        """How far the parameter can decrease: ``value - low``."""
        return self.value - self.low

    @property
    def above(self):
        """How far the parameter can increase: ``high - value``."""
        return self.high - self.value

    @property
    def factors(self):
        """``(low / value, high / value)``: the interval as factors of the value (None at 0)."""
        if self.value == 0:
            return None
        ends = sorted((self.low / self.value, self.high / self.value))
        return ends[0], ends[1]


@dataclasses.dataclass(frozen=True)
class Margins:
    """The margins of a loop at a stable point (:func:`symstab.numeric.analysis.margins.margins`).

    Attributes
    ----------
    point : dict
        The parameters' values.
    T : float
        The sample period, s.
    modulus : float
        ``min |1 + L|`` on the circle (the value found; the true minimum is
        in ``[modulus_lower, modulus]``).
    modulus_lower : float
        The certified lower bound.
    modulus_theta, modulus_frequency : float
        Where it is, rad/sample and Hz.
    gain, phase : tuple of NyquistCrossing
        Every phase crossover's gain margin and every gain crossover's
        phase margin, by increasing frequency.
    parameters : tuple of ParameterMargin
        The parameter margins.
    delay : int or None
        The delay margin in whole samples (None: stable up to
        ``delay_limit`` samples more).
    delay_limit : int
        The added delays examined, 1 to ``delay_limit``.
    exact_delay : symstab.numeric.analysis.delays.DelayMargin or None
        The exact delay margin (its first switch) and its crossing
        frequency, up to ``delay_limit`` samples more.
    """

    point: dict
    T: float
    modulus: float
    modulus_lower: float
    modulus_theta: float
    modulus_frequency: float
    gain: tuple
    phase: tuple
    parameters: tuple
    delay: object
    delay_limit: int
    exact_delay: object = None

    @property
    def gain_margin(self):
        """The gain margin: the smallest factor above 1 of :attr:`gain` (inf: none)."""
        up = [c.margin for c in self.gain if c.margin > 1]
        return min(up) if up else math.inf

    @property
    def phase_margin(self):
        """The phase margin: the smallest magnitude of :attr:`phase`, degrees (inf: none)."""
        return min((abs(c.margin) for c in self.phase), default=math.inf)

    @property
    def delay_seconds(self):
        """The delay margin in seconds, ``delay T`` (None with :attr:`delay` None)."""
        return None if self.delay is None else self.delay * self.T

    def rows(self):
        """``(quantity, value, where)`` rows of the margins, for tables."""
        out = [("modulus margin min|1+L|", f"{self.modulus:.6g}",
                f"{self.modulus_frequency:.6g} Hz ({self.modulus_theta:.6g} rad/sample); "
                f"certified >= {self.modulus_lower:.10g}")]
        for c in self.gain:
            out.append(("gain margin", f"{c.margin:.6g}", f"{c.frequency:.6g} Hz"))
        for c in self.phase:
            out.append(("phase margin (deg)", f"{c.margin:.6g}", f"{c.frequency:.6g} Hz"))
        for p in self.parameters:
            out.append((f"{p.name} stable interval", f"[{p.low:.6g}, {p.high:.6g}]",
                        f"at {p.name} = {p.value:.6g}"))
        delay = ("none" if self.delay is None else
                 f"{self.delay} samples ({self.delay * self.T:.6g} s)")
        if self.delay is None and self.delay_limit == 0:
            delay = "not examined"
        out.append(("delay margin (whole samples)", delay, self.delay_note))
        if self.exact_delay is not None and self.exact_delay.margin is not None:
            found = self.exact_delay.switches[0]
            out.append(("delay margin (exact)",
                        f"{found.added:.9g} samples ({found.added_seconds:.6g} s)",
                        f"a root on the circle at d = {found.samples:.9g}, "
                        f"{found.frequency:.6g} Hz"))
        return out

    @property
    def delay_note(self):
        """What the delay margin says: unstable at which ``d``, or stable up to where examined."""
        if self.delay is not None:
            return f"unstable at d = {self.point['d'] + self.delay}"
        if self.delay_limit == 0:
            # d is SYMSTAB_MAX_DELAY already: no longer delay is evaluated.
            return "not examined: d is the largest delay accepted (SYMSTAB_MAX_DELAY)"
        return (f"stable up to {self.delay_limit} samples more (d = "
                f"{self.point['d'] + self.delay_limit})")

    def __repr__(self):
        width = max(len(r[0]) for r in self.rows())
        lines = [f"Margins at {point_text(self.point)}"]
        lines += [f"  {q:<{width}}  {v}  ({w})" for q, v, w in self.rows()]
        return "\n".join(lines)

    def _repr_html_(self):
        return html_table(f"Margins at {point_text(self.point)}",
                          [(q, f"{v} ({w})") for q, v, w in self.rows()])

    def as_dict(self):
        """The margins as plain numbers (JSON-ready)."""
        return {
            "point": dict(self.point), "T": self.T,
            "modulus": self.modulus, "modulus_lower": self.modulus_lower,
            "modulus_theta": self.modulus_theta, "modulus_frequency": self.modulus_frequency,
            "gain": [dataclasses.asdict(c) for c in self.gain],
            "phase": [dataclasses.asdict(c) for c in self.phase],
            "parameters": [dataclasses.asdict(p) for p in self.parameters],
            "delay": self.delay, "delay_seconds": self.delay_seconds,
            "delay_limit": self.delay_limit,
            "exact_delay": None if self.exact_delay is None else self.exact_delay.as_dict(),
        }


def point_text(point):
    """A point's values in one line (``K = 2, d = 40``), for the reprs of margins."""
    return ", ".join(f"{k} = {v:.6g}" if isinstance(v, float) else f"{k} = {v}"
                     for k, v in point.items())


def margins(loop, *, parameters=None, delay_limit=None, rtol=1e-9, **values):
    """The margins of a loop at a stable point: modulus, gain, phase, parameter and delay.

    Parameters
    ----------
    loop : symstab.Loop
        The loop.
    parameters : sequence of str, optional
        The parameters whose stable interval through the point is given
        (each in :meth:`symstab.Loop.affine_parameters`); default the
        loop's :attr:`~symstab.Loop.plane`, or none without one.
    delay_limit : int, optional
        The most samples added to ``d`` in the search for the delay margin
        (default ``max(100, 10 (d + 1))``, within ``SYMSTAB_MAX_DELAY``).
    rtol : float
        The relative width of the modulus margin's certified bracket.
    **values
        A single value of every parameter (or its default), ``d`` included.

    Returns
    -------
    Margins

    Raises
    ------
    ValueError
        At a point that is not stable (the margins of an unstable or
        marginal loop are not distances to instability), for an array of
        values, or a parameter that is not affine.

    Examples
    --------
    >>> from symstab import Loop
    >>> loop = Loop("1/(m*s**2 + b*s)", "K + B*(z - 1)/(T*z)", plane=("B", "K"),
    ...             values=dict(m=0.0128, b=0.0324, T=1e-3, d=0, K=100.0, B=1.0))
    >>> found = margins(loop)
    >>> round(found.modulus, 6), round(found.modulus_frequency, 3)
    (0.739598, 19.022)
    """
    point = stable_point(loop, values)
    chi = loop.polynomial(**point)
    T = float(point["T"])
    lower, upper, theta = (float(x) for x in circle_minimum(chi, rtol=check_real(
        "rtol", rtol, low=0.0, low_open=True, high=0.5, high_open=True)))
    delayed, direct = chi.delayed.reshape(-1), chi.direct.reshape(-1)
    limit = delay_limit_of(point["d"], delay_limit)
    phase = phase_crossings(delayed, direct, chi.shift, T)
    return Margins(
        point=point, T=T, modulus=upper, modulus_lower=lower, modulus_theta=theta,
        modulus_frequency=theta / (2 * math.pi * T),
        gain=_gain_crossings(delayed, direct, chi.shift, T),
        phase=phase,
        parameters=tuple(_parameter_margin(loop, name, point)
                         for name in _margin_parameters(loop, parameters)),
        delay=_delay_margin(loop, point, limit, _first_delay(phase, delayed, direct)),
        delay_limit=limit,
        # The loop's own question (symstab.numeric.analysis.delays), which asks this module's.
        exact_delay=loop.delay_margin(limit=limit, every=False, **point) if limit else None)


def classified_point(loop, values):
    """``(point, code)``: the point's values (defaults filled in, single numbers) and its verdict.

    The checks of every question (unknown and missing names, ``d`` a whole
    number of samples, finite reals), then :meth:`symstab.Loop.classify`.

    Parameters
    ----------
    loop : symstab.Loop
    values : dict
        A single value of every parameter (or its default).

    Returns
    -------
    (dict, int)
        ``{name: value}`` in the loop's parameters' order, and ``STABLE``,
        ``MARGINAL`` or ``UNSTABLE``.
    """
    checked, d, _ = loop.evaluation.prepare(values, scalar=loop.parameters)
    point = {name: float(checked[name]) for name in loop.symbols}
    # The delay in samples: whole, or with its fraction (Td read as d).
    point["d"] = d if FRACTION not in checked else d + float(checked[FRACTION])
    point = {name: point[name] for name in loop.parameters}
    return point, int(loop.classify(**point))


def stable_point(loop, values, what="margins"):
    """The point's values (defaults filled in, single numbers), checked to be stable.

    The one check of the questions asked at a stable point (``what``: the
    margins, the force noise): an unstable or marginal point is a
    ValueError saying which.
    """
    point, code = classified_point(loop, values)
    if code != STABLE:
        state = ("marginal (a pole on the unit circle)" if code == MARGINAL else
                f"unstable ({int(loop.unstable_root_counts(**point))} poles outside the unit "
                f"circle)")
        need = "need" if what.endswith("s") else "needs"
        raise ValueError(f"{what} {need} a stable point: the loop is {state} there")
    return point


def _on_circle(c, theta):
    """The polynomial ``c`` (highest power first) at ``exp(j theta)`` (1-D ``theta``)."""
    theta = np.asarray(theta, dtype=float)
    return _rows_on_circle(np.asarray(c, dtype=float)[None, :],
                           np.zeros(theta.size, dtype=np.int64), theta)


def _open_loop(delayed, direct, shift, theta):
    """``L(exp(j theta)) = N / (z**s D)``."""
    with np.errstate(all="ignore"):
        return _on_circle(direct, theta) / (np.exp(1j * shift * theta) * _on_circle(delayed, theta))


def _gain_crossings(delayed, direct, shift, T):
    """Every phase crossover (``L`` real, negative) with its gain margin ``-1 / L``."""
    _, theta, gain = _phase_crossovers(delayed[None, :], direct[None, :], shift)
    return tuple(NyquistCrossing(float(-1.0 / g.real), float(t), float(t / (2 * math.pi * T)))
                 for t, g in zip(theta, gain, strict=True))


def _rows_on_circle(c, rows, theta):
    """Row ``rows[k]`` of the polynomials ``c`` (highest first) at ``exp(j theta[k])``."""
    return horner(c[rows], np.exp(1j * theta)[:, None])[0][:, 0]


def _phase_crossovers(delayed, direct, shift):
    """``(row, theta, L)`` of every phase crossover (``L`` real, negative) of each row, in order.

    Sign changes of ``Im(N conj(D) z**-s) / sin(theta) = Im L |D|**2 / sin(theta)``
    (no division by ``D``, which vanishes at ``z = 1`` for an integrator) on
    a grid of :data:`_SCAN_PER_HARMONIC` points per period of its highest
    harmonic from a thousandth of a step off each end, refined by
    :func:`~symstab.numeric.engine.search.bracketed_root`, and the ends
    ``theta = 0`` and ``pi``, where ``L`` is real; a pole of ``L`` on the
    circle (``D`` 0 to within rounding) is no crossing.  Two crossings
    closer than the grid's step are not separated.
    """
    n_rows = len(delayed)
    harmonics = shift + max(delayed.shape[1], direct.shape[1])
    grid = np.linspace(0.0, np.pi, _SCAN_PER_HARMONIC * harmonics + 1)
    # Im L |D|**2 is an odd function of theta, 0 at both ends: divided by
    # sin(theta) a crossing in the first or last step is a sign change too.
    # The ends themselves are moved in by a thousandth of a step.
    grid[0], grid[-1] = 1e-3 * grid[1], np.pi - 1e-3 * grid[1]

    def imag(theta, rows):
        value = _rows_on_circle(direct, rows, theta) * np.conj(_rows_on_circle(delayed, rows, theta))
        return np.imag(value * np.exp(-1j * shift * theta)) / np.sin(theta)

    found_rows, found_theta = [np.repeat(np.arange(n_rows), 2)], [np.tile([0.0, np.pi], n_rows)]
    for part in chunk_slices(n_rows, 16 * 4 * len(grid)):
        rows = np.repeat(np.arange(n_rows)[part], len(grid))
        values = imag(np.tile(grid, part.stop - part.start), rows).reshape(-1, len(grid))
        change = np.sign(values[:, :-1]) * np.sign(values[:, 1:]) < 0
        r, k = np.nonzero(change)
        r = r + part.start
        found_rows.append(r)
        found_theta.append(bracketed_root(lambda t, i, r=r: imag(t, r[i]), grid[k], grid[k + 1],
                                          indexed=True))
        r0, k0 = np.nonzero(values == 0)
        found_rows.append(r0 + part.start)
        found_theta.append(grid[k0])
    rows, theta = np.concatenate(found_rows), np.concatenate(found_theta)
    order = np.lexsort((theta, rows))
    rows, theta = rows[order], theta[order]
    # A root bracketed next to an end is the end's crossing, added above.
    single = np.r_[True, (np.diff(rows) != 0) | (np.diff(theta) > 1e-9)]
    rows, theta = rows[single], theta[single]
    with np.errstate(all="ignore"):
        d_val = _rows_on_circle(delayed, rows, theta)
        gain = (_rows_on_circle(direct, rows, theta)
                / (np.exp(1j * shift * theta) * d_val))
    pole = np.abs(d_val) <= 64 * _EPS * np.sum(np.abs(delayed), axis=1)[rows]
    keep = np.isfinite(gain) & (gain.real < 0) & ~pole
    return rows[keep], theta[keep], gain[keep]


def _autocorrelation(c):
    """``r_k = sum_i c_i c_(i+k)``, k = 0 .. n: ``|c(exp(j theta))|**2 = r_0 + 2 sum r_k cos(k theta)``."""
    c = np.asarray(c, dtype=float)
    full = np.correlate(c, c, mode="full")
    return full[len(c) - 1:]


def phase_crossings(delayed, direct, shift, T):
    """Every gain crossover (``|L| = 1``) with its phase margin ``180 + arg L`` (degrees).

    ``chi = z**shift delayed + direct`` (rows highest first); ``T`` the
    sample period (for the frequencies).  A tuple of :class:`NyquistCrossing`.
    """
    rn, rd = _autocorrelation(direct), _autocorrelation(delayed)
    size = max(len(rn), len(rd))
    series = np.zeros(size)
    series[:len(rn)] += rn
    series[:len(rd)] -= rd
    series[1:] *= 2
    # In x = cos(theta), cos(k theta) = T_k(x): the roots of a Chebyshev series.
    roots = np.polynomial.chebyshev.chebroots(np.trim_zeros(series, "b")) if np.any(series) else []
    # A tangency is a near-double root that rounding may make a complex pair:
    # candidates are taken loosely, and kept where |L| = 1 once polished.
    x = np.array([r.real for r in np.atleast_1d(roots)
                  if abs(r.imag) <= 1e-6 and -1 - 1e-6 <= r.real <= 1 + 1e-6])
    theta = _polished(delayed, direct, np.unique(np.arccos(np.clip(x, -1.0, 1.0))))
    gain = _open_loop(delayed, direct, shift, theta)
    pole = np.abs(_on_circle(delayed, theta)) <= 64 * _EPS * np.sum(np.abs(delayed))
    on = np.isfinite(gain) & ~pole & (np.abs(np.abs(gain) - 1) <= 1e-6)
    theta, gain = theta[on], gain[on]
    keep = np.r_[True, np.diff(theta) > 1e-12] if theta.size else np.zeros(0, dtype=bool)
    out = []
    for k in np.flatnonzero(keep):
        phase = math.degrees(float(np.angle(gain[k])))
        margin = (phase + 360.0) % 360.0 - 180.0
        out.append(NyquistCrossing(margin, float(theta[k]), float(theta[k] / (2 * math.pi * T))))
    return tuple(out)


def _polished(delayed, direct, theta, steps=8):
    """Newton steps on ``|N|**2 - |D|**2`` evaluated on the circle (not in ``cos theta``).

    The Chebyshev roots lose digits where ``x = cos theta`` is near 1 (a
    crossover at low frequency: ``d theta = dx / sin theta``); a step is kept
    only where it lowers the residual.
    """
    def residual(t):
        z = np.exp(1j * t)
        n, dn = np.polyval(direct, z), 1j * z * np.polyval(np.polyder(direct), z)
        d, dd = np.polyval(delayed, z), 1j * z * np.polyval(np.polyder(delayed), z)
        value = np.abs(n) ** 2 - np.abs(d) ** 2
        return value, 2 * np.real(np.conj(n) * dn - np.conj(d) * dd)

    for _ in range(steps):
        value, slope = residual(theta)
        with np.errstate(all="ignore"):
            trial = np.clip(theta - value / slope, 0.0, np.pi)
        better = np.isfinite(trial) & (np.abs(residual(trial)[0]) < np.abs(value))
        theta = np.where(better, trial, theta)
    return theta


def _margin_parameters(loop, parameters):
    """The parameters named for parameter margins (the plane's by default), checked."""
    if parameters is None:
        return tuple(loop.plane or ())
    if isinstance(parameters, str):
        parameters = (parameters,)
    try:
        names = tuple(parameters)
    except TypeError:
        raise TypeError(f"parameters must be parameter names (a sequence of str), got "
                        f"{type(parameters).__name__}") from None
    if len(set(names)) != len(names):
        raise ValueError(f"parameters: each name once, got {', '.join(map(str, names))}")
    affine = loop.affine_parameters()
    for name in names:
        if name not in affine:
            raise ValueError(f"parameters: {name!r} does not enter the loop's polynomial "
                             f"affinely; a parameter margin needs one of: "
                             f"{', '.join(affine) or 'none'}")
    return names


def _parameter_margin(loop, name, point):
    """The stable interval through ``point`` along ``name``."""
    others = {k: v for k, v in point.items() if k != name}
    value = point[name]
    for low, high in loop.stable_intervals(name, **others):
        if low <= value <= high:
            return ParameterMargin(name, value, float(low), float(high))
    # Stable at the point but on no interval: the line engine and the verdict disagree.
    raise ValueError(f"the stable intervals of {name} do not hold its value {value:.6g} at a "
                     f"point classified stable: the point is too close to the boundary to "
                     f"resolve")


def delay_limit_of(d, delay_limit, *, name="delay_limit", whole=True):
    """The samples to examine beyond the delay ``d``: ``delay_limit``, or the default.

    The default is ``max(100, 10 (d + 1))``; either within
    ``SYMSTAB_MAX_DELAY`` (0 where ``d`` is there already).  ``whole``: a
    whole number of samples (the whole-sample margin's), else any positive
    number (the exact margin's).
    """
    room = max_delay() - d
    if whole:
        room = math.floor(room + 1e-9)
    if delay_limit is None:
        return max(0, min(max(100, 10 * (math.floor(d) + 1)), room))
    limit = (check_count(name, delay_limit, 1) if whole else
             check_real(name, delay_limit, low=0.0, low_open=True))
    if limit > room:
        raise ValueError(f"{name} must be at most {room:g} (SYMSTAB_MAX_DELAY - d), "
                         f"got {limit:g}")
    return limit


def _delay_margin(loop, point, limit, first):
    """The smallest whole number of samples added to ``d`` at which the loop is not stable.

    From the added delay ``first`` (``_first_delay``) on, the certified
    verdicts at ``d + k`` up to ``limit``; None when the loop stays stable
    (or ``first`` is inf: stable at every added delay).
    """
    if not math.isfinite(first):
        return None
    for k in range(int(first), limit + 1):
        if int(loop.classify(**{**point, "d": point["d"] + k})) != STABLE:
            return k
    return None


def _first_delay(phase, delayed, direct):
    """The first whole added delay at which the loop can be unstable (inf: at none).

    On the circle ``|L z**-k| = |L|``, so a root reaches it at an added delay
    only at a gain crossover ``theta_c``, when the delay's phase ``k theta_c``
    has used up that crossover's phase margin ``phi_c`` (mod 2 pi).  Extended
    to real ``k``, ``chi = z**(s + k) D + N`` has no zero on the half circle
    before ``tau* = min phi_c / theta_c``.  The argument change over the half
    circle, which counts the roots inside at whole ``k``, then grows by
    ``pi`` a sample, as the degree does, if and only if the end ``z = -1``
    keeps ``|z**k D| > |N|`` there (``|L(-1)| < 1``): then every whole ``k <
    tau*`` is stable, and with no gain crossover every ``k``.  With
    ``|L(-1)| >= 1`` the end does not turn with ``k`` and no added delay is
    known stable: the search starts at 1.  ``floor(tau*)``, one below, for
    the rounding of ``tau*``.
    """
    if np.abs(_on_circle(direct, [np.pi])[0]) >= np.abs(_on_circle(delayed, [np.pi])[0]):
        return 1
    out = math.inf
    for c in phase:
        if c.theta <= 0:
            continue
        phi = math.radians(c.margin)
        out = min(out, (phi if phi > 0 else phi + 2 * math.pi) / c.theta)
    return max(1, math.floor(out)) if math.isfinite(out) else math.inf


def first_whole_delays(chi):
    """``_first_delay`` of each of ``chi``'s points (flat, stable ones): inf where at none.

    The bound of the delay-margin scan
    (:func:`symstab.numeric.analysis.delay_scan.verdict_changes`) per
    fraction of its grid.
    """
    n = int(np.prod(chi.shape))
    return np.array([_first_delay(phase_crossings(delayed, direct, chi.shift, 1.0), delayed,
                                  direct)
                     for delayed, direct in zip(chi.delayed.reshape(n, -1),
                                                chi.direct.reshape(n, -1), strict=True)],
                    dtype=float)


# --------------------------------------------------------------------------
# Margin maps

#: The margins a map can hold.
MAP_MARGINS = ("modulus", "delay", "gain")


@dataclasses.dataclass(frozen=True)
class MarginMap:
    """A margin over a grid of a plane: NaN where the point is not stable.

    Made by :func:`symstab.numeric.analysis.margins.margin_map`.

    Attributes
    ----------
    x, y : str
        The plane's parameters.
    x_values, y_values : ndarray
        The grid's values (1-D).
    margin : str
        Which margin: ``"modulus"`` (``min |1 + L|`` on the unit circle),
        ``"delay"`` (the exact delay margin: the smallest delay added, in
        samples, fractional, at which a root reaches the unit circle, as
        :meth:`symstab.Loop.delay_margin` finds it) or ``"gain"`` (the gain
        margin, :attr:`Margins.gain_margin`).
    values : ndarray
        The margin per point, shape ``(len(y_values), len(x_values))``; NaN
        where the point is unstable or marginal (never a number there); for
        ``"delay"``, inf where the point stays stable up to ``delay_limit``
        samples more; for ``"gain"``, inf where no phase crossover
        limits the gain.
    lower : ndarray
        Its certified lower bound per point (NaN as ``values``); for
        ``"delay"`` equal to ``values`` (the crossing's delay, to a few ulps;
        what the grid of ``delay_step`` cannot see is a window of
        instability shorter than a step, entered and left between two of
        its points).
    codes : ndarray
        The verdicts (:data:`~symstab.numeric.engine.roots.STABLE`, ...).
    at : dict
        The values of the other parameters.
    delay_limit : float or None
        ``"delay"``: the most samples added that were examined.
    delay_step : float or None
        ``"delay"``: the step of the grid of added delays, samples.
    """

    x: str
    y: str
    x_values: np.ndarray
    y_values: np.ndarray
    margin: str
    values: np.ndarray
    lower: np.ndarray
    codes: np.ndarray
    at: dict
    delay_limit: object = None
    delay_step: object = None

    def __repr__(self):
        stable = ~np.isnan(self.values)
        best = (f", largest {np.nanmax(self.values):.4g} at {self.x} = "
                f"{self.x_values[np.nanargmax(self.values) % len(self.x_values)]:.4g}, "
                f"{self.y} = {self.y_values[np.nanargmax(self.values) // len(self.x_values)]:.4g}"
                if stable.any() else "")
        return (f"MarginMap({self.margin} margin over {len(self.x_values)} x "
                f"{len(self.y_values)} points of ({self.x}, {self.y}): {int(stable.sum())} "
                f"stable{best})")

    def plot(self, ax=None, *, region=None, levels=None):
        """Draw the margin as filled contours, a decomposition over it if given.

        See :func:`symstab.drawing.plot_margin_map`.

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            Where to draw (default: a new figure's axes).
        region : symstab.numeric.engine.decomposition.Decomposition, optional
            The loop's decomposition in the same plane (:meth:`symstab.Loop.region`).
        levels : int or sequence of float, optional
            The contour levels (default 10 levels).

        Returns
        -------
        symstab.drawing.Plot
        """
        from ...drawing import plot_margin_map

        return plot_margin_map(self, ax, region=region, levels=levels)


def margin_map(loop, x_values, y_values, *, x=None, y=None, margin="modulus", rtol=1e-9,
               delay_limit=None, delay_step=None, **values):
    """A margin at every point of a grid of a loop's plane, certified per point.

    Each point is classified (:meth:`symstab.Loop.classify`); at the stable
    ones the modulus margin ``min |1 + L|`` is certified as in
    :func:`margins` (:func:`symstab.numeric.engine.roots.circle_minimum`,
    all points at once); elsewhere the map holds NaN.

    Parameters
    ----------
    loop : symstab.Loop
        The loop.
    x_values, y_values : array_like
        The grid's values along ``x`` and ``y`` (1-D).
    x, y : str, optional
        The plane (default: the loop's :attr:`~symstab.Loop.plane`).
    margin : str
        ``"modulus"`` or ``"gain"``, as :func:`margins` finds each at every
        stable point (the modulus margins and the phase crossovers of all
        points at once), or ``"delay"``, the exact delay margin as
        :meth:`symstab.Loop.delay_margin` finds it, every point at once
        (:mod:`symstab.numeric.analysis.delay_scan`: the certified verdicts
        of the points still stable at each whole sample of the grid in one
        call, the grid's fractions an array; every point's first change
        refined together).
    rtol : float
        The relative width of each point's certified bracket (wider next to
        the boundary, where the rounding of chi allows no narrower one).
    delay_limit : float, optional
        ``"delay"``: the most samples added (default ``max(100, 10 (d +
        1))``, within ``SYMSTAB_MAX_DELAY``); a point stable up to there
        holds inf.
    delay_step : float, optional
        ``"delay"``: the grid's step in samples, in (0, 1] (default 1/16).
    **values
        Single values of every other parameter.

    Returns
    -------
    MarginMap

    Examples
    --------
    >>> from symstab import Loop
    >>> loop = Loop("1/(m*s**2 + b*s)", "K + B*(z - 1)/(T*z)", plane=("B", "K"),
    ...             values=dict(m=0.0128, b=0.0324, T=1e-3, d=10))
    >>> found = margin_map(loop, [0.1, 0.2], [1.0, 50.0])
    >>> found.values.shape, bool(np.isnan(found.values[1, 0]))
    ((2, 2), True)
    """
    if margin not in MAP_MARGINS:
        raise ValueError(f"margin must be one of {', '.join(map(repr, MAP_MARGINS))}, "
                         f"got {margin!r}")
    x, y = loop.plane_of(x, y)
    xs, ys = check_grid(x, y, x_values, y_values, values)
    rtol = check_real("rtol", rtol, low=0.0, low_open=True, high=0.5, high_open=True)
    X, Y = np.meshgrid(xs, ys)
    codes = np.asarray(loop.classify(**{**values, x: X, y: Y}))
    stable = codes == STABLE
    out = np.full((2, *X.shape), np.nan)
    checked, d, _ = loop.evaluation.prepare(values, drop=(x, y))
    if FRACTION in checked:
        d = d + float(checked[FRACTION])
    if margin == "delay":
        limit = float(delay_limit_of(d, delay_limit, whole=False))
        delay_step = 1.0 / STEPS_PER_SAMPLE if delay_step is None else check_real(
            "delay_step", delay_step, low=0.0, low_open=True, high=1.0)
    if stable.any():
        if margin == "delay":
            given = {k: v for k, v in values.items() if k not in ("d", "Td")}
            upper = lower = first_crossings(loop, given, {x: X[stable], y: Y[stable]}, d, limit,
                                            delay_step, first_whole_delays)
        elif margin == "modulus":
            lower, upper, _ = circle_minimum(
                loop.polynomial(**{**values, x: X[stable], y: Y[stable]}), rtol=rtol)
        else:
            upper = lower = _gain_margins(loop.polynomial(**{**values, x: X[stable],
                                                             y: Y[stable]}))
        out[0][stable], out[1][stable] = upper, lower
    return MarginMap(x=x, y=y, x_values=xs, y_values=ys, margin=margin, values=out[0],
                     lower=out[1], codes=codes, at=dict(values),
                     delay_limit=limit if margin == "delay" else None,
                     delay_step=delay_step if margin == "delay" else None)


def _gain_margins(chi):
    """The gain margin of each point's ``chi``: the smallest ``-1 / L > 1`` at a phase crossover."""
    n = int(np.prod(chi.shape))
    rows, _, gain = _phase_crossovers(chi.delayed.reshape(n, -1), chi.direct.reshape(n, -1),
                                      chi.shift)
    factor = -1.0 / gain.real
    out = np.full(n, np.inf)
    up = factor > 1
    np.minimum.at(out, rows[up], factor[up])
    return out
