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

The loop holds the model; its numbers are its :attr:`Loop.evaluation`
(:mod:`symstab.numeric.loop.evaluation`) and its questions module functions
that take it (the plane's in :mod:`symstab.numeric.loop.plane`, the others
in :mod:`symstab.numeric.analysis` and :mod:`symstab.numeric.simulation`),
which its methods pass through to.

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

import functools
import warnings

import sympy as sp

from ...codegen.loop_kernels import environment_kernels, load_numpy_kernels
from ...symbolic.loop_assembly import LoopModel, parse_environment, parse_plant
from ..engine.results import Boundary, Limits
from .evaluation import (
    LoopEvaluation,
    classify,
    closed_loop,
    difference_equations,
    difference_parts,
    is_stable,
    spectral_radius,
    unstable_root_counts,
)
from .plane import boundary, limits, region, stable_intervals

__all__ = ["Loop", "LoopLimits", "LoopBoundary", "parse_plant", "parse_environment"]


#: Older name of :class:`symstab.numeric.engine.results.Limits`, the one result type of ``limits``.
LoopLimits = Limits


#: Older name of :class:`symstab.numeric.engine.results.Boundary`, the one result type of a boundary.
LoopBoundary = Boundary


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
        A word for reprs and generated files (ASCII letters, digits, ``_-.``).
    units : dict, optional
        The SI unit of each parameter, as text, e.g. ``{"K": "N/m"}``: a unit not SI
        (``"ms"``) or whose dimensions do not fit is refused (a loop file's are converted,
        :func:`symstab.load_loop`).
    description : str, optional
        One line on what the loop is.
    plane : (str, str), optional
        The default ``(x, y)`` plane of :meth:`boundary` and :meth:`limits`
        (for example ``("B", "K")``); checked to be jointly affine.
    arc : callable, optional
        The loop's arc in closed form, where SymPy derived one (whole delays):
        ``arc(x, y, values)`` gives ``theta -> (x, y)``, the point of the plane
        where ``exp(j theta)`` is a root (NaN where the form loses its digits),
        or None for a plane it does not cover (the paper's loop: eq. (7)).
    polynomial : callable, optional
        ``chi`` in closed form, where SymPy derived one (whole delays):
        ``polynomial(values, d)`` gives a
        :class:`~symstab.numeric.engine.polynomial.DelayedPolynomial` with its
        roots at ``values`` (arrays that broadcast), whose roots
        :meth:`classify` and the root counts count (the paper's loop: eq. (5),
        exact next to ``z = 1``); :meth:`polynomial` stays the loop's own.
    actuator : str or sympy.Expr, optional
        ``A(s)``, the factor of the plant from the force command to the
        force on the driven mass (an amplifier's lag, ``"1/(tau*s + 1)"``);
        default ``1``.  Coulomb friction acts on the mass, after it
        (:meth:`simulate`); ``plant / actuator`` must be a mass's force to
        position (relative degree 2).

    Attributes
    ----------
    parameters : tuple of str
        The names of the loop's parameters: the plant's and the
        environment's, then ``T`` and ``d``, the delay in samples (whole or
        not; every question also takes ``Td``, the delay in seconds, instead).
    zoh_method : str
        ``'residues'`` (the plant's pulse transfer function derived
        symbolically) or ``'matrix exponential'`` (numerically, at 30 digits).
    plane : (str, str) or None
        The default ``(x, y)`` plane.
    defaults : dict
        The default value of each parameter that has one.
    units : dict
        The SI unit of each parameter that has one, as text.
    evaluation : symstab.numeric.loop.evaluation.LoopEvaluation
        ``chi`` and its parts in floats: what the loop's questions compute on.

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
        self.evaluation = LoopEvaluation(
            self, plant=self._numeric_plant, exact_plant=self._exact_plant,
            plant_parts=self.plant_parts_of, kernels=lambda: self._kernels,
            closed_polynomial=polynomial, closed_arc=arc)
        if self.units:
            self._check_units()

    def __reduce__(self):
        # Rebuilt from its definition (the kernels are compiled again on first
        # use): a loop, and a result that refers to it, travel to a worker process.
        return (_rebuilt, (self.plant, self.environment, {
            "values": dict(self.defaults), "name": self.name, "units": dict(self.units),
            "description": self.description, "plane": self.plane, "arc": self._arc,
            "polynomial": self._closed_polynomial, "actuator": self.actuator}))

    def _repr_latex_(self):
        """Jupyter's view: :func:`~symstab.numeric.loop.display.loop_latex` of this loop."""
        from .display import loop_latex

        return loop_latex(self.plant, self.environment, self.environment_parts,
                          self._plant_parts)

    def _check_units(self):
        from .quantities import check_si_units

        check_si_units(self)

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

    def coefficients(self, **values):
        """Coefficients of ``chi(z)`` (highest power first), divided by ``P_d``'s leading one.

        Dense: for short delays and for comparisons; the loop's own
        computations keep ``chi`` structured (:meth:`polynomial`).

        Parameters
        ----------
        **values
            As :meth:`polynomial`'s.

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
            Every parameter (:attr:`parameters`) or its default, arrays broadcast;
            ``d`` in samples, whole or not (``P_eps = N_eps / (z P_d)``), or ``Td``.
        """
        return self.evaluation.polynomial(values)

    def spectral_radius(self, **values):
        """Largest modulus of the closed-loop poles.

        See :func:`symstab.numeric.loop.evaluation.spectral_radius`.
        """
        return spectral_radius(self, **values)

    def classify(self, **values):
        """Stable (1), marginal (0) or unstable (-1) at each point.

        See :func:`symstab.numeric.loop.evaluation.classify`.
        """
        return classify(self, **values)

    def is_stable(self, **values):
        """Whether each point is stable: bool, or a masked bool array (masked = marginal).

        See :func:`symstab.numeric.loop.evaluation.is_stable`.
        """
        return is_stable(self, **values)

    def unstable_root_counts(self, **values):
        """Certified number of closed-loop poles outside the unit circle (-1: marginal).

        See :func:`symstab.numeric.loop.evaluation.unstable_root_counts`.
        """
        return unstable_root_counts(self, **values)

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
        return self.evaluation.affine_parts(names, given, structured=structured)

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
        >>> import numpy as np
        >>> B, K, det = loop.arc("B", "K")(np.array([0.05]))
        >>> bool(K[0] > 0)
        True
        """
        x, y = self.plane_of(x, y)
        structured, slopes, _ = self.affine_parts((x, y), values, structured=True)
        return self.evaluation.arc_source(x, y, values, (structured, *slopes))

    def stable_intervals(self, name, **values):
        """The stable intervals of one parameter, the others fixed.

        See :func:`symstab.numeric.loop.plane.stable_intervals`.
        """
        return stable_intervals(self, name, **values)

    def boundary(self, x=None, y=None, n=1000, *, window=None, segments=False, **values):
        """The D-decomposition of the ``(x, y)`` plane.

        See :func:`symstab.numeric.loop.plane.boundary`.
        """
        return boundary(self, x, y, n, window=window, segments=segments, **values)

    def region(self, x=None, y=None, *, x_range=None, y_range=None, uncertain=None, strips=64,
               rtol=1e-6, progress=None, delay_range=None, **values):
        """The complete D-decomposition of the ``(x, y)`` plane: cells, root counts, stable set.

        See :func:`symstab.numeric.loop.plane.region`.

        Parameters
        ----------
        delay_range : (float, float), optional
            ``(Td_min, Td_max)``, seconds: instead, the two sets of the range,
            :func:`symstab.numeric.analysis.delay_range.delay_range_region`.
        strips, rtol, progress : optional
            Of the robust region of ``delay_range`` (or of ``uncertain``).
        uncertain : dict, optional
            Deprecated: the robust region is :meth:`robust_region`'s, which
            ``uncertain`` calls with a DeprecationWarning.
        """
        return _region(self, x, y, x_range, y_range, delay_range, (uncertain, strips, rtol,
                                                                    progress), values)

    def robust_region(self, x=None, y=None, *, uncertain, strips=64, rtol=1e-6, x_range=None,
                      y_range=None, progress=None, **values):
        """The points of the ``(x, y)`` plane stable for every value in a box.

        See :func:`symstab.numeric.analysis.robust.robust_region`.
        """
        from ..analysis.robust import robust_region

        return robust_region(self, x, y, uncertain=uncertain, strips=strips, rtol=rtol,
                             x_range=x_range, y_range=y_range, progress=progress, **values)

    def limits(self, x=None, y=None, **values):
        """The extent and area of the stable set in the ``(x, y)`` plane (robust with uncertain).

        See :func:`symstab.numeric.loop.plane.limits`; with ``uncertain``, the
        limits of :meth:`robust_region`.
        """
        if values.get("uncertain") is not None:
            return self.robust_region(x, y, **values).limits()
        return limits(self, x, y, **values)

    def simulated_limit(self, x=None, y=None, *, amplitude, nonideal=None, steps=None, x0=None,
                        progress=None, **values):
        """The largest ``y`` at which the simulated loop neither grows nor ends above ``amplitude``.

        See :func:`symstab.numeric.simulation.simulated_limit.simulated_limit`.
        """
        from ..simulation.simulated_limit import simulated_limit

        return simulated_limit(self, x=x, y=y, amplitude=amplitude, nonideal=nonideal,
                               steps=steps, x0=x0, progress=progress, **values)

    def margins(self, *, parameters=None, delay_limit=None, rtol=1e-9, **values):
        """The margins at a stable point: modulus, gain, phase, parameter and delay.

        See :func:`symstab.numeric.analysis.margins.margins`."""
        from ..analysis.margins import margins

        return margins(self, parameters=parameters, delay_limit=delay_limit, rtol=rtol, **values)

    def delay_margin(self, *, limit=None, step=None, every=None, **values):
        """The exact delay margin at a stable point, and where stability switches.

        See :func:`symstab.numeric.analysis.delays.delay_margin`."""
        from ..analysis.delays import delay_margin

        return delay_margin(self, limit=limit, step=step, every=every, **values)

    def delay_range(self, x_values=None, y_values=None, *, delay_range, **values):
        """Every delay of a range, at a point or (given ``x_values, y_values``) a grid's.

        See :func:`symstab.numeric.analysis.delay_range.delay_range_map` (a point: ``delay_range``)."""
        from ..analysis import delay_range as rooms

        if x_values is None and y_values is None:
            return rooms.delay_range(self, delay_range=delay_range, **values)
        return rooms.delay_range_map(self, x_values, y_values, delay_range=delay_range, **values)

    def force_noise(self, *, encoder_resolution, **values):
        """The force RMS of the encoder's quantization at a stable point.

        See :func:`symstab.numeric.analysis.noise.force_noise`."""
        from ..analysis.noise import force_noise

        return force_noise(self, encoder_resolution=encoder_resolution, **values)

    def margin_map(self, x_values, y_values, *, x=None, y=None, margin="modulus", **values):
        """A margin over a grid of the plane, NaN where not stable.

        See :func:`symstab.numeric.analysis.margins.margin_map`."""
        from ..analysis.margins import margin_map

        return margin_map(self, x_values, y_values, x=x, y=y, margin=margin, **values)

    def passive_region(self, x=None, y=None, *, damping="b", x_range=None, y_range=None, **values):
        """The passive set of the environment behind the loop's delay, in the ``(x, y)`` plane.

        See :func:`symstab.numeric.analysis.passivity.passive_region`.
        """
        from ..analysis.passivity import passive_region

        return passive_region(self, x, y, damping=damping, x_range=x_range, y_range=y_range,
                              **values)

    def simulate(self, *, steps=None, x0=1.0, v0=None, nonideal=None, record=False,
                 progress=None, compensation=None, start="samples", overflow="raise", **values):
        """Run the loop in time for every parameter point at once (``delays=``: a varying delay).

        See :func:`symstab.numeric.simulation.simulator.simulate_loop`.
        """
        from ..simulation.simulator import simulate_loop

        return simulate_loop(self, steps=steps, x0=x0, v0=v0, nonideal=nonideal, record=record,
                             progress=progress, compensation=compensation, start=start,
                             overflow=overflow, **values)

    def stability_map(self, x_values, y_values, *, x=None, y=None, steps=None, x0=1.0, v0=None,
                      nonideal=None, progress=None, **values):
        """Stable cells of an ``(x, y)`` grid by simulation (:meth:`simulate` on every cell).

        See :func:`symstab.numeric.simulation.simulator.loop_stability_map`.
        """
        from ..simulation.simulator import loop_stability_map

        return loop_stability_map(self, x_values, y_values, x=x, y=y, steps=steps, x0=x0, v0=v0,
                                  nonideal=nonideal, progress=progress, **values)

    def stability_probability(self, x_values, y_values, *, uncertain, samples=1000, seed=0,
                              x=None, y=None, progress=None, **values):
        """The probability that each cell of an ``(x, y)`` grid is stable when parameters are uncertain.

        See :func:`symstab.numeric.analysis.probability.stability_probability`.
        """
        from ..analysis.probability import stability_probability

        x, y = self.plane_of(x, y)
        return stability_probability(self, x_values, y_values, x=x, y=y, uncertain=uncertain,
                                     samples=samples, seed=seed, progress=progress, **values)

    def design(self, *, over, maximize="y_max", x=None, y=None, n=None, rtol=None, damping="b",
               delay=None, progress=None, amplitude=None, nonideal=None, x0=None, steps=None,
               noise_limit=None, encoder_resolution=None, noise_at=None, **values):
        """The value of one or two parameters that maximises a target (K_max, the Z-width, ...).

        See :func:`symstab.numeric.analysis.design.design`.
        """
        from ..analysis.design import design

        x, y = self.plane_of(x, y)
        return design(self, over=over, maximize=maximize, x=x, y=y, n=n, rtol=rtol,
                      damping=damping, delay=delay, progress=progress, amplitude=amplitude,
                      nonideal=nonideal, x0=x0, steps=steps, noise_limit=noise_limit,
                      encoder_resolution=encoder_resolution, noise_at=noise_at, **values)

    def difference_equations(self, **values):
        """The loop's difference equations per point: ``(a, b, c, e)``, ``d`` and the shape.

        See :func:`symstab.numeric.loop.evaluation.difference_equations`.
        """
        return difference_equations(self, **values)

    def difference_parts(self, values):
        """:meth:`difference_equations` of the dict ``values``, coefficients that overflow kept.

        See :func:`symstab.numeric.loop.evaluation.difference_parts`.
        """
        return difference_parts(self, values)

    def friction_spaces(self, substeps, **values):
        """The state spaces in which friction acts: ``(spaces, inverse)``.

        See :func:`symstab.numeric.simulation.friction.friction_spaces`.
        """
        from ..simulation.friction import friction_spaces

        return friction_spaces(self, substeps, **values)

    def closed_loop(self, **values):
        """The closed loop from a force at the plant's input to the position (python-control).

        See :func:`symstab.numeric.loop.evaluation.closed_loop`.
        """
        return closed_loop(self, **values)


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


def _region(loop, x, y, x_range, y_range, delay_range, robust, values):
    """:meth:`Loop.region`: the decomposition, a delay range's sets, or (deprecated) a robust region."""
    uncertain, strips, rtol, progress = robust
    if delay_range is not None:
        from ..analysis.delay_range import delay_range_region

        if uncertain is not None:
            values = {**values, "uncertain": uncertain}     # refused there, with what to do
        return delay_range_region(loop, x, y, delay_range=delay_range, x_range=x_range,
                                  y_range=y_range, strips=strips, rtol=rtol, progress=progress,
                                  **values)
    if uncertain is not None:
        warnings.warn("Loop.region(uncertain=...) is deprecated: use Loop.robust_region "
                      "(or symstab.numeric.analysis.robust.robust_region)",
                      DeprecationWarning, stacklevel=3)
        return loop.robust_region(x, y, uncertain=uncertain, strips=strips, rtol=rtol,
                                  x_range=x_range, y_range=y_range, progress=progress, **values)
    return region(loop, x, y, x_range=x_range, y_range=y_range, **values)
