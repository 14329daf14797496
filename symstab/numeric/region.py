"""The stable region in the (beta, alpha) plane, and what it lets a user render.

For fixed ``(gamma, d, delta)`` the characteristic polynomial is affine in
alpha and in beta, so along any vertical line ``beta = b`` (or horizontal
line ``alpha = a``) a root can cross the unit circle only where the line
meets

* the boundary arc ``(beta(theta), alpha(theta))``, ``0 < theta < pi``
  (a pair of complex roots on the circle), from the generated kernel;
* the line ``alpha = 0`` (a root at z = 1);
* the line ``alpha + 2 beta = c`` (a root at z = -1,
  :func:`symstab.numeric.curves.minus_one_line`).

Between two consecutive crossings the number N of roots outside the unit
circle is constant, and across a crossing it changes by +-2 (the arc) or +-1
(z = +-1) with the sign of the crossing root's radial velocity; at the two
ends of a line N is known in closed form.  So N in every gap follows by
counting, with no classification and no probe near the boundary: the stable
intervals along a line are the gaps with N = 0, exact up to the root-finding
of the crossings (to the last bit, by :func:`symstab.numeric.curves.bracketed_root`),
with no scan of alpha.  A line whose count fails its consistency check is
decided gap by gap with :func:`symstab.numeric.stability.classify`.  The cost per
line is O(d) kernel evaluations, not the O(d**2) of a Schur-Cohn test or the
O(d**3) of eigenvalues, so d in the thousands stays interactive.

:class:`StabilityRegion` does this for many lines at once; :func:`limits`
builds on it (a scan of vertical lines between the arc's samples finds the
region, then alpha_max and the beta range by a k-ary search for the last
line that still meets it, and the Z-width by integrating the stable length
over beta), and :func:`best_virtual_mass` maximises alpha_max over gamma.
"""

import collections.abc
import dataclasses
import functools
import math
import warnings

import numpy as np

from .._generated import kernels
from .._resources import CHUNK_BYTES, check_memory, chunk_slices
from .._validate import check_array, check_count, check_loop, check_real, check_window
from .curves import (KERNEL_BYTES_PER_POINT, KERNEL_CHUNK_BYTES, Segment,
                     golden_max, arc_end_angle, bracketed_root, minus_one_line, scan_grid)
from .arcs import ClosedFormArc, crossing_change
from .decomposition import decompose
from .paper_loop import paper_limits
from .results import PAPER_PLANE, Boundary
from .polynomial import DelayedPolynomial
from .stability import MARGINAL, STABLE, UNSTABLE, classify, loop_coefficients, paper_polynomial

__all__ = ["StabilityRegion", "limits", "vanishing_gamma", "BestVirtualMass", "best_virtual_mass",
           "scan_maximum", "boundary_curve"]

#: Working bytes per crossing of a line with the boundary (positions, angles,
#: the terms of the crossing direction); lines are processed in chunks of
#: :data:`symstab._resources.CHUNK_BYTES` of crossings.
_BYTES_PER_CROSSING = 640


def _ranges(start, stop):
    """Concatenate ``arange(start[i], stop[i])``; also return the owner i of each."""
    counts = stop - start
    owner = np.repeat(np.arange(len(start)), counts)
    offsets = np.arange(counts.sum()) - np.repeat(np.cumsum(counts) - counts, counts)
    return owner, np.repeat(start, counts) + offsets


def _structured_basis(gamma, d, delta):
    """chi = A0 + alpha A_alpha + beta A_beta as structured polynomials (A0, A_alpha, A_beta)."""
    at = {(a, b): paper_polynomial(alpha=a, beta=b, gamma=gamma, d=d, delta=delta)
          for a, b in ((0.0, 0.0), (1.0, 0.0), (0.0, 1.0))}
    base = at[0.0, 0.0]
    slopes = [DelayedPolynomial(at[k].delayed - base.delayed, at[k].direct - base.direct, base.shift)
              for k in ((1.0, 0.0), (0.0, 1.0))]
    return DelayedPolynomial(base.delayed, base.direct, base.shift), *slopes


def _count(owner, change, low, high, n_lines):
    """N just above each cut (sorted by line, then position), and the lines whose count fails.

    ``low``/``high`` are N at the two ends of each line.  One crossing
    whose direction was lost (``change == 0``) is filled in from the ends;
    a line fails when more are lost, when the count from the low end does
    not arrive at the high end's value, or when it goes below 0.
    """
    unknown = change == 0
    n_unknown = np.bincount(owner, weights=unknown, minlength=n_lines)
    known_sum = np.bincount(owner, weights=change, minlength=n_lines)
    missing = (high - low - known_sum)[owner]
    fill = unknown & (n_unknown[owner] == 1) & (np.abs(missing) <= 2)
    change = np.where(fill, missing, change)
    n_cuts = np.bincount(owner, minlength=n_lines)
    first = np.r_[True, owner[1:] != owner[:-1]] if owner.size else np.zeros(0, dtype=bool)
    running = np.cumsum(change)
    offset = np.repeat(running[first] - change[first], n_cuts[n_cuts > 0])
    above = low[owner] + running - offset
    bad = np.zeros(n_lines, dtype=bool)
    np.logical_or.at(bad, owner, (unknown & ~fill) | (above < 0))
    bad |= (low < 0) | (low + np.bincount(owner, weights=change, minlength=n_lines) != high)
    return above, bad


@dataclasses.dataclass
class _Crossings:
    """Crossings of a family of lines with the boundary (parallel arrays)."""

    axis: str
    owner: np.ndarray
    segment: np.ndarray
    target: np.ndarray
    theta: np.ndarray
    other: np.ndarray
    low: np.ndarray
    high: np.ndarray
    exact: np.ndarray
    change: np.ndarray = None

    _FIELDS = ("owner", "segment", "target", "theta", "other", "low", "high", "exact", "change")

    def take(self, index):
        return _Crossings(self.axis, *(None if getattr(self, f) is None else getattr(self, f)[index]
                                       for f in self._FIELDS))

    def join(self, more):
        return _Crossings(self.axis, *(np.concatenate([getattr(self, f), getattr(more, f)])
                                       for f in self._FIELDS[:-1]))

    def alpha_beta(self):
        """(alpha, beta) of each crossing."""
        return (self.other, self.target) if self.axis == "beta" else (self.target, self.other)


class StabilityRegion:
    """The stable set of one ``(gamma, d, delta)`` in the (beta, alpha) plane.

    On a line ``beta = b`` (or ``alpha = a``) the number N of roots outside
    the unit circle changes only where the line crosses the boundary: by 2
    on the arc (a pair of roots), by 1 on z = 1 and z = -1, with the sign
    of the radial velocity of the crossing root, ``-Re(conj(z) chi_s /
    chi'(z))``.  At the ends of the line N is known in closed form (see
    :meth:`_end_counts`), so N in every gap between crossings follows by
    counting, with no classification and no probe next to the boundary; the
    stable gaps are those with N = 0.  Each line is checked: the count from
    one end must arrive at the other end's value and never go below 0.  A
    line that fails the check (a crossing whose direction rounding cannot
    tell, at a corner or a tangency) is decided gap by gap with
    :func:`symstab.numeric.stability.classify` instead.

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

    def __repr__(self):
        return f"StabilityRegion(gamma={self.gamma:g}, d={self.d}, delta={self.delta:g})"

    def __init__(self, *, gamma, d, delta):
        self.gamma, self.d, self.delta = check_loop(gamma, d, delta)
        self.minus_one = minus_one_line(gamma=self.gamma, d=self.d, delta=self.delta)
        self._structured = _structured_basis(self.gamma, self.d, self.delta)

    # The sampled arc, taken on first use: the limits (the one engine's)
    # do not need it, only the line questions do.

    @functools.cached_property
    def _samples(self):
        """``(theta, alpha, beta, segments)`` of the sampled arc (see :meth:`_sample`)."""
        return self._sample()

    _theta = property(lambda self: self._samples[0])
    _alpha = property(lambda self: self._samples[1])
    _beta = property(lambda self: self._samples[2])
    _segments = property(lambda self: self._samples[3])

    def _sample(self):
        """The arc on the scan grid, with its extrema and a few ulps either side of each pole."""
        theta = np.concatenate([[0.0], scan_grid(self.d, upper=np.pi * (1 - 1e-9))])
        theta = np.union1d(theta, self._extrema(theta))
        poles = self._poles(theta)
        # Samples a few ulps either side of each pole: every other segment
        # is then monotone in alpha and in beta, so a crossing lies between
        # its segment's ends, without root-finding.
        theta = np.union1d(theta, np.concatenate([poles - 4 * np.spacing(poles),
                                                  poles + 4 * np.spacing(poles)]))
        alpha, beta = kernels.boundary(theta, self.gamma, self.d, self.delta)
        alpha[0], beta[0] = 0.0, -self.delta
        finite = np.isfinite(alpha) & np.isfinite(beta)
        segment = finite[:-1] & finite[1:]
        segment[np.searchsorted(theta, poles) - 1] = False
        return theta, alpha, beta, np.flatnonzero(segment)

    def decomposition(self, x_range, y_range):
        """The complete D-decomposition of a window of the (beta, alpha) plane.

        Every branch of eq. (7) over all of (0, pi) -- not only the first
        arc, up to theta_max --, the z = 1 line (alpha = 0) and the z = -1
        line, the cells they cut the window into and each cell's certified
        count of unstable roots (:func:`symstab.numeric.decomposition.decompose`).

        Parameters
        ----------
        x_range : (float, float)
            The window's beta, ``lo < hi``.
        y_range : (float, float)
            The window's alpha, ``lo < hi``.

        Returns
        -------
        symstab.numeric.decomposition.Decomposition
            With ``x = "beta"``, ``y = "alpha"``.

        Examples
        --------
        >>> r = StabilityRegion(gamma=0.0, d=10, delta=0.00253125)
        >>> cells = r.decomposition((-0.05, 0.2), (-0.001, 0.0062)).cells
        >>> sorted(cell.count for cell in cells)
        [0, 1, 2, 3]
        """
        x_range = check_window("x_range", x_range)
        y_range = check_window("y_range", y_range)
        coefficients = [loop_coefficients(alpha=a, beta=b, gamma=self.gamma, d=self.d,
                                          delta=self.delta)
                        for a, b in ((0.0, 0.0), (0.0, 1.0), (1.0, 0.0))]
        base = coefficients[0]
        ax, ay = coefficients[1] - base, coefficients[2] - base
        signs = (-1.0) ** np.arange(len(base) - 1, -1, -1)
        ends = []
        for c in (base, ax, ay):
            # chi(+-1): a sum below its own rounding is 0 (alpha = 0 is exactly z = 1).
            values = np.array([np.sum(c), np.sum(c * signs)])
            values[np.abs(values) <= 64 * np.finfo(float).eps * np.sum(np.abs(c))] = 0.0
            ends.append(values)
        # The paper's arc source is its closed form (the generated kernel).
        arc = ClosedFormArc(gamma=self.gamma, d=self.d, delta=self.delta)
        return decompose(base, ax, ay, ends, x_range=x_range, y_range=y_range,
                         names=("beta", "alpha"), arc=arc)

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
                out.append(golden_max(lambda t, k=index, s=sign: s * kernels.boundary(
                    t, self.gamma, self.d, self.delta)[k], theta[i - 1], theta[i + 1]))
        return np.concatenate(out) if out else np.empty(0)

    def _poles(self, theta):
        """Angles where the arc goes to infinity (alpha and beta change sign there)."""
        beta = kernels.boundary(theta, self.gamma, self.d, self.delta)[1]
        s = np.flatnonzero(np.isfinite(beta[:-1]) & np.isfinite(beta[1:])
                           & (beta[:-1] * beta[1:] < 0))
        if s.size == 0:
            return np.empty(0)
        root = bracketed_root(lambda t, i: kernels.boundary(t, self.gamma, self.d, self.delta)[1],
                              theta[s], theta[s + 1], indexed=True)
        value = np.abs(kernels.boundary(root, self.gamma, self.d, self.delta)[1])
        pole = ~np.isfinite(value) | (value > np.maximum(np.abs(beta[s]), np.abs(beta[s + 1])))
        return root[pole]

    # -- crossings of the boundary with a family of lines -----------------

    def _arc_point(self, theta):
        return kernels.boundary(theta, self.gamma, self.d, self.delta)

    def _arc_crossings(self, axis, values, precise=True):
        """Arc points where ``axis`` (``"beta"`` or ``"alpha"``) equals each value.

        Returns a :class:`_Crossings`: for every crossing the index into
        ``values``, its arc segment, angle and other coordinate.  Each arc
        segment is half-open, so a value met exactly at a sample is found
        once.  Without ``precise`` the angle and the other coordinate are
        interpolated in the segment, and ``low``/``high`` bound the other
        coordinate (the segments are monotone); :meth:`_refine` settles
        those it is asked to.
        """
        coord = self._beta if axis == "beta" else self._alpha
        other = self._alpha if axis == "beta" else self._beta
        order = np.argsort(values)
        sorted_values = values[order]
        c0, c1 = coord[self._segments], coord[self._segments + 1]
        rising = c1 > c0
        start = np.where(rising, np.searchsorted(sorted_values, c0, "left"),
                         np.searchsorted(sorted_values, c1, "right"))
        stop = np.where(rising, np.searchsorted(sorted_values, c1, "left"),
                        np.searchsorted(sorted_values, c0, "right"))
        stop = np.maximum(stop, start)
        segment, k = _ranges(start, stop)
        segment = self._segments[segment]
        target = sorted_values[k]
        c0, c1 = coord[segment], coord[segment + 1]
        o0, o1 = other[segment], other[segment + 1]
        with np.errstate(divide="ignore", invalid="ignore"):
            frac = np.clip((target - c0) / (c1 - c0), 0.0, 1.0)
        frac = np.where(c0 == target, 0.0, frac)
        t0, t1 = self._theta[segment], self._theta[segment + 1]
        found = _Crossings(axis=axis, owner=order[k], segment=segment, target=target,
                           theta=t0 + frac * (t1 - t0), other=o0 + frac * (o1 - o0),
                           low=np.minimum(o0, o1), high=np.maximum(o0, o1),
                           exact=c0 == target)
        found.other[found.exact] = o0[found.exact]
        found.low[found.exact] = found.high[found.exact] = o0[found.exact]
        if precise:
            self._refine(found, np.flatnonzero(~found.exact))
        return found

    def _refine(self, found, which):
        """Root-find the crossings ``which`` of ``found`` to the last bit (in place)."""
        which = which[~found.exact[which]]
        if which.size == 0:
            return
        index = 1 if found.axis == "beta" else 0
        segment, target = found.segment[which], found.target[which]

        def f(t, i):
            return self._arc_point(t)[index] - target[i]

        root = bracketed_root(f, self._theta[segment], self._theta[segment + 1], indexed=True)
        other = self._arc_point(root)[1 - index]
        other = np.where(root == 0.0, 0.0 if found.axis == "beta" else -self.delta, other)
        found.theta[which], found.other[which] = root, other
        found.low[which] = found.high[which] = other
        found.exact[which] = True

    def _crossing_change(self, axis, theta, alpha, beta):
        """How N (roots outside the circle) changes across each crossing.

        Moving along the line in the increasing direction of its free
        coordinate s (alpha on ``beta = b``, beta on ``alpha = a``):
        :func:`symstab.numeric.arcs.crossing_change`, +-2 on the arc, +-1 at
        z = +-1, and 0 where the radial velocity is lost in rounding (a
        tangency or a corner).
        """
        base, d_alpha, d_beta = self._structured
        chi = base.combine([np.asarray(alpha, dtype=float), np.asarray(beta, dtype=float)],
                           [d_alpha, d_beta])
        change = crossing_change(chi, d_alpha if axis == "beta" else d_beta, theta)
        return np.where(np.isnan(change), 0.0, change)

    def _cuts(self, axis, values, precise=True):
        """Every crossing of the boundary with the lines ``axis = value``.

        Returns ``(owner, position, change)`` sorted by line and position:
        the line's index, the free coordinate of the crossing and the change
        of N across it (:meth:`_crossing_change`).
        """
        cuts = self._all_cuts(axis, values, precise)
        return cuts.owner, cuts.other, cuts.change

    def _all_cuts(self, axis, values, precise):
        """The crossings with the arc (:meth:`_arc_crossings`) and with z = +-1, sorted."""
        found = self._arc_crossings(axis, values, precise)
        # The arc's start (theta = 0) is the corner with z = 1, counted there.
        found = found.take(found.theta > 0)
        lines = np.arange(len(values))
        if axis == "beta":
            extra = [(np.zeros(len(values)), 0.0), (self.minus_one - 2 * values, np.pi)]
        else:
            extra = [((self.minus_one - values) / 2, np.pi)]
        for position, theta in extra:
            keep = np.isfinite(position)
            n = int(keep.sum())
            found = found.join(_Crossings(
                axis=axis, owner=lines[keep], segment=np.full(n, -1), target=values[keep],
                theta=np.full(n, theta), other=position[keep], low=position[keep],
                high=position[keep], exact=np.ones(n, dtype=bool)))
        found = found.take(np.lexsort((found.other, found.owner)))
        found.change = self._crossing_change(axis, found.theta, *found.alpha_beta())
        return found

    def _end_counts(self, axis, values):
        """N at the low and the high end of each line (closed form).

        For |alpha| -> infinity on ``beta = b``, d + 1 roots go to infinity
        and the other three tend to 0, 0 and ``-zoh_b0 / zoh_b1`` (inside:
        ``0 < zoh_b0 < zoh_b1`` for delta > 0), so N = d + 1 at both ends.
        For |beta| -> infinity on ``alpha = a``, d + 1 roots go to infinity
        and the others tend to 0, ``-zoh_b0 / zoh_b1`` and
        ``1 - a / beta``: N = d + 1 at the end where ``a / beta > 0`` and
        d + 2 at the other.  On ``alpha = 0`` z = 1 is a root everywhere:
        the line is marginal (ends ``-1``, matched by nothing).

        For delta = 0, ``zoh_b0 = zoh_b1`` and the third root tends to -1
        itself: ``z + 1 ~ -8 (-1)**d / alpha`` on a vertical line and
        ``-4 (-1)**d / beta`` on a horizontal one (chi(-1) = 4 (-1)**d), one
        more root outside at one end (checked against 50-digit roots).
        """
        n = np.full(len(values), self.d + 1)
        even = self.d % 2 == 0
        if axis == "beta":
            if self.delta == 0:
                return n + (not even), n + even
            return n, n
        low = np.where(values > 0, self.d + 2, self.d + 1)
        high = np.where(values > 0, self.d + 1, self.d + 2)
        if self.delta == 0:
            low, high = low + (not even), high + even
        low[values == 0] = -1
        return low, high

    def _line_chunks(self, axis, values):
        """Slices of ``values`` whose crossings fit in :data:`CHUNK_BYTES` together.

        Most lines cross the boundary about d + 2 times, but a line along
        which the arc keeps returning (alpha = 0 itself) crosses it up to
        once per segment, so the crossings are counted first (O(segments)).
        """
        if len(values) == 0:
            return []
        coord = self._beta if axis == "beta" else self._alpha
        order = np.argsort(values)
        c0, c1 = coord[self._segments], coord[self._segments + 1]
        rising = c1 > c0
        start = np.where(rising, np.searchsorted(values[order], c0, "left"),
                         np.searchsorted(values[order], c1, "right"))
        stop = np.maximum(start, np.where(rising, np.searchsorted(values[order], c1, "left"),
                                          np.searchsorted(values[order], c0, "right")))
        step = np.zeros(len(values) + 1)
        np.add.at(step, start, 1)
        np.add.at(step, stop, -1)
        per_line = np.empty(len(values))
        per_line[order] = np.cumsum(step)[:-1]
        weight = _BYTES_PER_CROSSING * (per_line + 3)
        chunks, begin, total = [], 0, 0.0
        for i, w in enumerate(weight):
            if i > begin and total + w > CHUNK_BYTES:
                chunks.append(slice(begin, i))
                begin, total = i, 0.0
            total += w
        chunks.append(slice(begin, len(values)))
        return chunks

    def _counted_runs(self, axis, values):
        """Stable intervals on each line by counting; ``None`` where the check fails.

        The crossings start as estimates bounded by their arc segments;
        those whose bounds overlap a neighbour's (their order is in doubt)
        and those that end an interval with N = 0 are root-found, until
        none is left in doubt.
        """
        out = [None] * len(values)
        for part in self._line_chunks(axis, values):
            chunk = values[part]
            cuts = self._all_cuts(axis, chunk, precise=False)
            low, high = self._end_counts(axis, chunk)
            for _ in range(8):
                above, bad = _count(cuts.owner, cuts.change, low, high, len(chunk))
                # Pairs of neighbours on one line: in doubt when their bounds
                # overlap, or when they end an interval with N = 0.
                pair = (cuts.owner[1:] == cuts.owner[:-1]) & (
                    (cuts.high[:-1] >= cuts.low[1:]) | (above[:-1] == 0))
                doubt = np.zeros(len(cuts.owner), dtype=bool)
                doubt[:-1] |= pair
                doubt[1:] |= pair
                doubt &= ~cuts.exact
                if not doubt.any():
                    break
                which = np.flatnonzero(doubt)
                self._refine(cuts, which)
                cuts.change[which] = self._crossing_change(
                    axis, cuts.theta[which], *(x[which] for x in cuts.alpha_beta()))
                cuts = cuts.take(np.lexsort((cuts.other, cuts.owner)))
            else:
                bad[:] = True
            for i in np.flatnonzero(~bad):
                out[part.start + i] = []
            same = np.zeros(len(cuts.owner), dtype=bool)
            same[:-1] = cuts.owner[1:] == cuts.owner[:-1]
            for j in np.flatnonzero((above == 0) & same):
                runs = out[part.start + cuts.owner[j]]
                if runs is not None and cuts.other[j + 1] > cuts.other[j]:
                    runs.append((float(cuts.other[j]), float(cuts.other[j + 1])))
        return out

    def _classified_runs(self, axis, values, closure):
        """Stable intervals on each line by one classification per gap (the fallback).

        With ``closure``, gaps whose probe is marginal count too (the
        searches for the extent of the region run into corners, where the
        gaps are too short for the classification to tell).
        """
        owner, cuts, _ = self._cuts(axis, values)  # precise: the probes go between them
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

    def _intervals(self, axis, values, closure=False, confirm=False, fallback=True):
        """Stable intervals of the other coordinate on each line ``axis = value``.

        By counting (:meth:`_counted_runs`); lines whose count fails its
        check, and with ``confirm`` lines where the classification of the
        middle of a counted interval disagrees, are decided gap by gap
        (:meth:`_classified_runs`), or left ``None`` without ``fallback``.
        """
        values = np.atleast_1d(np.asarray(values, dtype=float))
        runs = self._counted_runs(axis, values)
        if confirm:
            owner = np.array([i for i, r in enumerate(runs) if r for _ in r], dtype=int)
            middle = np.array([0.5 * (lo + hi) for r in runs if r for lo, hi in r])
            if owner.size:
                on_line = values[owner]
                alpha, beta = (middle, on_line) if axis == "beta" else (on_line, middle)
                # The float Schur-Cohn verdict (refine=False) is enough here:
                # "stable" keeps the counted interval, and "unstable" only
                # sends the line to the gap-by-gap classification, which
                # certifies its verdicts; a wrong verdict can cost time but
                # not change the answer.  (At large d every point has roots
                # within 1e-6 of the circle, and certifying one costs seconds.)
                code = np.atleast_1d(classify(alpha=alpha, beta=beta, gamma=self.gamma,
                                              d=self.d, delta=self.delta, refine=False))
                for i in owner[code == UNSTABLE]:
                    runs[i] = None
        redo = [i for i, r in enumerate(runs) if r is None]
        if redo and fallback:
            for i, r in zip(redo, self._classified_runs(axis, values[redo], closure)):
                runs[i] = r
        return runs

    def alpha_intervals(self, beta):
        """The stable alpha intervals at damping ``beta``.

        Each interval found by counting is checked by one Schur-Cohn test
        (:func:`symstab.numeric.stability.classify`) of its middle; a line where they
        disagree is classified gap by gap.

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
        return self._intervals("beta", [check_real("beta", beta)], confirm=True)[0]

    def beta_intervals(self, alpha):
        """The stable beta intervals at stiffness ``alpha`` (as :meth:`alpha_intervals`).

        Parameters
        ----------
        alpha : float
            Dimensionless stiffness.
        """
        return self._intervals("alpha", [check_real("alpha", alpha)], confirm=True)[0]

    def alpha_intervals_on(self, betas):
        """The stable alpha intervals on many vertical lines at once.

        The same intervals as :meth:`alpha_intervals` at each ``beta``, with
        the crossings of all lines found and counted together: tens of times
        faster than a loop over the lines when there are many.

        Parameters
        ----------
        betas : array_like of float
            Dimensionless dampings, one line each (a 1-D sequence).

        Returns
        -------
        list of list of (float, float)
            For each line, as :meth:`alpha_intervals` returns it.

        Raises
        ------
        TypeError, ValueError
            For a non-real or non-finite ``beta``, or ``betas`` that is not
            one-dimensional.
        """
        values = check_array("betas", betas)
        if values.ndim != 1:
            raise ValueError(f"betas must be a one-dimensional sequence, got shape {values.shape}")
        return self._intervals("beta", values, confirm=True)

    # -- where the region is ----------------------------------------------

    @functools.cached_property
    def _limits(self):
        """The limits of this region, from the one engine (:func:`~symstab.numeric.paper_loop.paper_limits`)."""
        return paper_limits(gamma=self.gamma, d=self.d, delta=self.delta, region=self)

    def _corners(self):
        """beta of the points where the arc meets alpha = 0 (exact corners)."""
        ends = self._arc_crossings("alpha", np.array([0.0])).other
        return np.sort(np.concatenate([ends, [-self.delta]]))

    def line_segments(self):
        """The pieces of z = 1 (alpha = 0) and z = -1 that bound the stable region.

        Along each line the corners (where the arc or the other line meets
        it) cut it into pieces; one vertical line through the middle of a
        piece tells whether the region borders it.

        Returns
        -------
        tuple of :class:`symstab.numeric.curves.Segment`
        """
        extent = self.beta_range()
        if extent is None:
            return ()
        c = self.minus_one
        out = []

        def within(ends):
            # Only pieces inside the region's beta range can border it (at
            # large d the arc meets alpha = 0 thousands of times elsewhere).
            # The searches for the extremes may stop an ulp-scale step short
            # of a corner: a corner that close stands for the extreme.
            tol = 1e-9 * (extent[1] - extent[0])
            ends = ends[(ends >= extent[0] - tol) & (ends <= extent[1] + tol)]
            extra = [b for b in extent if math.isfinite(b)
                     and (ends.size == 0 or np.min(np.abs(ends - b)) > tol)]
            return np.union1d(ends, extra)

        # z = 1: alpha = 0; the region borders a piece when a stable interval
        # of the vertical line through its middle starts or ends at 0.
        ends = self._corners()
        if math.isfinite(c):
            ends = np.union1d(ends, [c / 2])
        out += self._bordering_pieces("z=1", within(ends), lambda b: 0.0)
        if math.isfinite(c):
            # z = -1: alpha + 2 beta = c, cut where the arc crosses it and at alpha = 0.
            ends = np.union1d(self._arc_roots(lambda a, b: a + 2 * b - c), [c / 2])
            out += self._bordering_pieces("z=-1", within(ends), lambda b: c - 2 * b)
        return tuple(out)

    def _bordering_pieces(self, root, ends, line_alpha):
        """Segments of a line (alpha = line_alpha(beta)) between consecutive ``ends``
        that border the stable region, merged where they meet."""
        ends = ends[np.isfinite(ends)]
        if ends.size < 2:
            return []
        middle = 0.5 * (ends[1:] + ends[:-1])
        runs = self._intervals("beta", middle)
        out = []
        for b0, b1, bm, r in zip(ends[:-1], ends[1:], middle, runs):
            a = line_alpha(bm)
            if b1 > b0 and any(lo == a or hi == a for lo, hi in r):
                if out and out[-1][1] == b0:
                    out[-1] = (out[-1][0], b1)
                else:
                    out.append((b0, b1))
        return [Segment(root, float(b0), float(line_alpha(b0)), float(b1), float(line_alpha(b1)))
                for b0, b1 in out]

    def _arc_roots(self, g):
        """beta of the arc points where ``g(alpha, beta)`` changes sign (poles left out)."""
        s = self._segments
        g0 = g(self._alpha[s], self._beta[s])
        g1 = g(self._alpha[s + 1], self._beta[s + 1])
        change = np.sign(g0) != np.sign(g1)
        s, g0, g1 = s[change], g0[change], g1[change]
        if s.size == 0:
            return np.empty(0)
        root = bracketed_root(lambda t: g(*self._arc_point(t)), self._theta[s], self._theta[s + 1])
        a, b = self._arc_point(root)
        residual = np.abs(g(a, b))
        return b[np.isfinite(residual) & (residual <= np.maximum(np.abs(g0), np.abs(g1)))]

    def alpha_max(self):
        """``(alpha_max, beta at alpha_max)``, or ``None`` when the region is empty (see :meth:`limits`)."""
        lim = self._limits
        return None if lim.empty else (lim.y_max, lim.x_at_y_max)

    def beta_range(self):
        """``(beta_min, beta_max)`` of the stable region, or ``None`` when it is empty (see :meth:`limits`)."""
        lim = self._limits
        return None if lim.empty else (lim.x_min, lim.x_max)

    def limits(self, *, n_beta=None):
        """alpha_max, the beta range and the Z-width (see :func:`limits`).

        Parameters
        ----------
        n_beta : None
            Deprecated and ignored: the Z-width is the area of the stable
            polygons, not an integral over ``n_beta`` vertical lines.
        """
        _deprecated_n_beta(n_beta)
        return self._limits


def _deprecated_n_beta(n_beta):
    if n_beta is not None:
        check_count("n_beta", n_beta, 3)    # still refused as before, while it is deprecated
        warnings.warn("n_beta is deprecated and ignored: the Z-width is now the area of the "
                      "stable polygons of the D-decomposition (no line integration)",
                      DeprecationWarning, stacklevel=3)


def limits(*, gamma, d, delta, n_beta=None):
    """Renderable limits of one virtual mass, delay and device.

    The paper's loop in Table I's plane, on the engine of every loop
    (:meth:`symstab.Loop.limits`, :func:`~symstab.numeric.paper_loop.paper_limits`):
    the stable cells of the D-decomposition of the (beta, alpha) plane, their
    extreme vertices (refined along the arc) and the area of their polygons.

    Parameters
    ----------
    gamma : float
        ``M_w / m``.
    d : int
        Delay in samples, ``d >= 0``.
    delta : float
        ``b T / m > 0``.
    n_beta : None
        Deprecated and ignored (the Z-width was a trapezoid rule over
        ``n_beta`` vertical lines; it is now the polygons' area).

    Returns
    -------
    Limits
        Empty (``alpha_max is None``, ``z_width == 0``, with a message) when
        no point is stable.

    Examples
    --------
    >>> lim = limits(gamma=0.0, d=0, delta=0.00253125)
    >>> round(lim.alpha_max, 4), round(lim.beta_right, 4)
    (0.6897, 2.0034)
    >>> lim  # doctest: +ELLIPSIS
    Limits(gamma=0, d=0, delta=0.00253125: alpha_max=0.68967 at beta=0.827933, beta from ...)
    """
    _deprecated_n_beta(n_beta)
    return StabilityRegion(gamma=gamma, d=d, delta=delta).limits()


def vanishing_gamma(*, d, delta, inside, outside, tol=5e-5):
    """Where the stable region vanishes along gamma: ``(last gamma with a region, first without)``.

    Bisection between ``inside`` (a gamma with a stable region) and
    ``outside`` (one without) on the certified emptiness of :func:`limits`,
    until the two are ``tol`` apart.  Next to the vanishing point the set
    can be too small to decide (alpha_max below about 1e-12, where two
    roots meet at z = 1, and the engine refuses): such a gamma moves neither
    end, and the search goes on between it and ``outside``.  The bracket
    returned is a pair the engine decided, wider than ``tol`` when the
    search ran into such gammas; an "empty" next to the vanishing point can
    be a sliver thinner than the engine resolves (:meth:`symstab.Loop.limits`
    says so in its reason).

    Parameters
    ----------
    d : int
        Delay in samples.
    delta : float
        ``b T / m``.
    inside, outside : float
        The two ends; either may be the larger.
    tol : float
        Width of the bracket to stop at, > 0.

    Returns
    -------
    (float, float)
        ``(inside, outside)``, moved towards each other.

    Raises
    ------
    ValueError
        If ``inside`` has no stable region or ``outside`` has one.

    Examples
    --------
    A region exists while gamma > -1 - (d + 1) delta:

    >>> lo, hi = vanishing_gamma(d=0, delta=0.00253125, inside=-0.5, outside=-1.5, tol=1e-3)
    >>> hi <= -1.00253125 <= lo
    True
    """
    _, d, delta = check_loop(0.0, d, delta)
    inside, outside = check_real("inside", inside), check_real("outside", outside)
    tol = check_real("tol", tol, low=0.0, low_open=True)
    if limits(gamma=inside, d=d, delta=delta).empty:
        raise ValueError(f"inside = {inside!r} must be a gamma with a stable region (d = {d})")
    if not limits(gamma=outside, d=d, delta=delta).empty:
        raise ValueError(f"outside = {outside!r} must be a gamma without a stable region (d = {d})")
    probe = inside
    while abs(outside - inside) > tol and abs(outside - probe) > tol:
        middle = 0.5 * (probe + outside)
        try:
            empty = limits(gamma=middle, d=d, delta=delta).empty
        except ValueError:
            probe = middle
            continue
        if empty:
            outside = middle
        else:
            inside = probe = middle
    return inside, outside


@dataclasses.dataclass(frozen=True)
class BestVirtualMass:
    """The virtual mass that maximises the renderable stiffness.

    Attributes
    ----------
    d : int
        Delay in samples.
    delta : float
        ``b T / m``.
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
    lim = paper_limits(gamma=gamma, d=d, delta=delta)
    return (-math.inf, math.nan) if lim.empty else (lim.y_max, lim.x_at_y_max)


def _check_gamma_range(gamma_range):
    """``(low, high)``: two finite reals with ``low < high``."""
    if isinstance(gamma_range, (str, bytes)) or not isinstance(gamma_range, collections.abc.Sequence) \
            and not isinstance(gamma_range, np.ndarray):
        raise TypeError(f"gamma_range must be a pair (low, high) of real numbers, "
                        f"got {type(gamma_range).__name__}")
    if len(gamma_range) != 2:
        raise ValueError(f"gamma_range must be a pair (low, high) of real numbers, "
                         f"got {len(gamma_range)} item(s): {gamma_range!r}")
    low = check_real("gamma_range[0]", gamma_range[0])
    high = check_real("gamma_range[1]", gamma_range[1])
    if not low < high:
        raise ValueError(f"gamma_range must be a pair (low, high) with low < high, got {gamma_range!r}")
    return low, high


def scan_maximum(f, low, high, n=17, *, rtol=1e-6, scale=1.0):
    """The x of [low, high] that maximises a scalar f: a scan, then golden section.

    ``f`` is evaluated on ``n`` evenly spaced points of ``[low, high]``; the
    best scan point is refined by a golden-section search between its
    neighbours until the bracket is narrower than ``rtol * max(scale, |x|)``.
    The search of :func:`best_virtual_mass` (over gamma, ``scale = 1``) and
    of ``symstab design --loop`` (over a loop's parameter, ``scale`` its
    reference value): one routine.

    Parameters
    ----------
    f : callable
        ``f(x) -> float``; ``-inf`` (or NaN) where there is nothing to
        maximise (no stable region at x).
    low, high : float
        The interval searched, ``low < high``.
    n : int
        Points of the scan, ``n >= 3``.
    rtol : float
        Relative width of the final bracket, ``> 0``.
    scale : float
        The size of x below which ``rtol`` is taken absolute (times
        ``scale``), ``> 0``.

    Returns
    -------
    (float, float) or None
        ``(x, f(x))`` at the best point seen (scan or search), or None when
        ``f`` is not finite at any scan point.

    Raises
    ------
    ValueError
        For ``low >= high``, ``n < 3`` or a non-positive ``rtol`` or ``scale``.

    Examples
    --------
    >>> x, value = scan_maximum(lambda x: -(x - 0.3)**2, 0.0, 1.0)
    >>> round(x, 5), value <= 0
    (0.3, True)
    """
    low, high = check_real("low", low), check_real("high", high)
    if not low < high:
        raise ValueError(f"the interval searched must have low < high, got [{low!r}, {high!r}]")
    n = check_count("n", n, 3)
    for name, value in (("rtol", rtol), ("scale", scale)):
        if not (check_real(name, value) > 0):
            raise ValueError(f"{name} must be a real number > 0, got {value!r}")
    xs = np.linspace(low, high, n)
    values = [f(x) for x in xs]
    if not np.isfinite(values).any():
        return None
    k = int(np.nanargmax(np.where(np.isnan(values), -np.inf, values)))
    a, b = xs[max(k - 1, 0)], xs[min(k + 1, n - 1)]
    ratio = (math.sqrt(5) - 1) / 2
    x1, x2 = b - ratio * (b - a), a + ratio * (b - a)
    f1, f2 = f(x1), f(x2)
    while b - a > rtol * max(scale, abs(a)):
        if f1 < f2:
            a, x1, f1 = x1, x2, f2
            x2 = a + ratio * (b - a)
            f2 = f(x2)
        else:
            b, x2, f2 = x2, x1, f1
            x1 = b - ratio * (b - a)
            f1 = f(x1)
    # The best point seen: at the edge where the region vanishes the middle
    # of the last bracket may already have no region.
    candidates = [(value, x) for value, x in ((values[k], xs[k]), (f1, x1), (f2, x2))
                  if not math.isnan(value)]
    value, x = max(candidates)
    return float(x), float(value)


def best_virtual_mass(*, d, delta, gamma_range=None, n=17):
    """The gamma (and beta) that maximise alpha_max, and the gain over gamma = 0.

    alpha_max(gamma) is scanned on ``n`` points of ``gamma_range`` (default
    from just above ``-1 - (d + 1) delta``, below which no arc exists, to 3)
    and the best scan point is refined by a golden-section search between
    its neighbours, to 1e-6 in gamma.

    Parameters
    ----------
    d : int
        Delay in samples, ``d >= 0``.
    delta : float
        ``b T / m > 0``.
    gamma_range : (float, float), optional
        ``(low, high)``, finite, ``low < high``: the gammas scanned.
    n : int
        Points of the scan, ``n >= 3``.

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
    n = check_count("n", n, 3)
    if gamma_range is None:
        gamma_range = (-1.0 - (d + 1) * delta + 1e-3, 3.0)
    g_lo, g_hi = _check_gamma_range(gamma_range)
    found = scan_maximum(lambda g: _alpha_max(g, d, delta)[0], g_lo, g_hi, n)
    if found is None:
        return BestVirtualMass(d, delta, None, None, None, None, None, 0.0,
                               f"no gamma in [{g_lo:g}, {g_hi:g}] has a stable region at d = {d}")
    best_gamma, _ = found
    region = StabilityRegion(gamma=best_gamma, d=d, delta=delta)
    best = region.limits()
    alpha_zero = _alpha_max(0.0, d, delta)[0]
    return BestVirtualMass(d, delta, float(best_gamma), best.beta_at_alpha_max, best.alpha_max,
                           float(alpha_zero), float(best.alpha_max / alpha_zero), best.z_width)


def boundary_curve(*, gamma, d, delta, n=1000, segments=True):
    """Sample the boundary arc from theta = 0 to theta_max.

    Parameters
    ----------
    gamma : float
        ``M_w / m``.
    d : int
        Delay in samples, ``d >= 0``.
    delta : float
        ``b T / m > 0``.
    n : int
        Number of points on the arc, ``n >= 2``; about 24 bytes each are
        kept, so ``n`` is limited by the memory limit
        (:mod:`symstab._resources`, ``SYMSTAB_MEMORY_LIMIT``).
    segments : bool
        Also find the straight pieces (z = +-1) that bound the stable region
        (a stability scan; skip it when only the arc is wanted).

    Returns
    -------
    symstab.numeric.results.Boundary
        In the paper's plane: ``alpha`` and ``beta`` (aliases of
        ``y_values`` and ``x_values``), ``theta_max``, ``segments``.

    Raises
    ------
    TypeError, ValueError
        For a non-real, non-finite or out-of-range parameter, and
        ValueError for an ``n`` whose arrays would exceed the memory limit.

    Examples
    --------
    >>> c = boundary_curve(gamma=0.0, d=0, delta=0.00253125, n=5, segments=False)
    >>> float(c.alpha[0]), round(float(c.beta[0]), 8), round(c.theta_max, 4)
    (0.0, -0.00253125, 1.5725)
    """
    gamma, d, delta = check_loop(gamma, d, delta)
    n = check_count("n", n, 2)
    # theta, alpha and beta are kept; the kernel's temporaries are chunked.
    check_memory(f"boundary_curve with n = {n} points", 3 * 8 * n + KERNEL_CHUNK_BYTES)
    t_end = arc_end_angle(gamma=gamma, d=d, delta=delta)
    at = {"gamma": gamma, "d": d, "delta": delta}
    # c0 + c_beta beta + c_alpha alpha = 0: z = 1 is alpha = 0, z = -1 is alpha + 2 beta = c.
    lines = {"z = 1": (0.0, 0.0, 1.0)}
    c = minus_one_line(gamma=gamma, d=d, delta=delta)
    if math.isfinite(c):
        lines["z = -1"] = (-c, 2.0, 1.0)
    if not np.isfinite(t_end):
        empty = np.empty(0)
        return Boundary(*PAPER_PLANE, empty, empty, empty, lines=lines, theta_max=t_end,
                        reason="no boundary arc: alpha < 0 just after theta = 0, so the arc "
                               "never enters alpha > 0 (1 + gamma + (d + 1) delta <= 0 or close "
                               "to it)", at=at)
    theta = np.linspace(0.0, t_end, n)
    alpha, beta = np.empty(n), np.empty(n)
    for part in chunk_slices(n, KERNEL_BYTES_PER_POINT, KERNEL_CHUNK_BYTES):
        alpha[part], beta[part] = kernels.boundary(theta[part], gamma, d, delta)
    # The ends are exact: the arc starts at (-delta, 0) and ends on alpha = 0.
    alpha[0], beta[0] = 0.0, -delta
    if t_end < np.pi:
        alpha[-1] = 0.0
    pieces = ()
    if segments:
        pieces = StabilityRegion(gamma=gamma, d=d, delta=delta).line_segments()
    return Boundary(*PAPER_PLANE, theta, beta, alpha, lines=lines, segments=pieces, theta_max=t_end,
                    at=at)
