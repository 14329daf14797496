"""Any sampled haptic loop: the user's own plant and virtual environment.

:class:`Loop` takes a plant ``G(s)`` (force through the zero-order hold to
measured position) and an environment ``VE(z)`` (force law on the sampled
position), both with named parameters, and closes the loop with a delay of
``d`` samples::

    1 + VE(z) z**-d Z[ZOH G](z) = 0.

With ``VE = Ve_n / Ve_d`` and ``Z[ZOH G] = P_n / P_d`` the closed-loop poles
are the roots of

    chi(z) = z**d Ve_d(z) P_d(z) + Ve_n(z) P_n(z),

a *delayed part* and a *direct part*, as for the paper's loop
(:mod:`symstab.symbolic.loop`).  The derivation is SymPy's: the pulse transfer
function by residues when the denominator of ``G(s)/s`` factors, over the
parameters, into factors of degree 1 or 2 in ``s`` (repeated poles, complex
pairs and poles at 0 included), otherwise by the
matrix exponential at 30 digits once the plant's values are known
(:attr:`Loop.zoh_method` says which).

Numbers: the environment's polynomials come from a NumPy kernel generated
for the loop (:mod:`symstab.codegen.loop_kernels`, cached on disk); the plant's
pulse transfer function is evaluated at 30 digits for each distinct set of
plant values (its closed form cancels badly in floating point when
``b T / m`` is small) and rounded once.  Classification is
:func:`symstab.numeric.engine.roots.classify_polynomials` (float Schur-Cohn where its
margin is safe, the certified root count elsewhere).  The boundary of a
parameter plane is the D-decomposition: on ``z = exp(j theta)`` the two real
equations ``Re chi = Im chi = 0`` are linear in the plane's parameters
``(x, y)`` and solved per ``theta``; ``z = 1``, ``z = -1`` and a vanishing
leading coefficient give straight lines.
"""

import dataclasses
import fractions
import functools
import math

import mpmath
import numpy as np
import sympy as sp

from ..._memo import method_cache
from ..._resources import check_memory
from ..._validate import check_array, check_box, check_count, check_delay, check_real, check_window
from ...symbolic.loop_assembly import PLANT_DIGITS, LoopModel, parse_environment, parse_plant, shift_to_one
from ...codegen.loop_kernels import environment_kernels, load_numpy_kernels
from ..engine.arcs import END_ANGLE, EXACT_TERMS, ClosedFormArc, CramerArc, ExactPolynomial
from ..engine.decomposition import Decomposition, Unresolved, decompose, stable_hull, window_arc
from ..engine.decomposition import lines as _lines
from ..engine.polynomial import DelayedPolynomial
from ..engine.intervals import family_intervals
from ..engine.roots import MARGINAL, STABLE, classify_polynomials, root_counts, spectral_radius
from ..engine.results import Boundary, Limits

__all__ = ["Loop", "LoopLimits", "LoopBoundary", "parse_plant", "parse_environment"]



#: Older name of :class:`symstab.numeric.engine.results.Limits`, the one result type of ``limits``.
LoopLimits = Limits


#: Older name of :class:`symstab.numeric.engine.results.Boundary`, the one result type of a boundary.
LoopBoundary = Boundary


#: Largest coordinate of a window of :meth:`Loop.region`: products of two
#: coordinates (areas, cross products of the cells' edges) stay finite.
LARGEST_COORDINATE = 1e150


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


class Loop(LoopModel):
    """A sampled haptic loop: plant, zero-order hold, delay and virtual environment.

    Parameters
    ----------
    plant : str, sympy.Expr or control.TransferFunction
        ``G(s)``, force to position, proper and rational in ``s``, e.g.
        ``"1/(m*s**2 + b*s)"``.
    environment : str or sympy.Expr
        ``VE(z)``, sampled position to force, proper and rational in ``z``;
        ``T`` is the sample period, e.g.
        ``"K + B*(z - 1)/(T*z) + M*(z - 1)**2/(T**2*z**2)"``.
    values : dict, optional
        Default values of parameters (used where a call does not give one).
    name : str, optional
        A word for reprs and generated files (ASCII letters, digits, ``_``,
        ``-``, ``.``).
    units : dict, optional
        The SI unit of each parameter, as text (shown by the CLI), e.g.
        ``{"K": "N/m"}``.  The loop computes with its values as given, so a
        unit that is not SI (``"ms"``) is refused, and so are units whose
        dimensions do not fit the loop; a loop file's units are converted
        (:func:`symstab.load_loop`).
    description : str, optional
        One line on what the loop is.
    plane : (str, str), optional
        The default ``(x, y)`` plane of :meth:`boundary` and :meth:`limits`
        (for example ``("B", "K")``); checked to be jointly affine.
    arc : callable, optional
        The loop's arc in closed form, where SymPy derived one:
        ``arc(x, y, values)`` gives ``theta -> (x, y)``, the point of the
        ``(x, y)`` plane where ``exp(j theta)`` is a root at the other
        ``values`` (NaN where the closed form does not keep its digits), or
        None for a plane it does not cover.  The line engine refines its
        crossings on it (the paper's loop: eq. (7)'s kernel).
    polynomial : callable, optional
        The loop's characteristic polynomial in closed form, where SymPy
        derived one: ``polynomial(values, d)`` gives a
        :class:`~symstab.numeric.engine.polynomial.DelayedPolynomial` with the
        roots of ``chi`` (any nonzero scale) at ``values`` (arrays that
        broadcast together, ``d`` apart), of their broadcast shape.  :meth:`classify`,
        :meth:`unstable_root_counts` and :meth:`spectral_radius` count its
        roots (the paper's loop: eq. (5)'s kernel, exact next to ``z = 1``
        and from ``b T/m = 0`` to 1e6); :meth:`polynomial` stays the loop's own.
    actuator : str or sympy.Expr, optional
        ``A(s)``, the factor of the plant from the force command to the
        force on the driven mass (an amplifier's lag, ``"1/(tau*s + 1)"``);
        default ``1``.  Coulomb friction acts on the mass, after it
        (:meth:`simulate`); ``plant / actuator`` must be a mass's force to
        position (relative degree 2).

    Raises
    ------
    TypeError, ValueError
        If the plant or the environment is not a proper rational function
        of its variable, or uses ``d`` (the delay is the loop's); if a unit
        is not SI or does not fit the loop.

    Examples
    --------
    >>> loop = Loop("1/(m*s**2 + b*s)", "K + B*(z - 1)/(T*z)")
    >>> loop.parameters
    ('B', 'K', 'b', 'm', 'T', 'd')
    >>> loop.zoh_method
    'residues'
    >>> bool(loop.is_stable(K=300.0, B=0.5, m=0.0128, b=0.0324, T=1e-3, d=0))
    True
    """

    def __init__(self, plant, environment, *, values=None, name=None, units=None,
                 description="", plane=None, arc=None, polynomial=None, actuator=None):
        super().__init__(plant, environment, values=values, name=name, units=units,
                         description=description, plane=plane, actuator=actuator)
        for option, hook in (("arc", arc), ("polynomial", polynomial)):
            if hook is not None and not callable(hook):
                raise TypeError(f"{option} must be callable, got {type(hook).__name__}")
        self._arc = arc
        self._closed_polynomial = polynomial
        if self.units:
            self._check_units()

    def __reduce__(self):
        # Rebuilt from its definition (the kernels are compiled again on first
        # use): a loop, and a result that refers to it, travel to a worker process.
        return (_rebuilt, (self.plant, self.environment, {
            "values": dict(self.defaults), "name": self.name, "units": dict(self.units),
            "description": self.description, "plane": self.plane, "arc": self._arc,
            "polynomial": self._closed_polynomial, "actuator": self.actuator}))

    def _check_units(self):
        # A unit here names the unit of values the loop computes with as they
        # are: one that is not SI would be a label on a wrong number.
        from .quantities import check_loop_units, convert

        given = {}
        for key, unit in self.units.items():
            item = convert(key, 1, unit, where="units")
            if item.si_value != 1:
                raise ValueError(f"units: {key!r} is given in {unit!r}, which is "
                                 f"{float(item.si_value):g} {item.si_unit}: Loop takes its values "
                                 f"in SI, so give {key} in {item.si_unit} (a loop file's units are "
                                 f"converted: symstab.load_loop)")
            given[key] = convert(key, self.defaults.get(key, 1), unit, where="units")
        for key, value in self.defaults.items():
            given.setdefault(key, convert(key, value, None, where="values"))
        check_loop_units(self, given, [], source="units")

    def kernels(self):
        """The loop's generated kernels, as :class:`symstab.codegen.generator.Kernel` objects.

        ``environment`` gives the coefficients of ``Ve_n`` and ``Ve_d``
        (highest power of ``z`` first) from the environment's parameters
        (and ``T``); ``environment_slope_<name>`` their derivatives in each
        parameter that enters them affinely.  Their NumPy module is what the
        loop runs on (:meth:`kernel_file`); ``symstab derive --loop`` prints
        them in C as well.
        """
        return list(self._kernel_list[0])

    @functools.cached_property
    def _kernel_list(self):
        kernels, names = environment_kernels(self)
        ve_n, ve_d = self.environment_parts
        return kernels, names, len(ve_n), len(ve_d)

    def kernel_title(self):
        """The title line of the loop's generated NumPy module."""
        return f"NumPy kernels of the loop {self.name}: VE(z) = {self.environment}."

    @functools.cached_property
    def _kernels(self):
        kernels, names, n_num, n_den = self._kernel_list
        return load_numpy_kernels(kernels, title=self.kernel_title()), names, n_num, n_den

    def kernel_file(self):
        """Where the loop's generated NumPy module lives (None if in memory)."""
        return self._kernels[0].__file__

    def _values(self, given, *, scalar=(), drop=()):
        unknown = set(given) - set(self.parameters)
        if unknown:
            raise TypeError(f"unknown parameter(s) {', '.join(sorted(unknown))}; "
                            f"parameters of this loop: {', '.join(self.parameters)}")
        values = dict(self.defaults)
        values.update(given)
        missing = [n for n in self.parameters if n not in values and n not in drop]
        if missing:
            raise TypeError(f"missing value(s) for {', '.join(missing)}")
        d = check_delay(values.pop("d"))
        out = {}
        for name in self.symbols:
            if name in drop:
                continue
            if name == "T":
                out[name] = check_array("T", values[name], low=0.0, low_open=True)
            else:
                out[name] = check_array(name, values[name])
            if name in scalar and out[name].ndim:
                raise ValueError(f"{name} must be a single value here, got an array of "
                                 f"shape {out[name].shape}")
        return out, d

    def _plant_arrays(self, values, shape):
        """(P_n, P_d, ends, P_d in z - 1) per point, shape ``shape + (k,)``, one 30-digit evaluation per distinct row."""
        names = self.plant_names + ("T",)
        if all(np.ndim(values[n]) == 0 for n in names):
            # One plant for every point: the common case of a plane sweep.
            parts = self._numeric_plant(tuple(float(values[n]) for n in names[:-1]),
                                        float(values["T"]))
            return tuple(np.broadcast_to(part, shape + part.shape) for part in parts)
        columns = np.stack([np.broadcast_to(values[n], shape).ravel() for n in names], axis=-1)
        unique, inverse = np.unique(columns, axis=0, return_inverse=True)
        parts = [self._numeric_plant(tuple(row[:-1]), float(row[-1])) for row in unique]
        out = []
        for k in range(4):
            part = np.array([p[k] for p in parts])[inverse.ravel()]
            out.append(part.reshape(shape + part.shape[-1:]))
        return tuple(out)

    def _environment_arrays(self, values, shape, slope=None):
        module, names, n_num, n_den = self._kernels
        function = module.environment if slope is None else getattr(module, f"environment_slope_{slope}")
        with np.errstate(all="ignore"):
            out = function(*[values[n] for n in names])
        out = [np.broadcast_to(np.asarray(c, dtype=float), shape) for c in out]
        return np.stack(out[:n_num], axis=-1), np.stack(out[n_num:], axis=-1)

    @staticmethod
    def _convolve(a, b):
        out = np.zeros(np.broadcast_shapes(a.shape[:-1], b.shape[:-1]) + (a.shape[-1] + b.shape[-1] - 1,))
        for i in range(a.shape[-1]):
            out[..., i:i + b.shape[-1]] += a[..., i, None] * b
        return out

    def _polynomial(self, values, d, shape, *, slope=None, plant=None):
        """``chi = z**d Ve_d P_d + Ve_n P_n`` (or its slope in one parameter), structured.

        The delayed part comes also in powers of ``z - 1`` (the plant's at 30
        digits, the environment's shifted in double precision with a bound
        on that rounding), for the root count's accuracy next to ``z = 1``;
        a plant parameter's slope has none.
        """
        if plant is None:
            plant = self._plant_arrays(values, shape)
        p_n, p_d, _, p_d_one = plant
        # A power of z that divides Ve_d (the backward differences' 1/z**k)
        # joins the delay: chi = z**(d + k) (Ve_d / z**k) P_d + Ve_n P_n keeps
        # the delayed part short (the paper's z**(d+2) (z - 1)(z - r)).
        k = self.environment_delay
        d = d + k
        if slope is None or slope in self.environment_names:
            ve_n, ve_d = self._environment_arrays(values, shape, slope)
            ve_d = ve_d[..., :ve_d.shape[-1] - k]
            ve_one, ve_error = _shift_to_one(ve_d)
            near_one = (self._convolve(ve_one, p_d_one),
                        self._convolve(ve_error, np.abs(p_d_one))
                        + 4 * ve_d.shape[-1] * 2.0**-53 * self._convolve(np.abs(ve_one),
                                                                         np.abs(p_d_one)))
            return DelayedPolynomial(self._convolve(ve_d, p_d), self._convolve(ve_n, p_n), d,
                                     near_one=near_one)
        # A plant parameter: the slope of P_n, P_d (30 digits) by the exact
        # derivative of their symbolic coefficients.
        ve_n, ve_d = self._environment_arrays(values, shape)
        ve_d = ve_d[..., :ve_d.shape[-1] - k]
        dp_n, dp_d = self._plant_slope(values, shape, slope)
        return DelayedPolynomial(self._convolve(ve_d, dp_d), self._convolve(ve_n, dp_n), d)

    @functools.cached_property
    def environment_delay(self):
        """The environment's own delay in samples: the power of ``z`` that divides ``Ve_d``.

        How many trailing coefficients of the symbolic ``Ve_d`` are 0 (a
        ``z**-k`` in the environment), beside the loop's delay ``d``.
        """
        ve_d = self.environment_parts[1]
        k = 0
        while k < len(ve_d) - 1 and sp.simplify(ve_d[len(ve_d) - 1 - k]) == 0:
            k += 1
        return k

    def _coefficients(self, values, d, shape, *, slope=None, plant=None):
        return self._polynomial(values, d, shape, slope=slope, plant=plant).dense()

    def _end_values(self, values, d, shape, *, slope=None, plant):
        """``chi(1)`` and ``chi(-1)`` (or their slopes), from the plant's 30-digit end values."""
        ends = plant[2]
        if slope is not None and slope not in self.environment_names:
            dense = self._coefficients(values, d, shape, slope=slope, plant=plant)
            return np.stack([np.sum(dense, axis=-1),
                             np.sum(dense * (-1.0) ** np.arange(dense.shape[-1] - 1, -1, -1), axis=-1)],
                            axis=-1)
        ve_n, ve_d = self._environment_arrays(values, shape, slope)

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
        num, den = self._plant_parts
        symbol = self.symbols[name]
        if sp.diff(den[0], symbol) != 0:
            raise ValueError(f"parameter {name!r} scales the plant's denominator; use it as a "
                             f"fixed value")
        names = self.plant_names + ("T",)
        columns = np.stack([np.broadcast_to(values[n], shape).ravel() for n in names], axis=-1)
        unique, inverse = np.unique(columns, axis=0, return_inverse=True)
        rows = []
        for row in unique:
            sub = {self.symbols[n]: sp.Float(repr(float(v)), PLANT_DIGITS) for n, v in zip(names, row)}
            lead = den[0].subs(sub).evalf(PLANT_DIGITS)
            rows.append(([float(sp.diff(c, symbol).subs(sub).evalf(PLANT_DIGITS) / lead) for c in num],
                         [float(sp.diff(c, symbol).subs(sub).evalf(PLANT_DIGITS) / lead) for c in den]))
        dp_n = np.array([r[0] for r in rows])[inverse.ravel()].reshape(shape + (len(num),))
        dp_d = np.array([r[1] for r in rows])[inverse.ravel()].reshape(shape + (len(den),))
        return dp_n, dp_d

    def _prepare(self, given, scalar=(), drop=()):
        values, d = self._values(given, scalar=scalar, drop=drop)
        try:
            shape = np.broadcast_shapes(*[v.shape for v in values.values()])
        except ValueError as exc:
            raise ValueError(f"parameter arrays must broadcast together: {exc}") from None
        return values, d, shape

    def coefficients(self, **values):
        """Coefficients of ``chi(z)`` (highest power first), divided by ``P_d``'s leading one.

        Dense: for short delays and for comparisons; the loop's own
        computations keep ``chi`` structured (:meth:`polynomial`).

        Parameters
        ----------
        **values
            Every parameter (:attr:`parameters`), or its default; arrays
            broadcast; ``d`` is an integer.

        Returns
        -------
        ndarray
            Shape ``broadcast_shape + (degree + 1,)``.
        """
        return self.polynomial(**values).dense()

    def polynomial(self, **values):
        """``chi(z) = z**d D(z) + N(z)`` as a :class:`~symstab.numeric.engine.polynomial.DelayedPolynomial`.

        ``D = Ve_d P_d`` and ``N = Ve_n P_n``, divided by ``P_d``'s leading
        coefficient, one polynomial per point; what :meth:`classify`,
        :meth:`unstable_root_counts` and :meth:`spectral_radius` work on, in
        O(d) per point.

        Parameters
        ----------
        **values
            Every parameter (:attr:`parameters`), or its default; arrays
            broadcast; ``d`` is an integer.
        """
        values, d, shape = self._prepare(values)
        size = int(np.prod(shape))
        check_memory("the loop's polynomial", 8 * size * 64)
        with np.errstate(all="ignore"):     # an overflow is the ValueError of _finite
            chi = self._polynomial(values, d, shape)
        self._finite(np.concatenate([chi.delayed, chi.direct], axis=-1), values)
        return chi

    @staticmethod
    def _finite(c, values):
        """``c`` if every coefficient is finite, else a ValueError naming the values."""
        # Not finite (overflow), or nothing left (every coefficient underflowed).
        bad = ~np.all(np.isfinite(c), axis=-1) | ~np.any(c != 0, axis=-1)
        if np.any(bad):
            index = np.unravel_index(int(np.flatnonzero(bad.ravel())[0]), bad.shape)
            point = ", ".join(f"{n} = {float(v[index] if v.ndim else v):g}"
                              for n, v in values.items())
            raise ValueError(f"the characteristic polynomial overflows or underflows at {point}: a "
                             f"parameter is too large or too small for double precision")
        return c

    def _root_polynomial(self, values):
        """The polynomial whose roots are counted: the closed form where the loop has one."""
        if self._closed_polynomial is None:
            return self.polynomial(**values)
        values, d, shape = self._prepare(values)
        check_memory("the loop's polynomial", 8 * int(np.prod(shape)) * 64)
        # As given (a single value stays one): the closed form broadcasts.
        return self._closed_polynomial(values, d)

    def spectral_radius(self, **values):
        """Largest modulus of the closed-loop poles.

        :func:`symstab.numeric.engine.roots.spectral_radius`: companion eigenvalues
        up to degree 128, certified counts on circles and Newton steps on
        the structured polynomial above.

        Parameters
        ----------
        **values
            Every parameter (:attr:`parameters`) or its default; arrays
            broadcast; ``d`` is an integer.

        Returns
        -------
        float or ndarray
            Of the broadcast shape.
        """
        r = spectral_radius(self._root_polynomial(values))
        return float(r) if r.ndim == 0 else r

    def classify(self, **values):
        """Stable (1), marginal (0) or unstable (-1) at each point.

        Certified as :func:`symstab.numeric.engine.roots.classify_polynomials` is: for
        the polynomial with the coefficients as computed (each within an ulp
        or so of the exact value: the plant at 30 digits, the environment in
        double precision).

        Parameters
        ----------
        **values
            Every parameter (:attr:`parameters`) or its default; arrays
            broadcast; ``d`` is an integer.

        Returns
        -------
        int or ndarray of int8
        """
        codes = classify_polynomials(self._root_polynomial(values))
        return int(codes) if codes.ndim == 0 else codes

    def is_stable(self, **values):
        """Whether each point is stable: bool, or a masked bool array (masked = marginal).

        A single point gives ``True``, ``False`` or ``None`` (marginal).

        Parameters
        ----------
        **values
            Every parameter (:attr:`parameters`) or its default; arrays
            broadcast; ``d`` is an integer.
        """
        codes = self.classify(**values)
        if np.ndim(codes) == 0:
            return None if codes == MARGINAL else bool(codes == STABLE)
        return np.ma.masked_array(codes == STABLE, mask=codes == MARGINAL)

    def unstable_root_counts(self, **values):
        """Certified number of closed-loop poles outside the unit circle (-1: marginal).

        :func:`symstab.numeric.engine.roots.root_counts`, O(d) per point; -1 also
        where a root is at infinity to within rounding (an ill-posed loop),
        as in :meth:`classify`.

        Parameters
        ----------
        **values
            Every parameter (:attr:`parameters`) or its default; arrays
            broadcast; ``d`` is an integer.
        """
        counts = root_counts(self._root_polynomial(values))
        return int(counts) if counts.ndim == 0 else counts

    def affine_parts(self, names, given, *, structured=False):
        """``chi = A0 + x A_x (+ y A_y)`` in the affine parameters ``names``: the parts and their ends.

        What the line engine, the D-decomposition and the arc sources work
        on: the characteristic polynomial with the named parameters set to
        0, its slope in each, and their values at ``z = 1`` and ``z = -1``
        from the plant's 30-digit end values.

        Parameters
        ----------
        names : tuple of str
            One or two parameters in which ``chi`` is jointly affine.
        given : dict
            Single values of the other parameters (defaults for the rest).
        structured : bool
            :class:`~symstab.numeric.engine.polynomial.DelayedPolynomial` parts
            (one polynomial each, a common shift) instead of dense rows.

        Returns
        -------
        (A0, [A_x, A_y], [ends of A0, of A_x, of A_y])
            Each end an array ``(chi(1), chi(-1))``.
        """
        self.check_plane(names)
        values, d, shape = self._prepare(given, scalar=self.parameters, drop=names)
        for name in names:
            values[name] = np.asarray(0.0)
        plant = self._plant_arrays(values, shape)

        def part(slope=None):
            chi = self._polynomial(values, d, shape, slope=slope, plant=plant)
            if structured:
                self._finite(np.concatenate([chi.delayed, chi.direct], axis=-1), values)
                return chi
            return self._finite(chi.dense(), values)

        with np.errstate(all="ignore"):     # an overflow is the ValueError of _finite
            base = part()
            slopes = [part(n) for n in names]
        ends = [self._end_values(values, d, shape, plant=plant)] + [
            self._end_values(values, d, shape, slope=n, plant=plant) for n in names]
        return base, slopes, ends

    def stable_intervals(self, name, **values):
        """The stable intervals of one parameter, the others fixed.

        The polynomial is ``A0(z) + p A1(z)`` in the parameter ``p``, so a
        root crosses the unit circle only at the ``p`` where ``A0 + p A1``
        vanishes at some ``z = exp(j theta)``: where ``Im(A0 conj A1) = 0``,
        at ``z = +-1``, and where the leading coefficient vanishes.  The
        one line engine (:func:`symstab.numeric.engine.intervals.family_intervals`)
        finds them on the structured polynomial (O(d) per angle and per
        certified count, whatever the delay) and counts the roots outside
        the circle between them.

        Parameters
        ----------
        name : str
            A parameter in :meth:`affine_parameters`.
        **values
            Single values of every other parameter (``d`` included).  One
            other parameter of :meth:`affine_parameters` may be given a 1-D
            array instead: a family of parallel lines, one per value,
            scanned and counted together.

        Returns
        -------
        list of (float, float)
            Stable intervals ``(lo, hi)``, increasing; ``lo`` may be
            ``-inf`` and ``hi`` ``inf``.  Endpoints are unstable or marginal.
            A line on which every value has a root exactly at ``z = 1`` or
            ``z = -1`` has none.  For a family, one such list per value.

        Raises
        ------
        ValueError
            For more than one array, and where a line cannot be resolved in
            double precision (every stretch of it has a root on the unit
            circle to within rounding).
        """
        arrays = [k for k, v in values.items() if k != "d" and np.ndim(v) > 0]
        if len(arrays) > 1:
            raise ValueError(f"at most one parameter may be an array (a family of lines), got "
                             f"{', '.join(arrays)}")
        across = arrays[0] if arrays else None
        family = across is not None
        if not family and self.plane is not None and name in self.plane:
            # One line of the plane's family: the base polynomial then has
            # both plane parameters at 0, so a value that vanishes there
            # (chi(1) with K = 0) is exactly 0, as on every line of a family.
            other = self.plane[1 - self.plane.index(name)]
            if other in self.defaults or other in values:
                across = other
        at = np.zeros(1)
        if across is not None:
            at = check_array(across, values.get(across, self.defaults.get(across)))
            if at.ndim > 1:
                raise ValueError(f"{across} must be a single value or a 1-D array of values, "
                                 f"got shape {at.shape}")
            at = at.reshape(-1)
            values = {k: v for k, v in values.items() if k != across}
        names = (name,) if across is None else (name, across)
        base, slopes, ends = self.affine_parts(names, values, structured=True)
        # The crossings with the arc are re-found on the loop's arc source
        # where it is more accurate than the float parts the engine scans.
        runs = family_intervals(base, slopes[1] if across else None, slopes[0], at,
                                (tuple(ends[0]), tuple(ends[2]) if across else None,
                                 tuple(ends[1])),
                                arc=None if across is None else self._arc_points(across, name, values))
        if across is not None and not family:
            values = {**values, across: float(at[0])}
        for value, r in zip(at, runs):
            if r is None:
                fixed = ", ".join(f"{k} = {v:g}" for k, v in values.items() if k != "d")
                if family:
                    fixed = f"{across} = {value:g}" + (", " + fixed if fixed else "")
                raise ValueError(
                    f"the loop's polynomial along {name} cannot be resolved in double precision "
                    f"at {fixed}, d = {values.get('d', self.defaults.get('d'))}: every stretch "
                    f"has a root on the unit circle to within rounding (a value far outside "
                    f"the loop's usual range?)")
        return runs if family else runs[0]

    def _closed_form(self, x, y, values):
        """``theta -> (x, y)`` of the arc in closed form, or None (see the ``arc`` parameter)."""
        if self._arc is None or x is None:
            return None
        return self._arc(x, y, {**self.defaults, **values})

    def plane_of(self, x, y):
        """The plane ``(x, y)`` a question is asked in: the given names, or the loop's default.

        Parameters
        ----------
        x, y : str or None
            The plane's parameters; both None for the loop's :attr:`plane`.

        Returns
        -------
        tuple of str
            ``(x, y)``.

        Raises
        ------
        TypeError
            Only one of them given, or neither and the loop has no plane.
        """
        if x is None and y is None and self.plane is not None:
            return self.plane
        if x is None or y is None:
            raise TypeError("give the plane's parameters x and y (this loop has no default plane)")
        return x, y

    def arc(self, x=None, y=None, **values):
        """The arc source of the ``(x, y)`` plane: ``source(theta) -> (x, y, det)``.

        The one source of the loop's arc, which :meth:`boundary`,
        :meth:`region` and :meth:`limits` sample: the closed form where
        SymPy derived one (the ``arc`` parameter; the paper's kernel), else
        Cramer's rule with ``sin(theta)`` divided out
        (:class:`~symstab.numeric.engine.arcs.CramerArc`) on the loop's
        characteristic polynomial with its plant's 30-digit coefficients
        kept exact where the plane's parameters are the environment's (a
        plant zero next to ``z = -1``, a pole at ``z = 1``: rounded to
        doubles, those coefficients cost the arc up to 1e-9 of its size
        there).

        Parameters
        ----------
        x, y : str
            The plane's parameters, jointly affine (default: :attr:`plane`).
        **values
            Single values of every other parameter.

        Returns
        -------
        symstab.numeric.engine.arcs.ArcSource
            At angles in (0, pi): the point of the plane where ``exp(j
            theta)`` is a root (NaN where the arc is at infinity) and the
            sign-carrying determinant.

        Examples
        --------
        >>> loop = Loop("1/(m*s**2 + b*s)", "K + B*(z - 1)/(T*z)",
        ...             values=dict(m=0.0128, b=0.0324, T=1e-3, d=10))
        >>> B, K, det = loop.arc("B", "K")(np.array([0.05]))
        >>> bool(K[0] > 0)
        True
        """
        x, y = self.plane_of(x, y)
        structured, slopes, _ = self.affine_parts((x, y), values, structured=True)
        return self._arc_source(x, y, values, (structured, *slopes))

    def _arc_source(self, x, y, values, parts):
        """:meth:`arc` on the plane's structured parts, computed by the caller."""
        cramer = CramerArc(*(self._exact_parts((x, y), values) or parts))
        closed = self._closed_form(x, y, values)
        return cramer if closed is None else ClosedFormArc(closed, cramer)

    def _arc_points(self, x, y, values):
        """``theta -> (x, y)`` of :meth:`arc` where it beats Cramer on the float parts, else None.

        The exact Cramer solve gives NaN (nothing better) between
        :data:`~symstab.numeric.engine.arcs.END_ANGLE` and ``pi`` less it: the
        float parts lose their digits only next to ``z = +-1``, and a
        family of lines at a long delay crosses the arc thousands of times
        in between.
        """
        closed = self._closed_form(x, y, values)
        if closed is not None:
            return closed
        exact = self._exact_parts((x, y), values)
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

    def _exact_parts(self, names, given):
        """``(A0, A_x, A_y)`` as :class:`~symstab.numeric.engine.arcs.ExactPolynomial`, or None.

        The plant's coefficients exact at their 30 digits, the
        environment's doubles as they are, multiplied in rational
        arithmetic.  None where a plane parameter is also the plant's (its
        slope is not computed exactly) or a part is longer than the arc's
        exact sums take.
        """
        if any(n not in self.environment_names or n in self.plant_names or n == "T"
               for n in names):
            return None
        values, d, shape = self._prepare(given, scalar=self.parameters, drop=names)
        for name in names:
            values[name] = np.asarray(0.0)
        p_n, p_d = self._exact_plant(tuple(float(values[n]) for n in self.plant_names),
                                     float(values["T"]))
        k = self.environment_delay
        out = []
        for slope in (None, *names):
            ve_n, ve_d = (part.reshape(-1) for part in self._environment_arrays(values, shape, slope))
            ve_d = ve_d[:len(ve_d) - k]
            delayed, direct = _exact_product(ve_d, p_d), _exact_product(ve_n, p_n)
            if max(len(delayed), len(direct)) > EXACT_TERMS:
                return None
            out.append(ExactPolynomial(delayed, direct, d + k))
        return tuple(out)

    def boundary(self, x=None, y=None, n=1000, *, window=None, segments=False, **values):
        """The D-decomposition of the ``(x, y)`` plane.

        Parameters
        ----------
        x, y : str
            Two parameters entering the polynomial jointly affinely
            (default: the loop's :attr:`plane`).
        n : int
            Angles in (0, pi), evenly spaced (without ``window``).
        window : ((float, float), (float, float)), optional
            ``(x_range, y_range)``: the arc sampled to be drawn there instead,
            adaptively (:func:`symstab.numeric.engine.decomposition.window_arc`: no
            chord in the window longer than 2e-3 of it, NaN far from it).
        segments : bool
            Also find the pieces of the z = +-1 lines that close the stable
            set (from :meth:`region`: seconds at long delays).
        **values
            Single values of every other parameter.

        Returns
        -------
        symstab.numeric.engine.results.Boundary
        """
        x, y = self.plane_of(x, y)
        n = check_count("n", n, 2)
        check_memory("the boundary", 64 * n)
        structured, slopes, ends = self.affine_parts((x, y), values, structured=True)
        base, ax, ay = (p.dense().reshape(-1) for p in (structured, *slopes))
        arc = self._arc_source(x, y, values, (structured, *slopes))
        if window is None:
            theta = np.pi * (np.arange(1, n + 1) - 0.5) / n
            xs, ys, _ = arc(theta)
        else:
            theta, xs, ys = window_arc(arc, len(base) - 1, *check_box("window", window))
        lines = {label: c for label, c in _lines(base, ax, ay, ends).items() if c[1] or c[2]}
        pieces = self.region(x, y, **values).segments if segments else ()
        return Boundary(x, y, theta, xs, ys, lines=lines, segments=pieces, at=dict(values))

    def region(self, x=None, y=None, *, x_range=None, y_range=None, uncertain=None, strips=64,
               rtol=1e-6, progress=None, **values):
        """The complete D-decomposition of the ``(x, y)`` plane: cells, root counts, stable set.

        With ``uncertain``, the robust region instead: the points stable for
        every value in a box (:func:`symstab.numeric.analysis.robust.robust_region`
        states the guarantee), a
        :class:`~symstab.numeric.engine.results.RobustRegion` with the nominal
        decomposition (at the box's centre) beside it.

        Every branch of the arc (``theta`` over all of (0, pi)), the z = 1,
        z = -1 and leading-coefficient lines, the cells they cut the window
        into and the certified count of unstable roots in each
        (:func:`symstab.numeric.engine.decomposition.decompose`).

        Parameters
        ----------
        x, y : str
            The plane's parameters, jointly affine (default: the loop's
            :attr:`plane`).
        x_range, y_range : (float, float), optional
            The window.  A side not given is found.  First, where a stable
            point can be at all (:func:`symstab.numeric.engine.decomposition.stable_hull`,
            exact): when nowhere, that is the answer; when in a bounded
            polygon, no window goes beyond its box.  The window starts
            around the stable points next to the arc and the lines (or,
            when none is sampled, is the box itself, so a set too small to
            be sampled is still found, and a set not found there is empty)
            and is widened (up to 10 times) while a stable cell reaches that
            side; if it still does, the side is in
            :attr:`Decomposition.unbounded`.
        uncertain : dict, optional
            ``{name: (low, high)}`` of the plant's and environment's
            parameters (``T`` too) and ``d`` (whole delays): the box.
        strips, rtol, progress : optional
            With ``uncertain``: vertical strips across the window, the
            resolution of the certified intervals' ends (a fraction of the
            window's height), a callable given the delays done.
        **values
            Single values of every other parameter.

        Returns
        -------
        symstab.numeric.engine.decomposition.Decomposition
            Its ``hull`` is the enclosure used (None when both ranges are
            given).  When the enclosure is empty, no point is stable and the
            decomposition has no cells (its window is the curves' extent, or
            the one given).

        Examples
        --------
        >>> loop = Loop("1/(m*s**2 + b*s)", "K + B*(z - 1)/(T*z)",
        ...             values=dict(m=0.0128, b=0.0324, T=1e-3, d=10))
        >>> region = loop.region("B", "K")
        >>> [cell.count for cell in region.stable]
        [0]
        >>> robust = loop.region("B", "K", uncertain={"b": (0.0162, 0.0648)}, strips=16)
        >>> 0 < robust.area < robust.nominal.area
        True
        """
        x, y = self.plane_of(x, y)
        if uncertain is not None:
            from ..analysis.robust import robust_region

            return robust_region(self, x, y, uncertain=uncertain, strips=strips, rtol=rtol,
                                 x_range=x_range, y_range=y_range, progress=progress, **values)
        given = {key: None if window is None else check_window(key, window)
                 for key, window in (("x_range", x_range), ("y_range", y_range))}
        structured, slopes, ends = self.affine_parts((x, y), values, structured=True)
        base, ax, ay = (p.dense().reshape(-1) for p in (structured, *slopes))
        arc = self._arc_source(x, y, values, (structured, *slopes))
        free = {"x_min": given["x_range"] is None, "x_max": given["x_range"] is None,
                "y_min": given["y_range"] is None, "y_max": given["y_range"] is None}

        def run(box):
            if not all(abs(v) <= LARGEST_COORDINATE for v in box):
                raise ValueError(
                    f"the {x}, {y} window {x} in [{box[0]:.3g}, {box[1]:.3g}], {y} in "
                    f"[{box[2]:.3g}, {box[3]:.3g}] goes beyond {LARGEST_COORDINATE:g}, where "
                    f"the cells' areas overflow double precision: give the loop's values in "
                    f"units that keep the plane's numbers smaller")
            return decompose(base, ax, ay, ends, x_range=box[:2], y_range=box[2:], names=(x, y),
                             arc=arc, family=(structured, *slopes))

        # Where a stable point can be at all (exact): an empty enclosure is the
        # answer, a bounded one caps every window a free side may take.
        hull = stable_hull(base, ax, ay) if any(free.values()) else None
        enclosure = hull.box() if hull is not None else None
        if hull is not None and hull.empty:
            auto = _curve_windows(arc, base, ax, ay, ends)[-1]
            box = [*(given["x_range"] or auto[0]), *(given["y_range"] or auto[1])]
            return Decomposition(x=x, y=y, x_range=tuple(box[:2]), y_range=tuple(box[2:]),
                                 branches=(), cells=(), mismatches=(), unbounded=(),
                                 polynomial=(base, ax, ay), hull=hull)
        def fit(box, cells):
            """The free sides of ``box`` fitted to ``cells``, a quarter of their extent around."""
            points = np.vstack([cell.outer for cell in cells])
            box = list(box)
            for k, side in enumerate(free):
                if free[side]:
                    column = points[:, k // 2]
                    lo, hi = float(column.min()), float(column.max())
                    pad = 0.25 * (hi - lo) or 0.05 * (box[k // 2 * 2 + 1] - box[k // 2 * 2])
                    box[k] = lo - pad if k % 2 == 0 else hi + pad
            return box

        found, refused = None, None
        for auto in _start_windows(arc, (structured, *slopes), base, ax, ay, ends, hull):
            box = [*(given["x_range"] or auto[0]), *(given["y_range"] or auto[1])]
            try:
                found = run(box)
            except Unresolved as exc:
                refused = exc
                # A stable cell tiny beside its window (a sliver near a point where
                # three arcs cross, say) can break the finer pass's topology where the
                # coarse pass held: the window narrowed around the stable cells
                # found resolves it (and is checked anew), and the widening below
                # still reaches every side a stable cell touches.
                if not exc.attempt.stable or not any(free.values()):
                    continue
                narrowed = fit(box, exc.attempt.stable)
                if narrowed == box:
                    continue
                try:
                    found, box = run(narrowed), narrowed
                except ValueError:
                    continue
            except ValueError as exc:    # a first window too wide to resolve: try the next
                refused = exc
                continue
            if found.stable:
                break
        if found is None:
            raise refused
        if not found.stable and not _covers(found, enclosure, free):
            # Nothing stable in the windows tried, and they do not hold every
            # point that can be stable: to call the set empty would be a guess.
            if refused is not None:
                raise refused
            raise ValueError(
                f"no stable point in the {x}, {y} windows tried, and the necessary condition "
                f"for stability leaves an unbounded part of the plane (the leading coefficient "
                f"of the loop's polynomial changes in it, say), so a stable set outside them is "
                f"not excluded: give x_range and y_range")
        # Widen the free sides a stable cell reaches (never past the enclosure,
        # which holds the whole stable set); once it reaches none, fit them to
        # the stable set, a quarter of its extent around it.
        limit = [-math.inf, math.inf, -math.inf, math.inf]
        if enclosure is not None:
            limit = [*enclosure[0], *enclosure[1]]
        fitted = not any(free.values())
        for _ in range(12):
            grow = [side for side in found.unbounded if free[side]]
            before = list(box)
            if grow:
                span = (box[1] - box[0], box[3] - box[2])
                for side in grow:
                    k = ("x_min", "x_max", "y_min", "y_max").index(side)
                    box[k] += (-1 if k % 2 == 0 else 1) * span[k // 2]
                    box[k] = max(box[k], limit[k]) if k % 2 == 0 else min(box[k], limit[k])
                if box == before:
                    break
                fitted = False
            elif found.stable and not fitted:
                box = fit(box, found.stable)
                fitted = True
            else:
                break
            found = run(box)
        return dataclasses.replace(found, hull=hull)

    def limits(self, x=None, y=None, **values):
        """The extent and area of the stable set in the ``(x, y)`` plane.

        Read from :meth:`region`: the stable cells' polygons give the area
        (exact up to the chords of the sampled arc), and their extreme
        vertices the extent, refined along the arc by a zooming grid search
        where the extreme is a smooth turn of the arc rather than a corner.

        Parameters
        ----------
        x, y : str
            The plane's parameters, jointly affine (default: the loop's
            :attr:`plane`).
        **values
            Single values of every other parameter (and ``x_range`` /
            ``y_range`` for :meth:`region`; with ``uncertain``, ``strips`` and
            ``rtol``, the robust region's: its limits are then the robust
            set's, with :attr:`~symstab.numeric.engine.results.Limits.region` the
            :class:`~symstab.numeric.engine.results.RobustRegion`).

        Returns
        -------
        symstab.numeric.engine.results.Limits
            Empty (``y_max`` None, ``area`` 0, :attr:`~symstab.numeric.engine.results.Limits.reason`
            says why) when no point is stable: proved, not a failure to find
            one (see :meth:`region`).
        """
        if values.get("uncertain") is not None:
            return self.region(x, y, **values).limits()
        for option in ("uncertain", "strips", "rtol", "progress"):
            if values.pop(option, None) is not None and option != "uncertain":
                raise TypeError(f"{option} is an option of the robust region: give uncertain too")
        found = self.region(x, y, **values)
        at = {k: v for k, v in values.items() if k not in ("x_range", "y_range")}
        return found.limits(at=at, line=functools.partial(_stable_intervals_at, self, found.x,
                                                          found.y, at))

    def simulated_limit(self, x=None, y=None, *, amplitude, nonideal=None, steps=None, x0=None,
                        progress=None, **values):
        """The largest ``y`` at which the simulated loop neither grows nor ends above ``amplitude``.

        The simulated counterpart of :meth:`limits`' ``y_max``, with the
        non-idealities the linear model leaves out (encoder quantization, a
        force limit, Coulomb friction): runs of :meth:`simulate` on a grid over the certified
        stable set, refined in ``y``
        (:func:`symstab.numeric.simulation.simulated_limit.simulated_limit` says how, and
        how accurate it is).  Not certified.

        Parameters
        ----------
        x, y : str, optional
            The plane (default: :attr:`plane`).
        amplitude : float
            The largest ``|x|`` accepted in the last quarter of a run (the
            position's unit).
        nonideal, steps, x0 : optional
            As in :meth:`simulate` (``x0`` default 1, or 0.01 with
            non-idealities).
        progress : callable, optional
            Called with the runs done.
        **values
            Single values of the other parameters.

        Returns
        -------
        symstab.numeric.simulation.simulated_limit.SimulatedLimit

        Examples
        --------
        >>> from symstab.numeric.paper.simulate import Nonidealities
        >>> loop = Loop("1/(m*s**2 + b*s)", "K + B*(z - 1)/(T*z)")
        >>> found = loop.simulated_limit("B", "K", amplitude=1e-3, steps=3000,
        ...                              nonideal=Nonidealities(encoder_resolution=1e-5),
        ...                              m=0.0128, b=0.0324, T=1e-3, d=1)
        >>> 0.9 * found.linear.y_max < found.y_max < found.linear.y_max
        True
        """
        from ..simulation.simulated_limit import simulated_limit

        x, y = self.plane_of(x, y)
        return simulated_limit(self, x=x, y=y, amplitude=amplitude, nonideal=nonideal,
                               steps=steps, x0=x0, progress=progress, **values)

    def passive_region(self, x=None, y=None, *, damping="b", x_range=None, y_range=None, **values):
        """The passive set of the environment behind the loop's delay, in the ``(x, y)`` plane.

        Colgate and Schenkel's condition, with the delay:
        :func:`symstab.numeric.analysis.passivity.passive_region` states the theorem,
        its hypotheses and the construction.

        Parameters
        ----------
        x, y : str, optional
            Environment parameters (in its numerator, jointly affine) or the
            damping (default: the loop's :attr:`plane`).
        damping : str
            The plant parameter that is the device's viscous friction.
        x_range, y_range : (float, float), optional
            The window (default: fitted to the set).
        **values
            Single values of the other parameters.

        Returns
        -------
        symstab.numeric.analysis.passivity.PassiveRegion
        """
        from ..analysis.passivity import passive_region

        return passive_region(self, x, y, damping=damping, x_range=x_range, y_range=y_range,
                              **values)

    def difference_equations(self, **values):
        """The loop's difference equations per point: ``(a, b, c, e)``, ``d`` and the shape.

        The plant's sampled step ``P_d(z) y = P_n(z) u`` and the environment
        ``Ve_d(z) f = Ve_n(z) x_s``, both divided by their leading
        coefficient: ``y[k] = sum_i (b[i] u[k-1-i] - a[i] y[k-1-i])`` and
        ``f[k] = e[0] x_s[k] + sum_i (e[i+1] x_s[k-1-i] - c[i] f[k-1-i])``.
        The loop is closed by ``u[k] = -f[k - d]``, so that its
        characteristic polynomial is :meth:`polynomial`'s ``chi``.

        Parameters
        ----------
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
        values, d, shape = self._prepare(values)
        parts = self._difference_parts(values, shape)
        self._finite(np.concatenate(parts, axis=-1), values)
        return parts, d, shape

    def difference_parts(self, values):
        """:meth:`difference_equations` of the dict ``values``, with coefficients that overflow kept.

        The paper's simulator calls a point whose coefficient overflows (``K
        = 1e308``) a point that diverges at once, as it always has; a loop's
        own run refuses it (:meth:`difference_equations`).

        Parameters
        ----------
        values : dict
            Every parameter (or its default); arrays broadcast.

        Returns
        -------
        ((ndarray, ndarray, ndarray, ndarray), int, tuple)
            As :meth:`difference_equations`.
        """
        values, d, shape = self._prepare(values)
        return self._difference_parts(values, shape), d, shape

    def _difference_parts(self, values, shape):
        """``(a, b, c, e)`` at prepared ``values`` (:meth:`_prepare`) of the broadcast ``shape``."""
        # The coefficients and their working copies, about 64 floats a point.
        check_memory("the loop's difference equations", 8 * int(np.prod(shape)) * 64)
        p_n, p_d, _, _ = self._plant_arrays(values, shape)
        ve_n, ve_d = self._environment_arrays(values, shape)
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

    def friction_spaces(self, substeps, **values):
        """The state spaces in which friction acts: ``(spaces, inverse)``.

        One :class:`~symstab.numeric.simulation.friction.FrictionSpace` per distinct
        plant among the points (``values`` broadcast), and the index of
        each point's (of the broadcast shape).

        Parameters
        ----------
        substeps : int
            Sub-steps per period (:class:`~symstab.numeric.paper.simulate.Nonidealities`).
        **values
            The loop's parameters (or their defaults); arrays broadcast.

        Returns
        -------
        (list of symstab.numeric.simulation.friction.FrictionSpace, ndarray of int)

        Raises
        ------
        ValueError
            When the plant (over :attr:`actuator`) is not a mass's force to
            position, or its state is not determined by its positions.
        """
        values, _, shape = self._prepare(values)
        names = self.plant_names + ("T",)
        columns = np.stack([np.broadcast_to(values[n], shape).ravel() for n in names], axis=-1)
        unique, inverse = np.unique(columns, axis=0, return_inverse=True)
        spaces = [self._friction_space(tuple(float(v) for v in row[:-1]), float(row[-1]), substeps)
                  for row in unique]
        return spaces, inverse.reshape(shape)

    @method_cache(maxsize=256)
    def _friction_space(self, plant_values, T, substeps):
        from ..simulation.friction import DIGITS, friction_space

        with mpmath.workdps(DIGITS):
            coefficients = self.driven_mass(*map(mpmath.mpf, plant_values), mpmath.mpf(T))
        return friction_space(coefficients, T, substeps)

    def simulate(self, *, steps=None, x0=1.0, v0=None, nonideal=None, record=False,
                 progress=None, **values):
        """Run the loop in time for every parameter point at once.

        The plant's exact ZOH step on the samples, the environment's
        difference equation and the delay line
        (:func:`symstab.numeric.paper.simulate.simulate_loop` says how, and which
        non-idealities a loop has); stable when the last quarter of the run
        does not outgrow the third.

        Parameters
        ----------
        steps : int, optional
            Periods (default: 12000 + 800 d).
        x0, v0 : float
            Initial position and its change per period (default ``x0 / 100``).
        nonideal : symstab.numeric.paper.simulate.Nonidealities, optional
            Encoder quantization, force saturation, and Coulomb friction on
            the driven mass (after :attr:`actuator`).
        record : bool
            Keep every position.
        progress : callable, optional
            Called with the number of steps done.
        **values
            The loop's parameters (or their defaults); arrays broadcast.

        Returns
        -------
        symstab.numeric.paper.simulate.Simulation

        Examples
        --------
        >>> loop = Loop("1/(m*s**2 + b*s)", "K + B*(z - 1)/(T*z)")
        >>> run = loop.simulate(K=[100.0, 3000.0], B=0.5, m=0.0128, b=0.0324, T=1e-3, d=1,
        ...                     steps=4000)
        >>> run.stable.tolist()
        [True, False]
        """
        from ..simulation.simulator import simulate_loop

        return simulate_loop(self, steps=steps, x0=x0, v0=v0, nonideal=nonideal, record=record,
                             progress=progress, **values)

    def stability_map(self, x_values, y_values, *, x=None, y=None, steps=None, x0=1.0, v0=None,
                      nonideal=None, progress=None, **values):
        """Stable cells of an ``(x, y)`` grid by simulation (:meth:`simulate` on every cell).

        Parameters
        ----------
        x_values, y_values : array_like
            1-D grids.
        x, y : str, optional
            The plane (default: :attr:`plane`).
        steps, x0, v0, nonideal
            As in :meth:`simulate`.
        progress : callable or True
            ``True`` draws a progress bar on stderr for runs over 2 s.
        **values
            Single values of the other parameters.

        Returns
        -------
        symstab.numeric.paper.simulate.StabilityMap
            ``stable`` of shape ``(len(y_values), len(x_values))``.
        """
        from ..simulation.simulator import loop_stability_map

        x, y = self.plane_of(x, y)
        return loop_stability_map(self, x_values, y_values, x=x, y=y, steps=steps, x0=x0, v0=v0,
                                  nonideal=nonideal, progress=progress, **values)

    def stability_probability(self, x_values, y_values, *, uncertain, samples=1000, seed=0,
                              x=None, y=None, progress=None, **values):
        """The probability that each cell of an ``(x, y)`` grid is stable when parameters are uncertain.

        Monte Carlo over the draws of the uncertain parameters, each cell
        classified by its certified root count at every draw
        (:mod:`symstab.numeric.analysis.probability`).

        Parameters
        ----------
        x_values, y_values : array_like
            1-D grids.
        uncertain : dict
            ``{name: (low, high)}`` (uniform; ``d``: the integers from
            ``low`` to ``high``) or ``{name: distribution}`` (a frozen
            :mod:`scipy.stats` distribution, or any object with
            ``rvs(size=..., random_state=...)``).
        samples : int
            Draws (default 1000).
        seed : int
            The seed: the same seed gives the same map.
        x, y : str, optional
            The plane (default: :attr:`plane`).
        progress : callable, optional
            Called with the number of draws done.
        **values
            Single values of the other parameters.

        Returns
        -------
        symstab.numeric.engine.results.StabilityProbability

        Examples
        --------
        >>> loop = Loop("1/(m*s**2 + b*s)", "K + B*(z - 1)/(T*z)", plane=("B", "K"),
        ...             values={"m": 0.0128, "b": 0.0324, "T": 1e-3, "d": 10})
        >>> found = loop.stability_probability([-0.03, 0.05], [1.0], samples=200,
        ...                                    uncertain={"b": (0.0162, 0.0648)})
        >>> found.probability.tolist(), round(float(found.standard_error[0, 0]), 3)
        ([[0.57, 1.0]], 0.035)
        """
        from ..analysis.probability import stability_probability

        x, y = self.plane_of(x, y)
        return stability_probability(self, x_values, y_values, x=x, y=y, uncertain=uncertain,
                                     samples=samples, seed=seed, progress=progress, **values)

    def design(self, *, over, maximize="y_max", x=None, y=None, n=None, rtol=None, damping="b",
               delay=None, progress=None, amplitude=None, nonideal=None, x0=None, steps=None,
               **values):
        """The value of one or two parameters that maximises K_max, the Z-width, the passive K_max
        or the simulated K_max.

        Each evaluation of the linear targets is a certified answer at one
        value of the searched parameters (:meth:`limits`, or
        :meth:`passive_region` for ``maximize="passive"``); the simulated
        target is :func:`~symstab.numeric.simulation.simulated_limit.simulated_limit`
        (runs of :meth:`simulate` with the non-idealities given).  The
        search is a coarse scan, then
        ``scipy.optimize`` (:mod:`symstab.numeric.analysis.design` says how, and
        what it can miss).

        Parameters
        ----------
        over : dict
            ``{name: (low, high)}``, one or two parameters outside the plane
            (not ``d``), e.g. ``{"M": (0.0, 0.04)}``.
        maximize : str
            ``"y_max"`` (the largest stable ``y``, K_max), ``"area"`` (the
            Z-width), ``"passive"`` (the passive K_max) or ``"simulated"``
            (the largest ``y`` whose simulated run neither grows nor ends
            above ``amplitude``).
        x, y : str, optional
            The plane (default: the loop's :attr:`plane`).
        n : int, optional
            Scan points per parameter, ``>= 3`` (default 17 for one
            parameter, 9 for two).
        rtol : float, optional
            Relative accuracy of the optimum (default 1e-6; 1e-3 for
            ``"simulated"``, which is resolved to its grid).
        damping : str
            The device's viscous friction, for ``maximize="passive"``.
        delay : float, optional
            The loop delay in seconds, held while the sample period ``T``
            is searched: ``d = ceil(delay / T)`` at each value, the whole
            samples that cover it (instead
            of ``d``).
        progress : callable, optional
            Called with the number of evaluations so far.
        amplitude : float
            ``maximize="simulated"`` only (and needed there): the largest
            ``|x|`` accepted in the last quarter of a run (the position's
            unit).
        nonideal, x0, steps : optional
            ``maximize="simulated"`` only: as in :meth:`simulate` (``x0``
            default 1, or 0.01 with non-idealities, as ``symstab design``;
            ``steps`` is periods, so with ``delay`` and ``T`` searched a
            fixed ``steps`` is a shorter time at a smaller ``T``).
        **values
            Single values of the other parameters; the searched ones' values
            here (or defaults) are the nominal point the gain is measured
            against.

        Returns
        -------
        symstab.numeric.analysis.design.Design

        Raises
        ------
        TypeError, ValueError
            For a parameter that is unknown, the delay, an axis of the
            plane, a range that is not ``(low, high)`` with ``low < high``,
            or an unknown target.

        Examples
        --------
        >>> loop = Loop("1/(m*s**2 + b*s)", "K + B*(z - 1)/(T*z) + M*(z - 1)**2/(T**2*z**2)",
        ...             plane=("B", "K"))
        >>> best = loop.design(over={"M": (0.0, 0.03)}, m=0.0128, b=0.0324, T=1e-3, d=1, M=0.0)
        >>> 0.006 < best.best["M"] < 0.02 and best.gain > 2
        True
        """
        from ..analysis.design import design

        x, y = self.plane_of(x, y)
        return design(self, over=over, maximize=maximize, x=x, y=y, n=n, rtol=rtol,
                      damping=damping, delay=delay, progress=progress, amplitude=amplitude,
                      nonideal=nonideal, x0=x0, steps=steps, **values)

    def closed_loop(self, **values):
        """The closed loop from a force at the plant's input to the position.

        ``P / (1 + VE z**-d P) = z**d Ve_d P_n / chi(z)``, built from the
        polynomials (nothing cancelled), so its poles are the roots of
        ``chi``.  Needs python-control.

        Parameters
        ----------
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
        values, d, shape = self._prepare(values, scalar=self.parameters)
        chi = self._coefficients(values, d, shape)
        p_n = self._plant_arrays(values, shape)[0]
        _, ve_d = self._environment_arrays(values, shape)
        num = np.concatenate([self._convolve(ve_d, p_n), np.zeros(d)])
        return control.tf(num, chi, float(values["T"]))


def _rebuilt(plant, environment, options):
    """A :class:`Loop` from its pickled definition (:meth:`Loop.__reduce__`).

    One loop per definition and process: the results that refer to one
    loop (every Limits of a sweep, say) share it, and its derivation.
    """
    key = (sp.srepr(plant), sp.srepr(environment),
           *(tuple(sorted(v.items())) if isinstance(v, dict) else v for v in options.values()))
    if key not in _REBUILT:
        _REBUILT[key] = Loop(plant, environment, **options)
    return _REBUILT[key]


#: The loops rebuilt in this process from pickles, by definition.
_REBUILT = {}


def _stable_intervals_at(loop, x, y, values, at):
    """The stable ``y`` intervals of ``loop`` at ``x = at`` (:attr:`Limits.line`)."""
    return loop.stable_intervals(y, **{x: check_real(x, at)}, **values)


def _shift_to_one(c):
    """Coefficients of ``p(w + 1)`` (``w = z - 1``) from float rows ``c``, with a bound on their rounding.

    Each shifted coefficient is a sum of ``binom(j, k) c_j``; its rounding,
    and the few ulps of the given coefficients, are bounded by a multiple of
    the same sum of ``|c_j|`` (the shift of ``|c|``).
    """
    return (shift_to_one(c, dtype=float),
            (4 * c.shape[-1] + 8) * 2.0**-53 * shift_to_one(np.abs(c), dtype=float))


def _covers(found, enclosure, free):
    """Whether the window of ``found`` reaches ``enclosure`` on every free side."""
    if enclosure is None:
        return not any(free.values())
    window = (*found.x_range, *found.y_range)
    bound = (*enclosure[0], *enclosure[1])
    return all(not free[side] or (window[k] <= bound[k] if k % 2 == 0 else window[k] >= bound[k])
               for k, side in enumerate(("x_min", "x_max", "y_min", "y_max")))


def _start_windows(arc, family, base, ax, ay, ends, hull=None):
    """First windows for :meth:`Loop.region`, tried in turn until one holds a stable cell.

    First the extent of stable points next to the curves (a few steps off
    the arc's points and the lines' crossings, classified at once on the
    structured ``family`` ``(A0, Ax, Ay)``, and only where the ``hull``
    holds them: a point outside it is proved unstable): it is on the scale
    of the stable set however far the arc runs.  Then, when the stable set
    has a bounded enclosure (the box of the
    :func:`symstab.numeric.engine.decomposition.stable_hull`), the enclosure
    itself, which holds every stable point: a stable set too small for the
    steps is found there, and one that is not found there is empty.
    Without one, the extent of the curves themselves, without the outer 2 %
    on each side (the arc may run off to infinity), then all of it.  A
    quarter of the span is added on each side, and each window is cut to
    the enclosure.
    """
    enclosure = hull.box() if hull is not None else None
    xs, ys, _ = _curve_points(arc, base, ax, ay, ends, per_degree=4, first_lobe=64)
    candidates = []
    if xs.size:
        # Steps on each point's own scale: its size and the distance to its
        # neighbour (at long delays the stable set is tiny beside the arc's reach).
        sx = np.abs(xs) + np.abs(np.diff(xs, append=xs[-1])) + 1e-300
        sy = np.abs(ys) + np.abs(np.diff(ys, append=ys[-1])) + 1e-300
        px, py = [], []
        for step in (1e-5, 1e-3, 1e-2, 1e-1):
            for ux, uy in ((1, 1), (1, -1), (-1, 1), (-1, -1)):
                px.append(xs + ux * step * sx)
                py.append(ys + uy * step * sy)
        px, py = np.concatenate(px), np.concatenate(py)
        if hull is not None:
            held = hull.holds(px, py)
            px, py = px[held], py[held]
        codes = classify_polynomials(family[0].combine((px, py), family[1:]), refine=False)
        candidates.append((px[codes == STABLE], py[codes == STABLE], 0.0))
    out = _extent_windows(candidates, enclosure)
    if enclosure is not None:
        out.append(tuple(enclosure))
    else:
        out += [w for w in _curve_windows(arc, base, ax, ay, ends) if w not in out]
    return out or [((-1.0, 1.0), (-1.0, 1.0))]


def _curve_windows(arc, base, ax, ay, ends):
    """The extent of the arc and the lines' crossings: without the outer 2 % on each side, then all."""
    xs, ys, _ = _curve_points(arc, base, ax, ay, ends)
    return _extent_windows([(xs, ys, 0.02), (xs, ys, 0.0)]) or [((-1.0, 1.0), (-1.0, 1.0))]


def _extent_windows(candidates, enclosure=None):
    """A window per ``(xs, ys, q)``: the ``q`` to ``1 - q`` quantiles, a quarter of the span added.

    Each is cut to ``enclosure`` (``(x_range, y_range)``) when given; an
    empty or repeated window is left out.
    """
    out = []
    for cx, cy, q in candidates:
        if cx.size == 0:
            continue
        window = []
        for k, v in enumerate((cx, cy)):
            lo, hi = float(np.quantile(v, q)), float(np.quantile(v, 1 - q))
            pad = 0.25 * (hi - lo) or 0.1 * max(abs(lo), abs(hi), 1e-300)
            lo, hi = lo - pad, hi + pad
            if enclosure is not None:
                lo, hi = max(lo, enclosure[k][0]), min(hi, enclosure[k][1])
            window.append((lo, hi))
        ok = all(np.isfinite(window).ravel()) and all(lo < hi for lo, hi in window)
        if ok and tuple(window) not in out:
            out.append(tuple(window))
    return out


def _curve_points(arc, base, ax, ay, ends, per_degree=16, first_lobe=0):
    """Points of the arc (finite ones, from the loop's arc source ``arc``) and the lines' crossings.

    The arc at ``per_degree (n + 4)`` angles, plus ``first_lobe`` more below
    ``8 pi / (n + 4)``, where at long delays the stable set's arc lies, and
    with ``first_lobe`` 24 more spaced geometrically from ``1e-6`` of the
    first angle up to it, and as many next to pi: a stable set next to an
    end of the arc can be bounded by a piece far shorter than the grid's
    step (at gamma = -1 the paper's loop has its whole set below theta =
    0.03, under the first angle of a grid of 48).
    """
    n = len(base) - 1
    m = per_degree * (n + 4)
    theta = np.pi * (np.arange(1, m + 1) - 0.5) / m
    if first_lobe:
        lobe = 8 * np.pi / (n + 4) * np.arange(1, first_lobe + 1) / first_lobe
        near = theta[0] * np.geomspace(1e-6, 1.0, 24, endpoint=False)
        theta = np.union1d(theta, np.concatenate([lobe, near, np.pi - near]))
    xs, ys, _ = arc(theta)
    lines = list(_lines(base, ax, ay, ends).values())
    for i in range(len(lines)):
        for j in range(i + 1, len(lines)):
            (c0, c1, c2), (e0, e1, e2) = lines[i], lines[j]
            det = c1 * e2 - c2 * e1
            if det != 0:
                xs = np.append(xs, (-c0 * e2 + c2 * e0) / det)
                ys = np.append(ys, (-c1 * e0 + c0 * e1) / det)
    keep = np.isfinite(xs) & np.isfinite(ys)
    return xs[keep], ys[keep], theta
