"""The stable region in the (beta, alpha) plane, and what it lets a user render.

For fixed ``(gamma, d, delta)`` the characteristic polynomial is affine in
alpha and in beta, so along any vertical line ``beta = b`` (or horizontal
line ``alpha = a``) a root can cross the unit circle only where the line
meets

* the boundary arc ``(beta(theta), alpha(theta))``, ``0 < theta < pi``
  (a pair of complex roots on the circle), from the generated kernel;
* the line ``alpha = 0`` (a root at z = 1);
* the line ``alpha + 2 beta = c`` (a root at z = -1,
  :func:`symstab.curves.minus_one_line`).

Between two consecutive crossings the number of unstable roots is constant,
so one classification per gap (:func:`symstab.stability.classify`) decides
the whole gap: the stable intervals along a line are exact up to the
root-finding of the crossings (bisection to the last bit), with no scan of
alpha.  :class:`StabilityRegion` does this for many lines at once;
:func:`limits` builds on it (alpha_max and the beta range by a k-ary search
for the last line that still meets the region, the Z-width by integrating
the stable length over beta), and :func:`best_virtual_mass` maximises
alpha_max over gamma.
"""

import dataclasses
import functools
import math

import numpy as np

from ._generated import kernels
from ._validate import check_real, check_loop
from .curves import Segment, bracketed_root, minus_one_line, scan_grid
from .stability import MARGINAL, STABLE, classify

__all__ = ["StabilityRegion", "Limits", "limits", "BestVirtualMass", "best_virtual_mass"]

#: Relative offset of the probes that decide whether an arc point touches
#: the stable region: far above the 1e-12 marginal band, and below the width
#: of the thinnest regions (the gamma = 2, d = 0 sliver is 3e-5 wide; 1e-4
#: missed its top).  It picks the arc segments to work with and seeds the
#: searches, which then run to the last bit.
_PROBE = 1e-6
#: The probe distances of the touching test (relative).
_PROBES = (_PROBE, 1e-9)


def _ranges(start, stop):
    """Concatenate ``arange(start[i], stop[i])``; also return the owner i of each."""
    counts = stop - start
    owner = np.repeat(np.arange(len(start)), counts)
    offsets = np.arange(counts.sum()) - np.repeat(np.cumsum(counts) - counts, counts)
    return owner, np.repeat(start, counts) + offsets


class StabilityRegion:
    """The stable set of one ``(gamma, d, delta)`` in the (beta, alpha) plane.

    Parameters
    ----------
    gamma : float
        ``M_w / m``.
    d : int
        Delay in samples, ``d >= 0``.
    delta : float
        ``b T / m > 0``.

    Examples
    --------
    >>> r = StabilityRegion(gamma=1.5, d=0, delta=0.00253125)
    >>> [(round(lo, 3), round(hi, 3)) for lo, hi in r.alpha_intervals(-0.5)]
    [(1.266, 2.232)]
    """

    def __init__(self, *, gamma, d, delta):
        self.gamma, self.d, self.delta = check_loop(gamma, d, delta)
        theta = np.concatenate([[0.0], scan_grid(self.d, upper=np.pi * (1 - 1e-9))])
        theta = np.union1d(theta, self._extrema(theta))
        alpha, beta = kernels.boundary(theta, self.gamma, self.d, self.delta)
        alpha[0], beta[0] = 0.0, -self.delta
        self._theta, self._alpha, self._beta = theta, alpha, beta
        self.minus_one = minus_one_line(gamma=self.gamma, d=self.d, delta=self.delta)

    def _extrema(self, theta):
        """The angles of the local extrema of alpha(theta) and beta(theta).

        With them among the samples, alpha and beta are monotone on every
        segment of the sampled arc, so a line that meets a segment twice
        (near the top of the arc, say) cannot slip through unnoticed.
        """
        out = []
        values = kernels.boundary(theta, self.gamma, self.d, self.delta)
        for index, v in enumerate(values):
            inner = v[1:-1]
            peak = (inner >= v[:-2]) & (inner > v[2:]) | (inner <= v[:-2]) & (inner < v[2:])
            i = np.flatnonzero(peak & np.isfinite(inner)) + 1
            if i.size:
                sign = np.where(v[i] > v[i - 1], 1.0, -1.0)
                out.append(_golden_max(lambda t, k=index, s=sign: s * kernels.boundary(
                    t, self.gamma, self.d, self.delta)[k], theta[i - 1], theta[i + 1]))
        return np.concatenate(out) if out else np.empty(0)

    # -- crossings of the boundary with a family of lines -----------------

    def _arc_point(self, theta):
        return kernels.boundary(theta, self.gamma, self.d, self.delta)

    def _arc_crossings(self, axis, values):
        """Arc points where ``axis`` (``"beta"`` or ``"alpha"``) equals each value.

        Returns ``(owner, other)``: the index into ``values`` and the other
        coordinate of every crossing.  Each arc segment is half-open, so a
        value met exactly at a sample is found once.
        """
        coord = self._beta if axis == "beta" else self._alpha
        order = np.argsort(values)
        sorted_values = values[order]
        active = np.flatnonzero(self._active_segments)
        c0, c1 = coord[active], coord[active + 1]
        rising = c1 > c0
        start = np.where(rising, np.searchsorted(sorted_values, c0, "left"),
                         np.searchsorted(sorted_values, c1, "right"))
        stop = np.where(rising, np.searchsorted(sorted_values, c1, "left"),
                        np.searchsorted(sorted_values, c0, "right"))
        stop = np.maximum(stop, start)
        segment, k = _ranges(start, stop)
        segment = active[segment]
        if segment.size == 0:
            return np.empty(0, dtype=int), np.empty(0)
        target = sorted_values[k]
        index = 1 if axis == "beta" else 0

        def f(t):
            return self._arc_point(t)[index] - target

        lo, hi = self._theta[segment], self._theta[segment + 1]
        flo = coord[segment] - target
        exact = flo == 0
        root = bracketed_root(f, lo, hi)
        root = np.where(exact, lo, root)
        other = self._arc_point(root)[1 - index]
        if axis == "beta":
            other = np.where(root == 0.0, 0.0, other)
        else:
            other = np.where(root == 0.0, -self.delta, other)
        return order[k], other

    def _intervals(self, axis, values, closure=False):
        """Stable intervals of the other coordinate on each line ``axis = value``.

        With ``closure``, gaps whose probe is marginal count too: next to a
        corner or the top of the region the gap between two crossings is so
        short that its probe lies within 1e-12 of radius 1, and the searches
        for the extent of the region should run into the corner, not stop
        where the classification can no longer tell.
        """
        values = np.atleast_1d(np.asarray(values, dtype=float))
        owner, cuts = self._arc_crossings(axis, values)
        if axis == "beta":
            lines = [(np.arange(len(values)), np.zeros(len(values))),
                     (np.arange(len(values)), self.minus_one - 2 * values)]
        else:
            lines = [(np.arange(len(values)), (self.minus_one - values) / 2)]
        owner = np.concatenate([owner] + [o for o, _ in lines])
        cuts = np.concatenate([cuts] + [c for _, c in lines])
        keep = np.isfinite(cuts)
        owner, cuts = owner[keep], cuts[keep]
        order = np.lexsort((cuts, owner))
        owner, cuts = owner[order], cuts[order]
        # Probes: below the first cut, between cuts, above the last one.
        first = np.r_[True, owner[1:] != owner[:-1]]
        last = np.r_[owner[1:] != owner[:-1], True]
        pad = 1.0 + np.abs(cuts)
        between = 0.5 * (cuts[:-1] + cuts[1:])
        probe_owner = np.concatenate([owner[first], owner[:-1][~last[:-1]], owner[last]])
        probe_at = np.concatenate([cuts[first] - pad[first], between[~last[:-1]],
                                   cuts[last] + pad[last]])
        probe_lo = np.concatenate([np.full(first.sum(), -np.inf), cuts[:-1][~last[:-1]], cuts[last]])
        probe_hi = np.concatenate([cuts[first], cuts[1:][~last[:-1]], np.full(last.sum(), np.inf)])
        line_value = values[probe_owner]
        if axis == "beta":
            code = classify(alpha=probe_at, beta=line_value, gamma=self.gamma, d=self.d, delta=self.delta)
        else:
            code = classify(alpha=line_value, beta=probe_at, gamma=self.gamma, d=self.d, delta=self.delta)
        code = np.atleast_1d(code)
        stable = (code == STABLE) | (closure & (code == MARGINAL))
        out = [[] for _ in values]
        order = np.lexsort((probe_lo, probe_owner))
        for i in order[stable[order]]:
            runs = out[probe_owner[i]]
            if runs and runs[-1][1] == probe_lo[i]:
                runs[-1] = (runs[-1][0], float(probe_hi[i]))
            else:
                runs.append((float(probe_lo[i]), float(probe_hi[i])))
        return out

    def alpha_intervals(self, beta):
        """The stable alpha intervals at damping ``beta``.

        Parameters
        ----------
        beta : float
            Dimensionless damping.

        Returns
        -------
        list of (float, float)
            Increasing, disjoint; empty when no alpha is stable.  An interval
            that does not start at 0 shows the minimum stiffness needed.
        """
        return self._intervals("beta", [check_real("beta", beta)])[0]

    def beta_intervals(self, alpha):
        """The stable beta intervals at stiffness ``alpha`` (as :meth:`alpha_intervals`)."""
        return self._intervals("alpha", [check_real("alpha", alpha)])[0]

    # -- where the region is ----------------------------------------------

    @functools.cached_property
    def _active_segments(self):
        """Arc segments within two samples of one that touches the region.

        Only these can bound the stable region; the rest of the arc (at large
        d it winds around many times) only splits unstable gaps, so leaving
        it out changes no interval and saves most of the work.
        """
        near = np.convolve(self._touching.astype(float), np.ones(5), mode="same") > 0
        # The arc's start (-delta, 0) is a corner of every region that
        # reaches it, however thin the wedge there is next to it.
        near |= self._theta < 2 * self._theta[-1] / max(400, 16 * (self.d + 1))
        return near[:-1] | near[1:]

    @functools.cached_property
    def _touching(self):
        """Mask of arc samples with a stable point within a relative 1e-6 or 1e-9.

        Probes on both sides in alpha and in beta, at two distances: the far
        ones find ordinary regions, the near ones slivers thinner than the
        far ones jump over (at the gamma where the d = 0 sliver vanishes it
        is 2e-7 wide).
        """
        a, b = self._alpha, self._beta
        ok = np.isfinite(a) & np.isfinite(b) & (np.abs(a) < 1e6) & (np.abs(b) < 1e6)
        a, b = a[ok], b[ok]
        probes_a, probes_b = [], []
        for scale in _PROBES:
            ea = scale * (np.abs(a) + self.delta)
            eb = scale * (np.abs(b) + self.delta)
            probes_a += [a + ea, a - ea, a, a]
            probes_b += [b, b, b + eb, b - eb]
        # The Schur-Cohn verdicts alone: these probes sit next to the
        # boundary, where the eigenvalue refinement of every one would cost
        # 20 s at d = 200.  Where the margin is positive they never disagreed
        # with the eigenvalues in the tests (tests/test_classify.py); a false
        # "unstable" here would drop arc segments near the region.
        code = classify(alpha=np.concatenate(probes_a), beta=np.concatenate(probes_b),
                        gamma=self.gamma, d=self.d, delta=self.delta, refine=False)
        touching = np.zeros(len(self._alpha), dtype=bool)
        stable = (np.asarray(code) == STABLE).reshape(4 * len(_PROBES), -1)
        touching[np.flatnonzero(ok)] = np.any(stable, axis=0)
        return touching

    def _last_meeting(self, axis, inside, outside, rounds=14, fan=16):
        """The boundary between ``inside`` (a line meeting the region) and ``outside``.

        A ``fan``-ary search: each round tests ``fan`` lines at once.
        Returns the last line found to meet the region and its intervals
        (``None`` when no trial line met it: ``inside`` itself was the best).
        """
        runs_inside = None
        for _ in range(rounds):
            trial = np.linspace(inside, outside, fan + 2)[1:-1]
            runs = self._intervals(axis, trial, closure=True)
            k = np.flatnonzero([bool(r) for r in runs])
            j = k[-1] + 1 if k.size else 0
            if j > 0:
                inside, runs_inside = trial[j - 1], runs[j - 1]
            outside = trial[j] if j < fan else outside
            if abs(outside - inside) <= 4 * np.spacing(max(abs(inside), abs(outside))):
                break
        return inside, runs_inside

    def _corners(self):
        """beta of the points where the arc meets alpha = 0 (exact corners)."""
        ends = self._arc_crossings("alpha", np.array([0.0]))[1]
        return np.sort(np.concatenate([ends, [-self.delta]]))

    def _beta_window(self):
        touching = self._touching
        if not touching.any():
            return None
        lo, hi = self._beta[touching].min(), self._beta[touching].max()
        return lo, hi

    def line_segments(self):
        """The pieces of z = 1 (alpha = 0) and z = -1 that bound the stable region.

        Returns
        -------
        tuple of :class:`symstab.curves.Segment`
        """
        extent = self.beta_range()
        if extent is None:
            return ()
        lo, hi = extent
        pad = 0.05 * (hi - lo) + self.delta
        out = []
        # z = 1: the beta where a point just above alpha = 0 is stable.
        betas = np.linspace(lo - pad, hi + pad, 2001)
        step = betas[1] - betas[0]
        eps = _PROBE * max(self._alpha[self._touching].max(), self.delta)
        above = np.asarray(classify(alpha=eps, beta=betas, gamma=self.gamma, d=self.d,
                                    delta=self.delta)) == STABLE
        # The exact corners on alpha = 0: where the arc or the z = -1 line meets it.
        ends = np.concatenate([self._corners(), [self.minus_one / 2]])

        def snap(b):
            near = ends[np.argmin(np.abs(ends - b))]
            return near if abs(near - b) <= 2 * step else b

        for run in _runs(above):
            out.append(Segment("z=1", float(snap(betas[run[0]])), 0.0,
                               float(snap(betas[run[1]])), 0.0))
        # z = -1: alpha + 2 beta = c, stable on one side only.
        line_alpha = self.minus_one - 2 * betas
        e = _PROBE * (np.abs(line_alpha) + self.delta)
        sides = [np.asarray(classify(alpha=line_alpha + s * e, beta=betas, gamma=self.gamma,
                                     d=self.d, delta=self.delta)) == STABLE for s in (1, -1)]
        for run in _runs(sides[0] ^ sides[1]):
            out.append(Segment("z=-1", float(betas[run[0]]), float(line_alpha[run[0]]),
                               float(betas[run[1]]), float(line_alpha[run[1]])))
        return tuple(out)

    def alpha_max(self):
        """``(alpha_max, beta at alpha_max)``, or ``None`` when the region is empty.

        The highest arc sample next to the region (the arc's local maxima are
        among the samples, refined) brackets alpha_max within a relative 1e-6;
        a k-ary search for the last horizontal line that meets the region
        settles it.
        """
        touching = self._touching
        if not touching.any():
            return None
        top = self._alpha[touching].max()
        inside = top * (1 - 2 * _PROBE) - _PROBE * self.delta
        outside = top * (1 + 1e-9) + 1e-300
        if not self._intervals("alpha", [inside])[0]:
            return self._alpha_max_from_scan()
        while self._intervals("alpha", [outside])[0]:
            outside = inside + 4 * (outside - inside)
            if not math.isfinite(outside):
                return math.inf, math.nan
        alpha_max, at_top = self._last_meeting("alpha", inside, outside)
        at_top = at_top or self._intervals("alpha", [alpha_max], closure=True)[0]
        if not at_top:
            return float(alpha_max), math.nan
        # The run the search ended on touches the top: its middle is the
        # top's beta (to within the marginal band; limits() clamps it into
        # the beta range).
        return float(alpha_max), float(0.5 * (at_top[0][0] + at_top[-1][1]))

    def _alpha_max_from_scan(self, n_beta=801):
        """alpha_max when no arc sample is the top: the tops of vertical lines."""
        betas = np.linspace(*self._beta_range_bracket(n_beta)[:2], n_beta)
        runs = self._intervals("beta", betas)
        tops = np.array([r[-1][1] if r else -np.inf for r in runs])
        k = int(np.argmax(tops))
        if not np.isfinite(tops[k]):
            return (math.inf, math.nan) if tops[k] > 0 else None
        return float(tops[k]), float(betas[k])

    def _beta_range_bracket(self, n_beta):
        """A window of vertical lines whose first and last miss the region."""
        lo, hi = self._beta_window()
        pad = 0.05 * (hi - lo) + self.delta
        for _ in range(8):
            betas = np.linspace(lo - pad, hi + pad, n_beta)
            meets = np.array([bool(r) for r in self._intervals("beta", betas)])
            if not (meets[0] or meets[-1]):
                break
            pad *= 4
        return betas[0], betas[-1], betas, meets

    def beta_range(self, n_beta=201):
        """``(beta_min, beta_max)`` of the stable region, or ``None`` when it is empty."""
        if self._beta_window() is None:
            return None
        _, _, betas, meets = self._beta_range_bracket(n_beta)
        k = np.flatnonzero(meets)
        if k.size == 0:
            return None
        return (float(self._last_meeting("beta", betas[k[0]], betas[k[0] - 1])[0]),
                float(self._last_meeting("beta", betas[k[-1]], betas[k[-1] + 1])[0]))

    def z_width(self, beta_min, beta_max, n_beta=801):
        """Area of the stable region: the stable length on verticals, trapezoid rule."""
        betas = np.linspace(beta_min, beta_max, n_beta)
        lengths = np.array([sum(h - l for l, h in r) for r in self._intervals("beta", betas)])
        return float(np.sum(0.5 * (lengths[1:] + lengths[:-1]) * np.diff(betas)))

    def limits(self, *, n_beta=801):
        """alpha_max, the beta range and the Z-width (see :func:`limits`)."""
        beta_range = self.beta_range()
        top = self.alpha_max() if beta_range else None
        if top is None:
            return Limits.empty_region(self, "no stable point next to the boundary arc: "
                                             "the stable region is empty")
        alpha_max, beta_at = top
        if not math.isfinite(alpha_max):
            return Limits(self, math.inf, math.nan, beta_range[1], beta_range[0], math.inf,
                          "the stable region is unbounded in alpha")
        beta_at = min(max(beta_at, beta_range[0]), beta_range[1])
        return Limits(self, alpha_max, beta_at, beta_range[1], beta_range[0],
                      self.z_width(*beta_range, n_beta=n_beta), "")


def _golden_max(f, a, b, iterations=80):
    """Vectorised golden-section search for the maximum of f on [a, b]."""
    ratio = (math.sqrt(5) - 1) / 2
    a, b = np.array(a, dtype=float), np.array(b, dtype=float)
    x1, x2 = b - ratio * (b - a), a + ratio * (b - a)
    f1, f2 = f(x1), f(x2)
    for _ in range(iterations):
        left = f1 < f2
        a = np.where(left, x1, a)
        b = np.where(left, b, x2)
        x1, x2 = np.where(left, x2, b - ratio * (b - a)), np.where(left, a + ratio * (b - a), x1)
        f1, f2 = np.where(left, f2, f(x1)), np.where(left, f(x2), f1)
    return 0.5 * (a + b)


def _runs(mask):
    """Index pairs (first, last) of the runs of True in a 1-D mask."""
    edges = np.diff(np.r_[0, mask.astype(np.int8), 0])
    return list(zip(np.flatnonzero(edges == 1), np.flatnonzero(edges == -1) - 1))


@dataclasses.dataclass(frozen=True)
class Limits:
    """What one ``(gamma, d, delta)`` lets a device render.

    Attributes
    ----------
    alpha_max : float or None
        Largest stable alpha (the renderable stiffness ``K_w T**2 / m``).
    beta_at_alpha_max : float or None
        The beta at which alpha_max is reached.
    beta_max, beta_min : float or None
        The range of beta over the stable region.
    z_width : float
        Area of the stable region in the (beta, alpha) plane (0 when empty).
    message : str
        Empty, or why the region is empty or unbounded.
    """

    region: StabilityRegion
    alpha_max: float
    beta_at_alpha_max: float
    beta_max: float
    beta_min: float
    z_width: float
    message: str = ""

    @classmethod
    def empty_region(cls, region, message):
        return cls(region, None, None, None, None, 0.0, message)

    @property
    def empty(self):
        """True when no parameter point is stable."""
        return self.alpha_max is None

    def alpha_interval(self, beta):
        """The stable alpha intervals at ``beta``; see :meth:`StabilityRegion.alpha_intervals`."""
        return self.region.alpha_intervals(beta)

    def minimum_stiffness(self, beta):
        """The smallest stable alpha at ``beta`` (0 unless a minimum stiffness is needed).

        ``None`` when nothing is stable at ``beta``.
        """
        runs = self.region.alpha_intervals(beta)
        return runs[0][0] if runs else None

    def as_dict(self):
        """The numbers, for tables and JSON."""
        return {"gamma": self.region.gamma, "d": self.region.d, "delta": self.region.delta,
                "alpha_max": self.alpha_max, "beta_at_alpha_max": self.beta_at_alpha_max,
                "beta_max": self.beta_max, "beta_min": self.beta_min,
                "z_width": self.z_width, "message": self.message}


def limits(*, gamma, d, delta, n_beta=801):
    """Renderable limits of one virtual mass, delay and device.

    Parameters
    ----------
    gamma : float
        ``M_w / m``.
    d : int
        Delay in samples, ``d >= 0``.
    delta : float
        ``b T / m > 0``.
    n_beta : int
        Vertical lines for the Z-width (trapezoid rule; its error is about
        ``1 / n_beta**2`` of the width where the region's edges are smooth).

    Returns
    -------
    Limits
        Empty (``alpha_max is None``, ``z_width == 0``, with a message) when
        no point is stable.

    Examples
    --------
    >>> lim = limits(gamma=0.0, d=0, delta=0.00253125)
    >>> round(lim.alpha_max, 4), round(lim.beta_max, 4)
    (0.6897, 2.0034)
    """
    if isinstance(n_beta, bool) or not isinstance(n_beta, (int, np.integer)) or n_beta < 3:
        raise ValueError(f"n_beta must be an integer >= 3, got {n_beta!r}")
    return StabilityRegion(gamma=gamma, d=d, delta=delta).limits(n_beta=n_beta)


@dataclasses.dataclass(frozen=True)
class BestVirtualMass:
    """The virtual mass that maximises the renderable stiffness.

    Attributes
    ----------
    gamma, beta : float or None
        The best ``M_w / m`` and the damping at which alpha_max is reached.
    alpha_max : float or None
        alpha_max at that gamma (a supremum of the stable region).
    alpha_max_gamma0 : float or None
        alpha_max with no virtual mass.
    gain : float or None
        ``alpha_max / alpha_max_gamma0``.
    z_width : float
        Area of the stable region at the best gamma: how much room there is.
        At d = 0 the optimum lies where the region shrinks to nothing (near
        gamma = 2); the gain is real but needs very precise tuning, as the
        paper says.
    message : str
        Empty, or why there is no result (no gamma of the range has a region).
    """

    d: int
    delta: float
    gamma: float
    beta: float
    alpha_max: float
    alpha_max_gamma0: float
    gain: float
    z_width: float = 0.0
    message: str = ""


def _alpha_max(gamma, d, delta):
    top = StabilityRegion(gamma=gamma, d=d, delta=delta).alpha_max()
    return (-math.inf, math.nan) if top is None else top


def best_virtual_mass(*, d, delta, gamma_range=None, n=17):
    """The gamma (and beta) that maximise alpha_max, and the gain over gamma = 0.

    alpha_max(gamma) is scanned on ``n`` points of ``gamma_range`` (default
    from just above ``-1 - (d + 1) delta``, below which no arc exists, to 3)
    and the best scan point is refined by a golden-section search between
    its neighbours, to 1e-6 in gamma.

    Returns
    -------
    BestVirtualMass
        With ``None`` values and a message when no gamma of the range has a
        stable region.

    Raises
    ------
    TypeError, ValueError
        For bad ``d``, ``delta``, ``gamma_range`` or ``n``.

    Examples
    --------
    >>> best = best_virtual_mass(d=0, delta=0.00253125)
    >>> 5 < best.gain < 6.5
    True
    """
    _, d, delta = check_loop(0.0, d, delta)
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 3:
        raise ValueError(f"n must be an integer >= 3, got {n!r}")
    if gamma_range is None:
        gamma_range = (-1.0 - (d + 1) * delta + 1e-3, 3.0)
    g_lo, g_hi = (check_real("gamma_range[0]", gamma_range[0]), check_real("gamma_range[1]", gamma_range[1]))
    if not g_lo < g_hi:
        raise ValueError(f"gamma_range must be increasing, got {gamma_range!r}")
    gammas = np.linspace(g_lo, g_hi, n)
    values = [_alpha_max(g, d, delta)[0] for g in gammas]
    if not np.isfinite(values).any():
        return BestVirtualMass(d, delta, None, None, None, None, None, 0.0,
                               f"no gamma in [{g_lo:g}, {g_hi:g}] has a stable region at d = {d}")
    k = int(np.argmax(values))
    a, b = gammas[max(k - 1, 0)], gammas[min(k + 1, n - 1)]
    ratio = (math.sqrt(5) - 1) / 2
    x1, x2 = b - ratio * (b - a), a + ratio * (b - a)
    f1, f2 = _alpha_max(x1, d, delta)[0], _alpha_max(x2, d, delta)[0]
    while b - a > 1e-6 * max(1.0, abs(a)):
        if f1 < f2:
            a, x1, f1 = x1, x2, f2
            x2 = a + ratio * (b - a)
            f2 = _alpha_max(x2, d, delta)[0]
        else:
            b, x2, f2 = x2, x1, f1
            x1 = b - ratio * (b - a)
            f1 = _alpha_max(x1, d, delta)[0]
    # The best point seen: at the edge where the region vanishes the middle
    # of the last bracket may already have no region.
    candidates = [(values[k], gammas[k]), (f1, x1), (f2, x2)]
    _, best_gamma = max(candidates)
    region = StabilityRegion(gamma=best_gamma, d=d, delta=delta)
    best = region.limits(n_beta=201)
    alpha_zero = _alpha_max(0.0, d, delta)[0]
    return BestVirtualMass(d, delta, float(best_gamma), best.beta_at_alpha_max, best.alpha_max,
                           float(alpha_zero), float(best.alpha_max / alpha_zero), best.z_width)
