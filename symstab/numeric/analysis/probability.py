"""The probability that each point of a loop's plane is stable when some parameters are uncertain.

A device's mass and damping are identified with errors, a network's delay
varies: given a distribution for each uncertain parameter,
:func:`stability_probability` draws ``samples`` values of them (one random
generator, seeded: the same seed gives the same map) and classifies every
cell of an ``(x, y)`` grid at every draw with the loop's certified root
count (:meth:`symstab.Loop.classify`).  The probability of a cell is the
fraction of draws at which it is stable (a marginal draw, a root on the
unit circle to within rounding, counts as not stable and is counted
apart), with the Monte Carlo standard error ``sqrt(p (1 - p) / samples)``.

Distributions: ``(low, high)`` is uniform on that interval (for the delay
``d`` with whole ends, the integers from ``low`` to ``high``; with a
fractional end, or ``Td`` in seconds, every delay between, fractions of a
period included); any object with SciPy's
``rvs(size=..., random_state=...)`` (a frozen :mod:`scipy.stats`
distribution, e.g. ``scipy.stats.norm(0.0324, 0.003)``) is drawn from.
Draws outside the bounds a loop file declares are refused by name.

A delay drawn in fractions of a period (``d`` fractional, ``Td`` in
seconds, or a delay held in seconds while ``T`` is drawn) is ``Td / T``
samples per draw; the draws are classified in groups of one whole part
(a call of :meth:`symstab.Loop.classify` takes one whole ``d`` and each
draw's fraction).
"""

import numpy as np

from ..._resources import CHUNK_BYTES, check_memory, max_delay
from ..._validate import check_delay, check_grid, check_progress, check_real, snap_delay
from ..engine.results import StabilityProbability
from ..engine.roots import MARGINAL, STABLE

__all__ = ["stability_probability", "draw_values", "MAX_SAMPLES"]

#: The most draws per map: its standard error is then at most 5e-4 (a cell
#: with p = 1/2); more is time, not information.
MAX_SAMPLES = 1_000_000
#: Floats of a cell's characteristic polynomial and its work (as the loop's own
#: check_memory counts them): the chunk of draws classified at once.
_CELL_FLOATS = 64


def draw_values(loop, uncertain, samples, seed, *, axes=()):
    """``{name: ndarray of samples}``: the draws of each uncertain parameter, in the order given.

    Parameters
    ----------
    loop : symstab.Loop
    uncertain : dict
        ``{name: (low, high)}`` (uniform; ``d`` with whole ends: integers
        ``low .. high``) or ``{name: distribution}`` (an object with
        ``rvs(size=..., random_state=...)``); the delay as ``d`` (samples)
        or ``Td`` (seconds), not both.
    samples : int
        Draws, 1 to :data:`MAX_SAMPLES`.
    seed : int
        Seed of :func:`numpy.random.default_rng`.
    axes : tuple of str
        The plane's parameters, which cannot be uncertain.

    Raises
    ------
    TypeError, ValueError
        Naming the parameter: not the loop's, an axis, a range that is not
        two finite numbers with ``low < high`` (``low <= high`` for ``d``
        with whole ends), a distribution without ``rvs``, a draw that is
        not finite, a delay drawn below 0 or beyond the limit.
    """
    if not isinstance(uncertain, dict) or not uncertain:
        raise TypeError(f"uncertain must be a non-empty dict {{name: (low, high) or distribution}}, "
                        f"got {uncertain!r}")
    if isinstance(samples, (bool, np.bool_)) or not isinstance(samples, (int, np.integer)) \
            or not 1 <= samples <= MAX_SAMPLES:
        raise ValueError(f"samples must be an integer from 1 to {MAX_SAMPLES}, got {samples!r}")
    if isinstance(seed, (bool, np.bool_)) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise ValueError(f"seed must be a non-negative integer, got {seed!r}")
    rng = np.random.default_rng(int(seed))
    draws = {}
    if "d" in uncertain and "Td" in uncertain:
        raise TypeError("uncertain: give the delay once, d (in samples) or Td (in seconds)")
    for name, spec in uncertain.items():
        if name not in loop.parameters and name != "Td":
            raise ValueError(f"uncertain: {name!r} is not a parameter of the loop "
                             f"(its parameters: {', '.join(loop.parameters)})")
        if name in axes:
            raise ValueError(f"uncertain: {name} is an axis of the ({axes[0]}, {axes[1]}) plane; "
                             f"a map's axes are not drawn")
        where = f"uncertain[{name!r}]"
        if hasattr(spec, "rvs"):
            values = np.asarray(spec.rvs(size=int(samples), random_state=rng), dtype=float)
            if values.shape != (samples,) or not np.all(np.isfinite(values)):
                raise ValueError(f"{where}: the distribution must draw {samples} finite numbers")
        elif isinstance(spec, (tuple, list)) and len(spec) == 2:
            low, high = (check_real(f"{where} bounds", v) for v in spec)
            if name == "d" and float(low).is_integer() and float(high).is_integer():
                low, high = check_delay(spec[0]), check_delay(spec[1])
                if low > high:
                    raise ValueError(f"{where}: (low, high) must have low <= high, got {spec!r}")
                values = rng.integers(low, high, endpoint=True, size=int(samples)).astype(float)
            else:
                if not low < high or not np.isfinite(high - low):
                    raise ValueError(f"{where}: (low, high) must have low < high (and a finite "
                                     f"width), got {spec!r}")
                values = rng.uniform(low, high, size=int(samples))
        else:
            raise TypeError(f"{where} must be (low, high) or a distribution with rvs(size=..., "
                            f"random_state=...), got {spec!r}")
        draws[name] = values
    for name in ("d", "Td"):
        if name in draws and draws[name].min() < 0:
            raise ValueError(f"uncertain[{name!r}]: a delay is >= 0, a draw is "
                             f"{draws[name].min()!r}")
    if "d" in draws and draws["d"].max() > max_delay():
        check_delay(int(np.ceil(draws["d"].max())))     # names the limit and how to raise it
    return draws


def _delay_draws(loop, draws, values):
    """Each draw's delay in samples (``Td / T``, fractional), or None where it is one ``d``.

    The delay varies over the draws when ``d`` or ``Td`` is drawn, or when
    ``T`` is drawn and the delay is held in seconds (``Td`` given or the
    loop's own).
    """
    if "d" in draws:
        return draws["d"]
    seconds = draws.get("Td")
    if seconds is None and "T" in draws:
        if "Td" in values:
            seconds = values["Td"]
        elif "d" not in values and "Td" in loop.defaults:
            seconds = loop.defaults["Td"]
    if seconds is None:
        return None
    period = draws.get("T", values.get("T", loop.defaults.get("T")))
    if period is None:
        raise TypeError("uncertain: a delay in seconds (Td) needs the sample period T's value")
    return snap_delay(seconds / np.asarray(period, dtype=float))


def stability_probability(loop, x_values, y_values, *, x, y, uncertain, samples=1000, seed=0,
                          progress=None, **values):
    """The probability that each cell of an ``(x, y)`` grid is stable when parameters are uncertain.

    Monte Carlo over the draws of the uncertain parameters, each cell
    classified by its certified root count at every draw (the module says
    how).

    Parameters
    ----------
    loop, x_values, y_values
        As in :func:`symstab.numeric.simulation.simulator.loop_stability_map`,
        which maps the same grid by simulation.
    uncertain : dict
        ``{name: (low, high)}`` (uniform; ``d`` with whole ends: the
        integers from ``low`` to ``high``; ``d`` with a fractional end or
        ``Td`` in seconds: continuous) or ``{name: distribution}`` (a frozen
        :mod:`scipy.stats` distribution, or any object with
        ``rvs(size=..., random_state=...)``); :func:`draw_values`.
    samples : int
        Draws (default 1000: a standard error of at most 0.016).
    seed : int
        The random generator's seed: the same seed, the same map.
    x, y : str
        The plane (:meth:`symstab.Loop.stability_probability` takes the
        loop's :attr:`~symstab.Loop.plane` by default).
    progress : callable, bool or None, optional
        Called with the number of draws done; True draws a bar
        (``symstab._validate.check_progress``).
    **values
        Single values of the other parameters (defaults for the rest).

    Returns
    -------
    StabilityProbability

    Raises
    ------
    TypeError, ValueError
        As :func:`draw_values` and :meth:`symstab.Loop.classify`; a draw
        outside a loop file's bounds; a grid that does not fit in memory.

    Examples
    --------
    >>> from symstab import Loop
    >>> loop = Loop("1/(m*s**2 + b*s)", "K + B*(z - 1)/(T*z)", plane=("B", "K"),
    ...             values={"m": 0.0128, "b": 0.0324, "T": 1e-3, "d": 10})
    >>> found = stability_probability(loop, [-0.03, 0.05], [1.0], x="B", y="K", samples=200,
    ...                               uncertain={"b": (0.0162, 0.0648)})
    >>> found.probability.tolist(), round(float(found.standard_error[0, 0]), 3)
    ([[0.57, 1.0]], 0.035)
    """
    x_values, y_values = check_grid(x, y, x_values, y_values, values)
    draws = draw_values(loop, uncertain, samples, seed, axes=(x, y))
    for name in draws:
        if name in values or (name in ("d", "Td") and {"d", "Td"} & set(values)):
            raise TypeError(f"{name} is uncertain: give its distribution, not a value "
                            f"(of the delay: neither d nor Td)")
    from ..._progress import progress_printer

    progress = check_progress(progress, lambda: progress_printer("drawing", samples))
    known = getattr(loop, "file_parameters", None)
    if known is not None:
        from ..loop.quantities import check_bounds

        fixed = {k: v for k, v in {**loop.defaults, **values}.items() if k not in draws}
        check_bounds(known, {**fixed, **draws}, skip=(x, y),
                     where=lambda names: "uncertain: a draw of " + ", ".join(names))
    cells = x_values.size * y_values.size
    check_memory(f"a map of {cells} cells", 8 * 4 * cells + 8 * _CELL_FLOATS * cells)
    per_chunk = max(1, CHUNK_BYTES // (8 * _CELL_FLOATS * cells))
    Y, X = np.meshgrid(y_values, x_values, indexing="ij")
    stable = np.zeros(Y.shape, dtype=np.int64)
    marginal = np.zeros(Y.shape, dtype=np.int64)
    # Draws of one whole delay are classified together (a call takes one whole d, and each
    # draw's fraction of a period).
    delays = _delay_draws(loop, draws, values)
    wholes = None if delays is None else np.floor(delays)
    groups = ([np.arange(samples)] if delays is None
              else [np.flatnonzero(wholes == d) for d in np.unique(wholes)])
    done = 0
    for group in groups:
        fixed = {k: v for k, v in values.items() if delays is None or k not in ("d", "Td")}
        for start in range(0, group.size, per_chunk):
            part = group[start:start + per_chunk]
            drawn = {name: v[part][:, None, None] for name, v in draws.items()
                     if name not in ("d", "Td")}
            if delays is not None:
                drawn["d"] = delays[part][:, None, None]
            codes = np.asarray(loop.classify(**{x: X[None], y: Y[None]}, **drawn, **fixed))
            codes = np.broadcast_to(codes, (part.size,) + Y.shape)
            stable += np.count_nonzero(codes == STABLE, axis=0)
            marginal += np.count_nonzero(codes == MARGINAL, axis=0)
            done += part.size
            if progress is not None:
                progress(done)
    probability = stable / samples
    varied = set(draws) | ({"d", "Td"} if delays is not None else set())
    at = {k: v for k, v in {**loop.defaults, **values}.items() if k not in (x, y)
          and k not in varied}
    return StabilityProbability(
        y_values=y_values, x_values=x_values, probability=probability,
        standard_error=np.sqrt(probability * (1 - probability) / samples), marginal=marginal,
        samples=int(samples), seed=int(seed),
        uncertain={k: _describe(k, v) for k, v in uncertain.items()},
        x=x, y=y, at=at)


def _describe(name, spec):
    """The distribution of ``name`` in words, for the result and its files."""
    if hasattr(spec, "rvs"):
        dist = getattr(spec, "dist", None)
        name = getattr(dist, "name", type(spec).__name__)
        args = ", ".join(f"{a:g}" for a in getattr(spec, "args", ()))
        kwds = ", ".join(f"{k}={v:g}" for k, v in getattr(spec, "kwds", {}).items())
        return f"{name}({', '.join(p for p in (args, kwds) if p)})"
    if name == "d" and float(spec[0]).is_integer() and float(spec[1]).is_integer():
        return f"the integers {int(spec[0])} to {int(spec[1])}, equally likely"
    return f"uniform({float(spec[0]):g}, {float(spec[1]):g})"
