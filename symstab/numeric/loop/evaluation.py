"""A loop's characteristic polynomial in floats: :class:`LoopEvaluation`.

Every :class:`symstab.Loop` holds one (:attr:`symstab.Loop.evaluation`): the
loop keeps the model (its symbols, plant, environment, derivation and
kernels), this object turns values of its parameters into numbers.  The
plant's pulse transfer function is evaluated at 30 digits for each distinct
set of plant values and rounded once; the environment's polynomials come
from the loop's generated NumPy kernel; their products give

    chi(z) = z**d Ve_d(z) P_d(z) + Ve_n(z) P_n(z)

as a :class:`~symstab.numeric.engine.polynomial.DelayedPolynomial`, its
slope in an affine parameter, its values at ``z = +-1``, its exact parts
for the arc, the difference equations the simulator runs and the state
spaces friction acts in.  The questions asked of ``chi`` at points
(:func:`classify`, :func:`is_stable`, :func:`spectral_radius`,
:func:`unstable_root_counts`) and the difference equations are functions of
the loop here, which its methods of the same names pass through to.

May import what :mod:`symstab.numeric.loop` may: the base layer,
``symbolic``, ``codegen`` and :mod:`symstab.numeric.engine`.
"""

import fractions

import mpmath
import numpy as np
import sympy as sp

from ..._memo import method_cache
from ..._resources import check_memory
from ..._validate import check_array, split_delay
from ...symbolic.loop_assembly import FRACTION as FRACTION_SYMBOL
from ...symbolic.loop_assembly import PLANT_DIGITS, shift_to_one
from ..engine import roots
from ..engine.arcs import END_ANGLE, EXACT_TERMS, ClosedFormArc, CramerArc, ExactPolynomial
from ..engine.polynomial import DelayedPolynomial

__all__ = ["LoopEvaluation", "FRACTION", "finite", "spectral_radius", "classify", "is_stable",
           "unstable_root_counts", "difference_equations", "difference_parts", "closed_loop"]


#: The key of :meth:`LoopEvaluation.prepare`'s values that holds the fraction
#: ``eps`` of a period of a fractional delay ``(d + eps) T`` (no parameter's name:
#: those are ASCII).  The plant carries it: ``P_eps = N_eps / (z P_d)``.
FRACTION = "ε"


def _exact_product(a, b):
    """The coefficients of the product of two polynomials (rows highest first), as exact Fractions.

    ``a`` holds doubles (each taken as its binary value), ``b`` Fractions.
    """
    out = [fractions.Fraction(0)] * (len(a) + len(b) - 1)
    for i, x in enumerate(a):
        x = fractions.Fraction(float(x))
        for j, y in enumerate(b):
            out[i + j] += x * y
    return tuple(out)


def _shift_to_one(c):
    """Coefficients of ``p(w + 1)`` (``w = z - 1``) from float rows ``c``, with a bound on their rounding.

    Each shifted coefficient is a sum of ``binom(j, k) c_j``; its rounding,
    and the few ulps of the given coefficients, are bounded by a multiple of
    the same sum of ``|c_j|`` (the shift of ``|c|``).
    """
    return (shift_to_one(c, dtype=float),
            (4 * c.shape[-1] + 8) * 2.0**-53 * shift_to_one(np.abs(c), dtype=float))


def _convolve(a, b):
    """The products of the polynomials of the rows of ``a`` and ``b`` (broadcast, highest first)."""
    out = np.zeros(np.broadcast_shapes(a.shape[:-1], b.shape[:-1]) + (a.shape[-1] + b.shape[-1] - 1,))
    for i in range(a.shape[-1]):
        out[..., i:i + b.shape[-1]] += a[..., i, None] * b
    return out


def finite(c, values):
    """``c`` if every row of coefficients is finite and not all 0, else a ValueError naming them.

    Parameters
    ----------
    c : ndarray
        Coefficient rows (last axis).
    values : dict
        The prepared values (:meth:`LoopEvaluation.prepare`), named in the message.

    Returns
    -------
    ndarray
        ``c``.

    Raises
    ------
    ValueError
        Where a row overflowed, or underflowed to nothing.
    """
    # Not finite (overflow), or nothing left (every coefficient underflowed).
    bad = ~np.all(np.isfinite(c), axis=-1) | ~np.any(c != 0, axis=-1)
    if np.any(bad):
        index = np.unravel_index(int(np.flatnonzero(bad.ravel())[0]), bad.shape)
        point = ", ".join(f"{n} = {float(v[index] if v.ndim else v):g}"
                          for n, v in values.items())
        raise ValueError(f"the characteristic polynomial overflows or underflows at {point}: a "
                         f"parameter is too large or too small for double precision")
    return c


class LoopEvaluation:
    """The float evaluation of one loop's ``chi``: what :class:`symstab.Loop` computes on.

    Built by the loop (:attr:`symstab.Loop.evaluation`), which hands it the
    parts of its model that are not public: its plant's 30-digit values, its
    NumPy kernels and its closed forms.

    Its methods share the names of their arguments: ``given`` is a dict of
    values of the loop's parameters, the defaults for the rest (a
    :class:`symstab.Loop` method's ``**values``); ``values``, ``d`` and
    ``shape`` are what :meth:`prepare` makes of it (the values by symbol
    name, the delay, their broadcast shape); ``x, y`` or ``names`` are the
    plane's parameters, and ``given`` then holds single values of the
    others.

    Parameters
    ----------
    loop : symstab.Loop
        The loop (its public parameters, symbols and names).
    plant : callable
        ``plant(plant_values, T, eps)``: ``(P_n, P_d, ends, P_d in z - 1)`` as
        float arrays, monic ``P_d``, evaluated at 30 digits; with a fraction
        ``eps > 0`` of a period of delay, ``(N_eps, z P_d, ...)``.
    exact_plant : callable
        ``exact_plant(plant_values, T, eps)``: ``(P_n, P_d)`` as exact Fractions.
    plant_parts : callable
        ``plant_parts(fraction)``: the symbolic coefficients of ``P_n`` and
        ``P_d`` (not normalised), or with ``fraction`` of ``N_eps`` and ``z
        P_d`` in ``FRACTION``'s symbol.
    kernels : callable
        ``kernels()``: ``(module, names, n_num, n_den)`` of the loop's
        generated NumPy module.
    closed_polynomial : callable, optional
        The loop's ``polynomial`` option (see :class:`symstab.Loop`).
    closed_arc : callable, optional
        The loop's ``arc`` option (see :class:`symstab.Loop`).
    """

    def __init__(self, loop, *, plant, exact_plant, plant_parts, kernels, closed_polynomial=None,
                 closed_arc=None):
        self.loop = loop
        self._plant_at = plant
        self._exact_plant = exact_plant
        self._plant_parts = plant_parts
        self._kernels = kernels
        self._closed_polynomial = closed_polynomial
        self._closed_arc = closed_arc

    def _values(self, given, *, scalar=(), drop=()):
        loop = self.loop
        unknown = set(given) - set(loop.parameters) - {"Td", FRACTION}
        if unknown:
            raise TypeError(f"unknown parameter(s) {', '.join(sorted(unknown))}; "
                            f"parameters of this loop: {', '.join(loop.parameters)} (or Td "
                            f"for d)")
        if "Td" in given and "d" in given:
            raise TypeError("give the delay once: d (in samples) or Td (in seconds), not both")
        values = dict(loop.defaults)
        values.update(given)
        # The delay given wins over the default's other form.
        seconds = values.pop("Td", None) if "d" not in given else None
        if "Td" in given or seconds is not None:
            values.pop("d", None)
        values.pop("Td", None)
        missing = [n for n in loop.parameters if n not in values and n not in drop
                   and not (n == "d" and seconds is not None)]
        if missing:
            raise TypeError(f"missing value(s) for {', '.join(missing)}")
        out = {}
        for name in loop.symbols:
            if name in drop:
                continue
            if name == "T":
                out[name] = check_array("T", values[name], low=0.0, low_open=True)
            else:
                out[name] = check_array(name, values[name])
            if name in scalar and out[name].ndim:
                raise ValueError(f"{name} must be a single value here, got an array of "
                                 f"shape {out[name].shape}")
        d, eps = self._delay(values, seconds, out, drop)
        if eps is not None:
            if "d" in scalar and eps.ndim:
                raise ValueError(f"the delay must be a single value here, got an array of "
                                 f"shape {eps.shape}")
            out[FRACTION] = eps
        return out, d

    @staticmethod
    def _delay(values, seconds, out, drop):
        """``(d, eps)``: the delay's whole samples and fraction (None: whole) of a call's values."""
        if seconds is None:
            d, eps = split_delay(values.pop("d"), name="d")
            if FRACTION in values:
                # Passed on by this class's callers with the whole d: the fraction as it was.
                if eps is not None:
                    raise ValueError("a whole d is needed with a fraction given apart")
                eps = check_array("the delay's fraction", values.pop(FRACTION), low=0.0,
                                  high=1.0)
                eps = eps if np.any(eps != 0) else None
            return d, eps
        if "T" in drop:
            raise ValueError("Td (seconds) needs the sample period's value: with T on an axis, "
                             "give the delay in samples, d")
        with np.errstate(all="ignore"):
            samples = check_array("Td", seconds, low=0.0) / out["T"]
        return split_delay(samples, name="Td / T")

    def prepare(self, given, scalar=(), drop=()):
        """The values of a call checked: ``(values, d, shape)``.

        Parameters
        ----------
        given : dict
            Values of the loop's parameters (defaults for the rest).
        scalar : tuple of str
            Parameters that must be single values.
        drop : tuple of str
            Parameters left out (the plane's, set by the caller).

        Returns
        -------
        (dict of ndarray, int, tuple)
            The values by symbol name (``d`` apart), the delay and the
            broadcast shape.
        """
        values, d = self._values(given, scalar=scalar, drop=drop)
        try:
            shape = np.broadcast_shapes(*[v.shape for v in values.values()])
        except ValueError as exc:
            raise ValueError(f"parameter arrays must broadcast together: {exc}") from None
        return values, d, shape

    def _plant_names(self, values):
        """The names of a point's plant: its parameters, ``T`` and the delay's fraction if it has one."""
        return self.loop.plant_names + ("T",) + ((FRACTION,) if FRACTION in values else ())

    def _plant(self, row, values):
        """:meth:`plant_arrays` of one point's plant (a row in the order of :meth:`_plant_names`)."""
        n = len(self.loop.plant_names)
        eps = float(row[n + 1]) if FRACTION in values else None
        return self._plant_at(tuple(float(v) for v in row[:n]), float(row[n]), eps)

    def _plant_rows(self, values, shape):
        """The distinct rows of the plant's values and ``T`` (and ``eps``), and each point's row."""
        names = self._plant_names(values)
        columns = np.stack([np.broadcast_to(values[n], shape).ravel() for n in names], axis=-1)
        return np.unique(columns, axis=0, return_inverse=True)

    def plant_arrays(self, values, shape):
        """(P_n, P_d, ends, P_d in z - 1) per point, shape ``shape + (k,)``.

        One 30-digit evaluation per distinct row of the plant's values.

        Returns
        -------
        tuple of ndarray
        """
        names = self._plant_names(values)
        if all(np.ndim(values[n]) == 0 for n in names):
            # One plant for every point: the common case of a plane sweep.
            parts = self._plant([values[n] for n in names], values)
            return tuple(np.broadcast_to(part, shape + part.shape) for part in parts)
        unique, inverse = self._plant_rows(values, shape)
        parts = [self._plant(row, values) for row in unique]
        out = []
        for k in range(4):
            part = np.array([p[k] for p in parts])[inverse.ravel()]
            out.append(part.reshape(shape + part.shape[-1:]))
        return tuple(out)

    def environment_arrays(self, values, shape, slope=None):
        """``(Ve_n, Ve_d)`` per point (or their slopes in ``slope``), from the loop's kernel.

        Parameters
        ----------
        slope : str, optional
            A parameter entering the environment affinely.

        Returns
        -------
        (ndarray, ndarray)
            Of shape ``shape + (k,)``, highest power first.
        """
        module, names, n_num, n_den = self._kernels()
        function = module.environment if slope is None else getattr(module, f"environment_slope_{slope}")
        with np.errstate(all="ignore"):
            out = function(*[values[n] for n in names])
        out = [np.broadcast_to(np.asarray(c, dtype=float), shape) for c in out]
        return np.stack(out[:n_num], axis=-1), np.stack(out[n_num:], axis=-1)

    def chi(self, values, d, shape, *, slope=None, plant=None):
        """``chi = z**d Ve_d P_d + Ve_n P_n`` (or its slope in one parameter), structured.

        The delayed part comes also in powers of ``z - 1`` (the plant's at 30
        digits, the environment's shifted in double precision with a bound
        on that rounding), for the root count's accuracy next to ``z = 1``;
        a plant parameter's slope has none.

        Parameters
        ----------
        slope : str, optional
            The parameter whose slope is wanted.
        plant : tuple, optional
            :meth:`plant_arrays` at these values, when the caller has it.

        Returns
        -------
        symstab.numeric.engine.polynomial.DelayedPolynomial
        """
        if plant is None:
            plant = self.plant_arrays(values, shape)
        p_n, p_d, _, p_d_one = plant
        # A power of z that divides Ve_d (the backward differences' 1/z**k)
        # joins the delay: chi = z**(d + k) (Ve_d / z**k) P_d + Ve_n P_n keeps
        # the delayed part short (the paper's z**(d+2) (z - 1)(z - r)).
        k = self.loop.environment_delay
        d = d + k
        if slope is None or slope in self.loop.environment_names:
            ve_n, ve_d = self.environment_arrays(values, shape, slope)
            ve_d = ve_d[..., :ve_d.shape[-1] - k]
            ve_one, ve_error = _shift_to_one(ve_d)
            near_one = (_convolve(ve_one, p_d_one),
                        _convolve(ve_error, np.abs(p_d_one))
                        + 4 * ve_d.shape[-1] * 2.0**-53 * _convolve(np.abs(ve_one),
                                                                    np.abs(p_d_one)))
            return DelayedPolynomial(_convolve(ve_d, p_d), _convolve(ve_n, p_n), d,
                                     near_one=near_one)
        # A plant parameter: the slope of P_n, P_d (30 digits) by the exact
        # derivative of their symbolic coefficients.
        ve_n, ve_d = self.environment_arrays(values, shape)
        ve_d = ve_d[..., :ve_d.shape[-1] - k]
        dp_n, dp_d = self._plant_slope(values, shape, slope)
        return DelayedPolynomial(_convolve(ve_d, dp_d), _convolve(ve_n, dp_n), d)

    def _end_values(self, values, d, shape, *, slope=None, plant):
        """``chi(1)`` and ``chi(-1)`` (or their slopes), from the plant's 30-digit end values."""
        ends = plant[2]
        if slope is not None and slope not in self.loop.environment_names:
            dense = self.chi(values, d, shape, slope=slope, plant=plant).dense()
            return np.stack([np.sum(dense, axis=-1),
                             np.sum(dense * (-1.0) ** np.arange(dense.shape[-1] - 1, -1, -1), axis=-1)],
                            axis=-1)
        ve_n, ve_d = self.environment_arrays(values, shape, slope)

        def at(c, sign):
            return np.sum(c * sign ** np.arange(c.shape[-1] - 1, -1, -1, dtype=float), axis=-1)

        plus = at(ve_d, 1.0) * ends[..., 1] + at(ve_n, 1.0) * ends[..., 0]
        minus = (-1.0) ** d * at(ve_d, -1.0) * ends[..., 3] + at(ve_n, -1.0) * ends[..., 2]
        return np.stack([plus, minus], axis=-1)

    def _plant_slope(self, values, shape, name):
        # P_d is normalised to be monic in _plant_cache, which would make an
        # affine dependence rational; so differentiate the unnormalised
        # coefficients, scaled by the same leading coefficient (constant in
        # ``name`` when the loop is affine in it, checked by _check_plane).
        fraction = FRACTION in values
        parts = self._plant_parts(fraction)
        if parts is None:
            raise ValueError(f"parameter {name!r} is the plant's, and this plant's fractional "
                             f"delay is computed numerically (SymPy did not derive it): a plane "
                             f"or line along it needs a whole number of samples of delay")
        num, den = parts
        symbols = self.loop.symbols
        symbol = symbols[name]
        if sp.diff(den[0], symbol) != 0:
            raise ValueError(f"parameter {name!r} scales the plant's denominator; use it as a "
                             f"fixed value")
        names = self._plant_names(values)
        unique, inverse = self._plant_rows(values, shape)
        rows = []
        for row in unique:
            sub = {(FRACTION_SYMBOL if n == FRACTION else symbols[n]): sp.Float(repr(float(v)),
                                                                                 PLANT_DIGITS)
                   for n, v in zip(names, row, strict=True)}
            lead = den[0].subs(sub).evalf(PLANT_DIGITS)
            rows.append(([float(sp.diff(c, symbol).subs(sub).evalf(PLANT_DIGITS) / lead) for c in num],
                         [float(sp.diff(c, symbol).subs(sub).evalf(PLANT_DIGITS) / lead) for c in den]))
        dp_n = np.array([r[0] for r in rows])[inverse.ravel()].reshape(shape + (len(num),))
        dp_d = np.array([r[1] for r in rows])[inverse.ravel()].reshape(shape + (len(den),))
        return dp_n, dp_d

    def polynomial(self, given):
        """:meth:`symstab.Loop.polynomial` of the dict ``given``.

        Returns
        -------
        symstab.numeric.engine.polynomial.DelayedPolynomial
        """
        values, d, shape = self.prepare(given)
        size = int(np.prod(shape))
        check_memory("the loop's polynomial", 8 * size * 64)
        with np.errstate(all="ignore"):     # an overflow is the ValueError of finite
            chi = self.chi(values, d, shape)
        finite(np.concatenate([chi.delayed, chi.direct], axis=-1), values)
        return chi

    def root_polynomial(self, given):
        """The polynomial whose roots are counted: the closed form where the loop has one.

        Returns
        -------
        symstab.numeric.engine.polynomial.DelayedPolynomial
        """
        if self._closed_polynomial is None:
            return self.polynomial(given)
        values, d, shape = self.prepare(given)
        if FRACTION in values:
            # The closed form is the integer-delay loop's.
            return self.polynomial(given)
        check_memory("the loop's polynomial", 8 * int(np.prod(shape)) * 64)
        # As given (a single value stays one): the closed form broadcasts.
        return self._closed_polynomial(values, d)

    def affine_parts(self, names, given, *, structured=False):
        """:meth:`symstab.Loop.affine_parts`, which documents its parameters and the parts returned."""
        self.loop.check_plane(names)
        values, d, shape = self.prepare(given, scalar=self.loop.parameters, drop=names)
        for name in names:
            values[name] = np.asarray(0.0)
        plant = self.plant_arrays(values, shape)

        def part(slope=None):
            chi = self.chi(values, d, shape, slope=slope, plant=plant)
            if structured:
                finite(np.concatenate([chi.delayed, chi.direct], axis=-1), values)
                return chi
            return finite(chi.dense(), values)

        with np.errstate(all="ignore"):     # an overflow is the ValueError of finite
            base = part()
            slopes = [part(n) for n in names]
        ends = [self._end_values(values, d, shape, plant=plant)] + [
            self._end_values(values, d, shape, slope=n, plant=plant) for n in names]
        return base, slopes, ends

    def closed_form(self, x, y, values):
        """``theta -> (x, y)`` of the arc in closed form, or None (the loop's ``arc`` option).

        Returns
        -------
        callable or None
        """
        if self._closed_arc is None or x is None:
            return None
        if FRACTION in self.prepare(values, drop=(x, y))[0]:
            return None     # the closed form is the integer-delay loop's
        return self._closed_arc(x, y, {**self.loop.defaults, **values})

    def arc_source(self, x, y, values, parts):
        """:meth:`symstab.Loop.arc` on the plane's structured parts, computed by the caller.

        Parameters
        ----------
        parts : tuple
            ``(A0, A_x, A_y)``, structured (:meth:`affine_parts`).

        Returns
        -------
        symstab.numeric.engine.arcs.ArcSource
        """
        cramer = CramerArc(*(self.exact_parts((x, y), values) or parts))
        closed = self.closed_form(x, y, values)
        return cramer if closed is None else ClosedFormArc(closed, cramer)

    def arc_points(self, x, y, values):
        """``theta -> (x, y)`` of the arc where it beats Cramer on the float parts, else None.

        The exact Cramer solve gives NaN (nothing better) between
        :data:`~symstab.numeric.engine.arcs.END_ANGLE` and ``pi`` less it: the
        float parts lose their digits only next to ``z = +-1``, and a
        family of lines at a long delay crosses the arc thousands of times
        in between.

        Returns
        -------
        callable or None
        """
        closed = self.closed_form(x, y, values)
        if closed is not None:
            return closed
        exact = self.exact_parts((x, y), values)
        if exact is None:
            return None
        cramer = CramerArc(*exact)

        def points(theta):
            theta = np.asarray(theta, dtype=float)
            xs, ys = np.full(theta.shape, np.nan), np.full(theta.shape, np.nan)
            near = (theta < END_ANGLE) | (theta > np.pi - END_ANGLE)
            if near.any():
                xs[near], ys[near] = cramer(theta[near])[:2]
            return xs, ys

        return points

    def exact_parts(self, names, given):
        """``(A0, A_x, A_y)`` as :class:`~symstab.numeric.engine.arcs.ExactPolynomial`, or None.

        The plant's coefficients exact at their 30 digits, the
        environment's doubles as they are, multiplied in rational
        arithmetic.  None where a plane parameter is also the plant's (its
        slope is not computed exactly) or a part is longer than the arc's
        exact sums take.

        Returns
        -------
        tuple of symstab.numeric.engine.arcs.ExactPolynomial or None
        """
        loop = self.loop
        if any(n not in loop.environment_names or n in loop.plant_names or n == "T"
               for n in names):
            return None
        values, d, shape = self.prepare(given, scalar=loop.parameters, drop=names)
        for name in names:
            values[name] = np.asarray(0.0)
        p_n, p_d = self._exact_plant(tuple(float(values[n]) for n in loop.plant_names),
                                     float(values["T"]),
                                     float(values[FRACTION]) if FRACTION in values else None)
        k = loop.environment_delay
        out = []
        for slope in (None, *names):
            ve_n, ve_d = (part.reshape(-1) for part in self.environment_arrays(values, shape, slope))
            ve_d = ve_d[:len(ve_d) - k]
            delayed, direct = _exact_product(ve_d, p_d), _exact_product(ve_n, p_n)
            if max(len(delayed), len(direct)) > EXACT_TERMS:
                return None
            out.append(ExactPolynomial(delayed, direct, d + k))
        return tuple(out)

    def difference_parts(self, given, *, keep_overflow=False):
        """:meth:`symstab.Loop.difference_equations` of the dict ``given``.

        Parameters
        ----------
        keep_overflow : bool
            Keep coefficients that overflow (:meth:`symstab.Loop.difference_parts`)
            instead of refusing them.

        Returns
        -------
        ((ndarray, ndarray, ndarray, ndarray), int, tuple)
        """
        values, d, shape = self.prepare(given)
        parts = self._difference_parts(values, shape)
        if not keep_overflow:
            finite(np.concatenate(parts, axis=-1), values)
        return parts, d, shape

    def _difference_parts(self, values, shape):
        """``(a, b, c, e)`` at prepared ``values`` (:meth:`prepare`) of the broadcast ``shape``."""
        # The coefficients and their working copies, about 64 floats a point.
        check_memory("the loop's difference equations", 8 * int(np.prod(shape)) * 64)
        p_n, p_d, _, _ = self.plant_arrays(values, shape)
        ve_n, ve_d = self.environment_arrays(values, shape)
        n, m = p_d.shape[-1] - 1, ve_d.shape[-1] - 1
        p_n = np.concatenate([np.zeros(shape + (n + 1 - p_n.shape[-1],)), p_n], axis=-1)
        ve_n = np.concatenate([np.zeros(shape + (m + 1 - ve_n.shape[-1],)), ve_n], axis=-1)
        with np.errstate(all="ignore"):
            if np.any(p_n[..., 0] != 0):
                raise ValueError("the plant has direct feed-through (G(s) is not strictly "
                                 "proper): the sampled position would depend on the force of "
                                 "the same instant; not simulated")
            lead_p, lead_e = p_d[..., :1], ve_d[..., :1]
            if np.any(lead_p == 0) or np.any(lead_e == 0):
                raise ValueError("the leading coefficient of P_d or Ve_d is 0 at these values")
            return (p_d[..., 1:] / lead_p, p_n[..., 1:] / lead_p, ve_d[..., 1:] / lead_e,
                    ve_n / lead_e)

    def friction_spaces(self, substeps, given, *, build, digits):
        """:meth:`symstab.Loop.friction_spaces` of the dict ``given``, one space per distinct plant.

        Parameters
        ----------
        substeps : int
            Sub-steps per period.
        build : callable
            ``build(coefficients, T, substeps)``: the space from the driven
            mass's coefficients (the simulation room's ``friction_space``).
        digits : int
            The working precision of the driven mass's coefficients.

        Returns
        -------
        (list, ndarray of int)
            The spaces and each point's index into them.
        """
        values, _, shape = self.prepare(given)
        if FRACTION in values:
            raise ValueError("Coulomb friction and start='state' are simulated with a whole "
                             "number of samples of delay only: give d a whole number")
        unique, inverse = self._plant_rows(values, shape)
        spaces = [self._friction_space(tuple(float(v) for v in row[:-1]), float(row[-1]), substeps,
                                       build, digits)
                  for row in unique]
        return spaces, inverse.reshape(shape)

    @method_cache(maxsize=256)
    def _friction_space(self, plant_values, T, substeps, build, digits):
        with mpmath.workdps(digits):
            coefficients = self.loop.driven_mass(*map(mpmath.mpf, plant_values), mpmath.mpf(T))
        return build(coefficients, T, substeps)

    def closed_loop(self, given):
        """``(numerator, chi, T)`` of :meth:`symstab.Loop.closed_loop` at single values.

        Parameters
        ----------
        given : dict
            A single value of every parameter (or its default).

        Returns
        -------
        (ndarray, ndarray, float)
        """
        values, d, shape = self.prepare(given, scalar=self.loop.parameters)
        chi = self.chi(values, d, shape).dense()
        p_n = self.plant_arrays(values, shape)[0]
        _, ve_d = self.environment_arrays(values, shape)
        num = np.concatenate([_convolve(ve_d, p_n), np.zeros(d)])
        return num, chi, float(values["T"])

    def noise_path(self, given):
        """``(Ve_n P_d, chi, Ve_n, Ve_d)`` at single values: the sensor-to-force closed loop's parts.

        With the sampled position read as ``x + e``, the force is
        ``VE z**-d (x + e)`` and ``x = -P F``, so ``F = VE z**-d / (1 + L) e``,
        whose modulus on the circle is that of ``Ve_n P_d / chi`` (dense,
        highest power first); ``Ve_n / Ve_d`` is the environment alone.
        """
        values, d, shape = self.prepare(given, scalar=self.loop.parameters)
        chi = self.chi(values, d, shape).dense()
        p_d = self.plant_arrays(values, shape)[1]
        ve_n, ve_d = self.environment_arrays(values, shape)
        return _convolve(ve_n, p_d), chi, ve_n, ve_d


def _per_point(question, loop, values, number):
    """``question`` of the loop's root polynomial at ``values``: a ``number`` at a single point."""
    answer = question(loop.evaluation.root_polynomial(values))
    return number(answer) if answer.ndim == 0 else answer


def spectral_radius(loop, **values):
    """Largest modulus of a loop's closed-loop poles.

    :func:`symstab.numeric.engine.roots.spectral_radius`: companion eigenvalues
    up to degree 128, certified counts on circles and Newton steps on
    the structured polynomial (:meth:`symstab.Loop.polynomial`).

    Parameters
    ----------
    loop, **values
        As in :func:`classify`.

    Returns
    -------
    float or ndarray
        Of the broadcast shape.
    """
    return _per_point(roots.spectral_radius, loop, values, float)


def classify(loop, **values):
    """Stable (1), marginal (0) or unstable (-1) at each point of a loop's parameters.

    Certified as :func:`symstab.numeric.engine.roots.classify_polynomials` is: for
    the polynomial with the coefficients as computed (each within an ulp
    or so of the exact value: the plant at 30 digits, the environment in
    double precision).

    Parameters
    ----------
    loop : symstab.Loop
        The loop.
    **values
        Every parameter (:attr:`~symstab.Loop.parameters`) or its default;
        arrays broadcast; ``d`` in samples, whole or not, or ``Td`` in seconds.

    Returns
    -------
    int or ndarray of int8
    """
    return _per_point(roots.classify_polynomials, loop, values, int)


def is_stable(loop, **values):
    """Whether each point is stable: bool, or a masked bool array (masked = marginal).

    A single point gives ``True``, ``False`` or ``None`` (marginal).

    Parameters
    ----------
    loop, **values
        As in :func:`classify`, whose codes it reads.

    Returns
    -------
    bool, None or numpy.ma.MaskedArray
    """
    codes = loop.classify(**values)
    if np.ndim(codes) == 0:
        return None if codes == roots.MARGINAL else bool(codes == roots.STABLE)
    return np.ma.masked_array(codes == roots.STABLE, mask=codes == roots.MARGINAL)


def unstable_root_counts(loop, **values):
    """Certified number of a loop's closed-loop poles outside the unit circle (-1: marginal).

    :func:`symstab.numeric.engine.roots.root_counts`, O(d) per point; -1 also
    where a root is at infinity to within rounding (an ill-posed loop).

    Parameters
    ----------
    loop, **values
        As in :func:`classify`, which is marginal where this is -1.

    Returns
    -------
    int or ndarray of int
    """
    return _per_point(roots.root_counts, loop, values, int)


def difference_equations(loop, **values):
    """A loop's difference equations per point: ``(a, b, c, e)``, ``d`` and the shape.

    The plant's sampled step ``P_d(z) y = P_n(z) u`` and the environment
    ``Ve_d(z) f = Ve_n(z) x_s``, both divided by their leading
    coefficient: ``y[k] = sum_i (b[i] u[k-1-i] - a[i] y[k-1-i])`` and
    ``f[k] = e[0] x_s[k] + sum_i (e[i+1] x_s[k-1-i] - c[i] f[k-1-i])``.
    The loop is closed by ``u[k] = -f[k - d]``, so that its
    characteristic polynomial is :meth:`symstab.Loop.polynomial`'s ``chi``.

    Parameters
    ----------
    loop : symstab.Loop
        The loop.
    **values
        Every parameter (or its default); arrays broadcast.

    Returns
    -------
    ((ndarray, ndarray, ndarray, ndarray), int, tuple)
        ``a`` and ``b`` of length ``deg P_d``, ``c`` of length ``deg
        Ve_d`` and ``e`` one longer, each of shape ``shape + (k,)``;
        the delay; the broadcast shape.

    Raises
    ------
    ValueError
        For a plant with direct feed-through (``P_n`` as high as ``P_d``),
        a leading coefficient 0, or values that overflow.
    """
    return loop.evaluation.difference_parts(values)


def difference_parts(loop, values):
    """:func:`difference_equations` of the dict ``values``, with coefficients that overflow kept.

    The paper's simulator calls a point whose coefficient overflows (``K
    = 1e308``) a point that diverges at once, as it always has; a loop's
    own run refuses it (:func:`difference_equations`).

    Parameters
    ----------
    loop : symstab.Loop
    values : dict
        The ``**values`` of :func:`difference_equations` in one dict.

    Returns
    -------
    ((ndarray, ndarray, ndarray, ndarray), int, tuple)
        As :func:`difference_equations`.
    """
    return loop.evaluation.difference_parts(values, keep_overflow=True)


def closed_loop(loop, **values):
    """The closed loop of a loop from a force at the plant's input to the position.

    ``P / (1 + VE z**-d P) = z**d Ve_d P_n / chi(z)``, built from the
    polynomials (nothing cancelled), so its poles are the roots of
    ``chi``.  Needs python-control.

    Parameters
    ----------
    loop : symstab.Loop
        The loop.
    **values
        A single value of every parameter (or its default).

    Returns
    -------
    control.TransferFunction
        Discrete time, ``dt = T``.
    """
    try:
        import control
    except ImportError:
        raise ImportError("Loop.closed_loop needs python-control: pip install control") from None
    num, chi, T = loop.evaluation.closed_loop(values)
    return control.tf(num, chi, T)
