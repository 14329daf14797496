"""Units of a loop file's parameters: converted to coherent SI with pint, or refused.

The derivation is written in coherent SI (s, Hz = 1/s, kg, N s/m, N/m,
kg m^2, N m s/rad, N m/rad; an angle is dimensionless, as in SI), so every
value a loop file gives with a unit is converted to SI once, when the file
is read, and a unit pint does not know, an offset unit (degC) or a unit of
the wrong dimension is refused naming the parameter, the unit given and
the one expected.  A bare number (no unit) is taken as given, in SI, and
its dimension is not checked.

Dimensions are checked on the expression trees of the plant and the
environment, as a linear system in the exponents of the base dimensions
(``_check_dimensions``): terms that are added have one dimension, the
argument of ``exp`` and a symbolic exponent are dimensionless, ``s`` is
1/time and ``z`` dimensionless, ``T`` is a time, the environment ``VE(z)``
maps displacement to force (N/m, or N m/rad for a rotary device) and the
plant ``G(s)`` force to displacement (the loop gain ``VE G`` is
dimensionless).  A parameter without a unit is an unknown of that system,
so a file mixing bare numbers and units is checked as far as its units go.
This is an analysis of the dimensions, not an evaluation at numbers, so a
value of 0 or a sum that cancels at the file's values cannot hide (or fake)
an inconsistency.

A parameter may also declare bounds, as data: ``min``/``max`` (closed),
``above``/``below`` (open), each a number in the parameter's own unit or
an expression of the loop's parameters in SI (built by the loop's safe
expression parser, never evaluated as code), e.g. ``below = "1/(2*T)"``
(the Nyquist frequency).  :func:`check_bounds` refuses a value outside with
the wording of ``symstab._validate.check_real``.

pint is imported, and its one :func:`unit_registry` built, on the first
unit met: it takes about half a second, which a command without units
should not pay.
"""

import dataclasses
import fractions
import functools
import math
import re

import numpy as np
import sympy as sp

__all__ = ["unit_registry", "check_si_units", "ALLOWED_UNITS", "UnitInfo", "unit_info", "dimension_name", "FileValue", "Bound", "FileParameters",
           "read_parameters", "check_loop_units", "convert", "check_bounds", "SAMPLE_UNITS",
           "parameter_angle", "check_angle"]

#: The only units of the delay ``d``, a number of samples (40 or 40.5); the
#: delay in time is ``Td``, in a unit of time (``Td = { value = 40.5, unit = "ms" }``).
SAMPLE_UNITS = ("samples", "sample")
#: Keys of a parameter's table in a loop file.
ENTRY_KEYS = ("value", "unit", "min", "max", "above", "below")
#: The bound keys: (closed or open, lower or upper).
_BOUND_KINDS = {"min": (False, "low"), "above": (True, "low"),
                "max": (False, "high"), "below": (True, "high")}
_BASES = ("[mass]", "[length]", "[time]", "[current]", "[temperature]", "[substance]",
          "[luminosity]")
_BASE_SYMBOLS = {"[mass]": "kg", "[length]": "m", "[time]": "s", "[current]": "A",
                 "[temperature]": "K", "[substance]": "mol", "[luminosity]": "cd"}
#: Coherent SI names by (mass, length, time) exponents and angle exponent; what
#: is not here is written in base units (kg m^2 s^-3 ...).
_SI_NAMES = {
    ((0, 0, 0), 0): "1", ((0, 0, 0), 1): "rad",
    ((0, 0, 1), 0): "s", ((0, 0, -1), 0): "Hz", ((1, 0, 0), 0): "kg", ((0, 1, 0), 0): "m",
    ((1, 0, -1), 0): "N s/m", ((1, 0, -2), 0): "N/m", ((1, 1, -2), 0): "N",
    ((1, 2, 0), 0): "kg m^2", ((1, 2, -1), -1): "N m s/rad", ((1, 2, -2), -1): "N m/rad",
    ((1, 2, -1), 0): "N m s", ((1, 2, -2), 0): "N m",
}
#: An exponent in a unit: a number of at most two digits (a power of a power,
#: or 10**10**10, would make pint compute for ever).
_EXPONENT = re.compile(r"(\*\*|\^)\s*(\(\s*)?[+-]?\d{1,2}(\.\d{1,3})?(\s*/\s*\d{1,2})?\s*\)?")
_POWER = re.compile(r"\*\*|\^")
#: A unit's names: a letter, then letters, digits or ``_``.
_NAME = re.compile(r"[^\W\d_]\w*")
#: What may stand between the names (and exponents) of a unit.
_JOINERS = re.compile(r"[\s*/()\u00b7]*")
#: The units a loop file may name, by pint's canonical name, each with any
#: decimal SI prefix (and pint's plural ``s``).  pint knows far more names,
#: and some of them would scale a value silently: ``%`` (percent), ``alpha``
#: (the fine-structure constant), ``c`` (the speed of light), ``Nm`` (a
#: "number meter"); a name outside this list is refused instead.
ALLOWED_UNITS = frozenset({
    "meter", "inch", "foot", "gram", "pound", "ounce", "second", "minute", "hour",
    "newton", "force_pound", "force_ounce", "force_kilogram", "force_gram", "hertz",
    "radian", "degree", "turn", "arcminute", "arcsecond", "joule", "watt", "ampere",
    "volt", "ohm", "kelvin",
})
_PREFIXES = frozenset({"", "yocto", "zepto", "atto", "femto", "pico", "nano", "micro", "milli",
                       "centi", "deci", "deca", "hecto", "kilo", "mega", "giga", "tera", "peta",
                       "exa", "zetta", "yotta"})


def _check_names(text, registry):
    """Refuse a unit with anything but allowed names, exponents, ``1``, spaces, ``*``, ``/``, brackets."""
    bare = re.sub(r"(?<![\w.])1(?![\w.])", " ", _EXPONENT.sub(" ", text))
    names = _NAME.findall(bare)
    rest = _NAME.sub(" ", bare)
    if not _JOINERS.fullmatch(rest):
        odd = "".join(dict.fromkeys(re.sub(r"[\s*/()\u00b7]", "", rest)))
        what = ("a number belongs in 'value', not in the unit" if odd.isdigit() or odd == "."
                else f"{odd!r} has no place in a unit")
        raise ValueError(f"unit {text!r} is not a unit a loop file may name: {what} (a unit is "
                         f"names of units joined by spaces, '*' and '/', with exponents such as "
                         f"'^2' or '**-1', or 1 alone)")
    for name in names:
        readings = registry.parse_unit_name(name)
        prefix, unit, suffix = readings[0] if readings else ("", None, "")
        if unit not in ALLOWED_UNITS or prefix not in _PREFIXES or suffix not in ("", "s"):
            what = f"pint reads {name!r} as {prefix}{unit}" if unit else f"pint does not know {name!r}"
            raise ValueError(f"unit {text!r} is not a unit a loop file may name: {what}; allowed: "
                             f"m, g, s, N, Hz, rad, J, W, A, V, ohm and K with any SI prefix, "
                             f"and in, ft, lb, oz, lbf, ozf, kgf, min, h, deg, turn, arcmin, arcsec")


@functools.lru_cache(maxsize=None)
def unit_registry():
    """The one pint ``UnitRegistry`` of symstab, built on first use.

    Its factors are exact fractions, so a value is converted with one
    rounding (0.25 ms is exactly the float 2.5e-4).
    """
    import pint

    return pint.UnitRegistry(non_int_type=fractions.Fraction)


@dataclasses.dataclass(frozen=True)
class UnitInfo:
    """A unit as pint reads it: its SI factor, SI name and dimension."""

    text: str            # as written
    factor: fractions.Fraction
    si: str              # the coherent SI unit the value is converted to
    dimensions: tuple    # exponents of _BASES (Fractions)
    angle: fractions.Fraction   # exponent of the radian (dimensionless in SI)


def _si_name(dimensions, angle):
    key = (tuple(dimensions[:3]), angle)
    if not any(dimensions[3:]) and key in _SI_NAMES:
        return _SI_NAMES[key]
    return _dimension_text(dimensions) + (f" rad^{_power(angle)}" if angle else "")


def _power(x):
    return str(int(x)) if x == int(x) else str(x)


def _dimension_text(dimensions):
    """``"kg m^2 s^-2"``: a dimension in SI base units (``"1"`` when dimensionless)."""
    parts = [_BASE_SYMBOLS[b] + ("" if e == 1 else f"^{_power(e)}")
             for b, e in zip(_BASES, dimensions, strict=True) if e]
    return " ".join(parts) or "1"


def dimension_name(dimensions):
    """A dimension (exponents of the SI base dimensions) by its coherent SI name, e.g. ``"N/m"``.

    Parameters
    ----------
    dimensions : tuple
        Exponents of mass, length, time, current, temperature, amount of
        substance and luminous intensity, as :attr:`UnitInfo.dimensions`.

    Returns
    -------
    str
        ``"N m/rad"`` rather than ``"N m"`` where both fit (a rotary
        stiffness), base units (``"kg m^2 s^-3"``) where no name does.
    """
    dimensions = tuple(dimensions)
    if not any(dimensions[3:]):
        for angle in (-1, 0):
            if ((tuple(dimensions[:3])), angle) in _SI_NAMES:
                name = _SI_NAMES[(tuple(dimensions[:3]), angle)]
                return "no unit (dimensionless)" if name == "1" else name
    return _dimension_text(dimensions)


@functools.lru_cache(maxsize=256)
def unit_info(text):
    """Read a unit with pint: :class:`UnitInfo`, or ValueError saying why not.

    Parameters
    ----------
    text : str
        A unit, e.g. ``"ms"``, ``"N s/mm"``, ``"g cm^2"``, ``"N m/rad"``.

    Raises
    ------
    ValueError
        If pint does not know it, it is an offset unit (degC), its size is
        0 or not a float, or an exponent is not a short number.
    """
    if not isinstance(text, str):
        raise TypeError(f"a unit must be a string, got {type(text).__name__}")
    if not text.strip():
        raise ValueError("the unit is empty: leave 'unit' out for a bare number (taken in SI), "
                         "or write unit = \"1\" for a dimensionless one")
    if (len(_POWER.findall(text)) != len(_EXPONENT.findall(text))
            or re.search(r"(\*\*|\^)[^*^]*(\*\*|\^)\s*[\d(+-]", text)
            and re.search(_EXPONENT.pattern + r"\s*(\*\*|\^)", text)):
        raise ValueError(f"unit {text!r}: an exponent must be a number of at most two digits, "
                         f"and no power may be raised to a power")
    registry = unit_registry()
    _check_names(text, registry)
    try:
        quantity = registry.parse_expression(text)
        if not isinstance(quantity, registry.Quantity):
            quantity = registry.Quantity(quantity, "dimensionless")
        base = quantity.to_base_units()
        zero = registry.Quantity(0, quantity.units).to_base_units().magnitude
        factor = fractions.Fraction(base.magnitude)
        size = float(factor)
    except Exception as exc:   # pint's own errors (undefined unit, syntax) and arithmetic ones
        try:
            reason = str(exc).strip() or type(exc).__name__
        except Exception:   # some of pint's messages cannot format their own Fractions
            reason = type(exc).__name__
        raise ValueError(f"unit {text!r} is not a unit pint knows ({reason})") from None
    if zero != 0:
        raise ValueError(f"unit {text!r} has an offset (like degC): give a unit without one "
                         f"(K, for a temperature)")
    if not size or not math.isfinite(size):
        raise ValueError(f"unit {text!r} has no finite nonzero size")
    dims = quantity.dimensionality
    unknown = [k for k in dims if k not in _BASES]
    if unknown:
        raise ValueError(f"unit {text!r} has a dimension outside SI ({', '.join(unknown)})")
    dimensions = tuple(fractions.Fraction(dims.get(b, 0)) for b in _BASES)
    angle = fractions.Fraction(dict(base.unit_items()).get("radian", 0))
    return UnitInfo(text, factor, _si_name(dimensions, angle), dimensions, angle)


@dataclasses.dataclass(frozen=True)
class FileValue:
    """A parameter's value as the loop file gives it and as the derivation uses it."""

    name: str
    value: object        # as written (int or float)
    unit: object         # the unit as written; None for a bare number
    si_value: object     # the value in SI (a bare number unchanged)
    si_unit: str         # "" for a bare number
    info: object = None  # UnitInfo, None for a bare number and for d

    @property
    def converted(self):
        """Whether the value used differs in writing from the one given (value or unit)."""
        return self.unit is not None and (self.unit != self.si_unit or self.value != self.si_value)


@dataclasses.dataclass(frozen=True)
class Bound:
    """One bound a loop file declares on a parameter."""

    name: str            # the parameter bounded
    kind: str            # "min", "max", "above" or "below"
    text: str            # as written
    expression: object   # SymPy, in SI


@dataclasses.dataclass(frozen=True)
class FileParameters:
    """What a loop file says about its parameters: values, units, dimensions and bounds.

    ``values`` holds a :class:`FileValue` per parameter given, ``dimensions``
    the dimension of each parameter known from its unit or implied by the
    loop, ``bounds`` the declared :class:`Bound` objects.
    """

    values: dict
    dimensions: dict = dataclasses.field(default_factory=dict)
    bounds: tuple = ()

    def file_unit(self, name):
        """The unit the file gives ``name`` in (None: a bare number or not given)."""
        entry = self.values.get(name)
        return None if entry is None else entry.unit


def _check_number(source, name, value):
    if isinstance(value, int) and not isinstance(value, bool) and abs(value) > 1e300:
        value = math.inf   # past what a float holds: refused just below
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise ValueError(f"{source}: parameter {name!r} must be a finite number, got {value!r}")
    return value


def convert(name, value, unit, *, where):
    """``value`` given in ``unit`` for the parameter ``name``: a :class:`FileValue` in SI.

    ``T`` and ``Td`` (the delay in time, instead of ``d``) must be times and
    ``d`` a number of samples (whole or not); a frequency written
    with an angle (rad/s, rpm) is refused (the loop's expressions take a
    frequency in Hz = 1/s, and SI would read 1 rad/s as 1 Hz).  The
    dimension of any other parameter is checked against the loop by
    :func:`check_loop_units`.

    Parameters
    ----------
    name : str
        The parameter.
    value : int or float
        As written (finite).
    unit : str or None
        As written; None for a bare number, taken in SI and returned as is.
    where : str
        Begins every message: the file, or the ``--set`` option.

    Returns
    -------
    FileValue

    Raises
    ------
    ValueError
        Naming the parameter, the unit given and the one expected.
    """
    from ...symbolic.loop_assembly import check_text_line

    if unit is None:
        return FileValue(name, value, None, value, {"d": "samples", "Td": "s"}.get(name, ""))
    try:
        check_text_line(f"unit of {name!r}", unit)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{where}: {exc}") from None
    if name == "d":
        if unit not in SAMPLE_UNITS:
            raise ValueError(f"{where}: parameter 'd' has unit {unit!r}: the delay d is a "
                             f"number of samples (unit \"samples\", or none; 40.5 is a fraction "
                             f"of a period more); give a delay in time as Td (Td = {{ value = "
                             f"40.5, unit = \"ms\" }})")
        return FileValue(name, value, unit, value, "samples")
    try:
        info = unit_info(unit)
    except ValueError as exc:
        raise ValueError(f"{where}: parameter {name!r}: {exc}") from None
    if name in ("T", "Td") and info.dimensions != _vector({"[time]": 1}):
        named = dimension_name(info.dimensions)
        what = "the sample period" if name == "T" else "the loop delay (in samples: d)"
        raise ValueError(f"{where}: parameter {name!r} has unit {unit!r}"
                         + ("" if named == unit else f" ({named})")
                         + f": {name} is {what}, a time (s, ms, us)")
    # A rotary stiffness or damping in N m/deg^2: the dimension fits, the angle does not.
    check_angle(name, info, parameter_angle(info.dimensions), where=where)
    if info.dimensions == _vector({"[time]": -1}) and info.angle:
        raise ValueError(f"{where}: parameter {name!r} has unit {unit!r}, an angular frequency: "
                         f"give it in Hz or 1/s, as the loop's expressions use it (SI takes "
                         f"1 rad/s as 1/s, a factor 2 pi from 1 Hz)")
    try:
        si_value = float(fractions.Fraction(value) * info.factor)
    except OverflowError:
        si_value = math.inf
    if not math.isfinite(si_value) or (si_value == 0 and value != 0):
        raise ValueError(f"{where}: parameter {name!r} = {value!r} {unit} is not representable "
                         f"as a float in SI ({info.si})")
    return FileValue(name, value, unit, si_value, info.si, info)


def parameter_angle(dimensions, info=None):
    """The exponent of the angle in a parameter's own unit, or None where it is not known.

    pint (as SI) takes an angle as a number, so ``N m/deg^2`` has the
    dimension of ``N m/rad`` and would be converted by (180/pi)^2 without
    a word.  A parameter's own angle exponent is that of the unit its loop
    file gives it, where that unit writes an angle; else -1 for a rotary
    stiffness or damping (N m/rad, N m s/rad: the loop's VE(z) maps an angle
    to a torque); else unknown.

    Parameters
    ----------
    dimensions : tuple or None
        The parameter's dimension (:attr:`UnitInfo.dimensions`).
    info : UnitInfo, optional
        The unit the loop file gives the parameter.

    Returns
    -------
    fractions.Fraction or None
    """
    if info is not None and info.angle:
        return info.angle
    if dimensions is None or any(dimensions[3:]):
        return None
    if (tuple(dimensions[:3]), -1) in _SI_NAMES and (tuple(dimensions[:3]), 0) in _SI_NAMES:
        return fractions.Fraction(-1)
    return None


def check_angle(name, info, own, *, where, si_unit=None):
    """Refuse a unit whose angle exponent is not the parameter's own (:func:`parameter_angle`).

    A unit that writes no angle is taken as SI takes it (``N m`` for ``N m/rad``:
    the radian is 1); one that writes an angle must write it to the
    parameter's power, in any angle unit (``N m/deg`` is converted by
    180/pi).

    Parameters
    ----------
    name : str
        The parameter.
    info : UnitInfo
        The unit given.
    own : fractions.Fraction or None
        The parameter's angle exponent; None: not checked.
    where : str
        Begins the message (the file, or the ``--set`` option).
    si_unit : str, optional
        The parameter's unit, named in the message (default: the SI name of
        ``info``'s dimension with ``own``).

    Raises
    ------
    ValueError
        Naming the parameter, the unit given and the unit it is in.
    """
    if own is None or not info.angle or info.angle == own:
        return
    expected = si_unit or _si_name(info.dimensions, own)
    raise ValueError(f"{where}: parameter {name!r} has unit {info.text!r}, whose angle is to the "
                     f"power {_power(info.angle)}, and {name} is in {expected} (an angle to the "
                     f"power {_power(own)}): pint takes an angle as a number, so it would be "
                     f"converted silently; give it in {expected}, or with the angle in another "
                     f"unit to that power (e.g. 'deg' for 'rad')")


def _vector(mapping):
    return tuple(fractions.Fraction(mapping.get(b, 0)) for b in _BASES)


def read_parameters(parameters, *, source):
    """The ``[parameters]`` table of a loop file: its values in SI and their units.

    Parameters
    ----------
    parameters : dict
        The table as TOML reads it: a bare number or ``{ value, unit, min,
        max, above, below }`` per parameter.
    source : str
        The file, for messages.

    Returns
    -------
    (values, units, file_values, raw_bounds)
        ``values`` and ``units`` (SI) for :class:`symstab.Loop`, the
        :class:`FileValue` of each parameter, and each bound as written
        (``(name, kind, value)``), parsed by :func:`check_loop_units`.

    Raises
    ------
    ValueError
        Naming the file and the parameter.
    """
    if not isinstance(parameters, dict):
        raise ValueError(f"{source}: [parameters] must be a table")
    values, units, file_values, raw_bounds = {}, {}, {}, []
    for key, entry in parameters.items():
        if isinstance(entry, dict):
            extra = set(entry) - set(ENTRY_KEYS)
            if extra or "value" not in entry:
                raise ValueError(f"{source}: parameter {key!r} must be a number or "
                                 f"{{ value = ..., unit = \"...\" }} (keys: "
                                 f"{', '.join(ENTRY_KEYS)})")
            value, unit = entry["value"], entry.get("unit")
            raw_bounds += [(key, kind, entry[kind]) for kind in _BOUND_KINDS if kind in entry]
        else:
            value, unit = entry, None
        value = _check_number(source, key, value)
        if unit is not None and not isinstance(unit, str):
            raise ValueError(f"{source}: the unit of {key!r} must be a string, got "
                             f"{type(unit).__name__}")
        item = convert(key, value, unit, where=source)
        file_values[key] = item
        values[key] = item.si_value
        if item.unit is not None:
            units[key] = item.si_unit
    return values, units, file_values, raw_bounds


# --------------------------------------------------------------------------
# Dimensions


class _Dimensions:
    """The linear system of a loop's dimensions: one unknown per parameter and base."""

    def __init__(self):
        self.constraints = []   # (what, vector that must vanish)

    @staticmethod
    def unknown(name):
        return tuple(sp.Symbol(f"{name}|{b}") for b in _BASES)

    def of(self, expr, where):
        """The dimension of ``expr`` (a vector of linear expressions); records what must hold."""
        if not expr.free_symbols:
            return (0,) * len(_BASES)
        if expr.is_Symbol:
            name = str(expr)
            if name == "s":
                return tuple(sp.Integer(x) for x in _vector({"[time]": -1}))
            if name == "z":
                return (0,) * len(_BASES)
            return self.unknown(name)
        if isinstance(expr, sp.Add):
            terms = [(t, self.of(t, where)) for t in expr.args]
            first, first_dims = terms[0]
            for term, dims in terms[1:]:
                self.constraints.append(((where, first, term),
                                         tuple(a - b for a, b in zip(first_dims, dims,
                                                                     strict=True))))
            return first_dims
        if isinstance(expr, sp.Mul):
            out = (0,) * len(_BASES)
            for factor in expr.args:
                out = tuple(a + b for a, b in zip(out, self.of(factor, where), strict=True))
            return out
        if isinstance(expr, sp.Pow) and not expr.exp.free_symbols:
            power = sp.nsimplify(expr.exp, rational=True)
            return tuple(power * x for x in self.of(expr.base, where))
        # exp(x), a symbolic exponent, any other function: dimensionless arguments
        for arg in expr.args:
            self.constraints.append(((where, arg, None), self.of(arg, where)))
        return (0,) * len(_BASES)


def _solve(equations, unknowns):
    """A solution of the linear equations (dict), or None if there is none."""
    equations = [e for e in (sp.expand(e) for e in equations) if e != 0]
    if not equations:
        return {}
    if any(not e.free_symbols for e in equations):
        return None
    free = sorted({s for e in equations for s in e.free_symbols} & set(unknowns), key=str)
    solution = sp.linsolve(equations, free)
    if solution == sp.EmptySet:
        return None
    return dict(zip(free, next(iter(solution)), strict=True))


#: VE(z): force over displacement, linear (N/m) or rotary (N m/rad).
_STIFFNESS = {"linear": _vector({"[mass]": 1, "[time]": -2}),
              "rotary": _vector({"[mass]": 1, "[length]": 2, "[time]": -2})}


def check_loop_units(loop, file_values, raw_bounds, *, source):
    """Check the dimensions of a loop's parameters and parse its bounds.

    Parameters
    ----------
    loop : symstab.Loop
        Built from the file's values (in SI).
    file_values : dict
        The :class:`FileValue` of each parameter (:func:`read_parameters`).
    raw_bounds : list
        ``(name, kind, value)`` as written.
    source : str
        The file, for messages.

    Returns
    -------
    FileParameters

    Raises
    ------
    ValueError
        If the units do not fit the loop (naming the parameters and, where
        one unit alone is wrong, the unit it needs), or a bound is not a
        number or an expression of the loop's parameters of the
        parameter's dimension, or a value is outside its bounds.
    """
    from ...symbolic.loop_assembly import parse_expression

    bounds = []
    for name, kind, raw in raw_bounds:
        what = f"{source}: bound {kind} of {name!r}"
        if isinstance(raw, bool) or not isinstance(raw, (int, float, str)):
            raise ValueError(f"{what} must be a number (in the unit of {name}) or an expression "
                             f"of the loop's parameters, e.g. \"1/(2*T)\"")
        if isinstance(raw, str):
            expr = parse_expression(raw, what)
            names = {str(s) for s in expr.free_symbols}
            bad = sorted(names - set(loop.parameters))
            if bad:
                raise ValueError(f"{what} {raw!r}: {', '.join(bad)} is not a parameter of the "
                                 f"loop (parameters: {', '.join(loop.parameters)})")
            if not names:
                raw = float(expr)
        if not isinstance(raw, str):
            if isinstance(raw, int) and abs(raw) > 1e300 or not math.isfinite(raw):
                raise ValueError(f"{what} must be a finite number, got {raw!r}")
            entry = file_values[name]
            scale = entry.info.factor if entry.info is not None else 1
            expr = sp.Float(float(fractions.Fraction(raw) * scale))
        bounds.append(Bound(name, kind, str(raw) if isinstance(raw, str) else repr(raw), expr))
    dimensions = _check_dimensions(loop, file_values, bounds, source)
    parameters = FileParameters(dict(file_values), dimensions, tuple(bounds))
    check_bounds(parameters, dict(loop.defaults), where=source,
                 missing_ok=True)
    return parameters


def check_si_units(loop):
    """Check the units a :class:`symstab.Loop` was given: SI, and fitting the loop.

    A unit here names the unit of values the loop computes with as they
    are: one that is not SI would be a label on a wrong number.

    Parameters
    ----------
    loop : symstab.Loop
        The loop, with its ``units`` and ``defaults``.

    Raises
    ------
    ValueError
        For a unit that is not SI (naming the SI one), or units whose
        dimensions do not fit the loop.
    """
    given = {}
    for key, unit in loop.units.items():
        item = convert(key, 1, unit, where="units")
        if item.si_value != 1:
            raise ValueError(f"units: {key!r} is given in {unit!r}, which is "
                             f"{float(item.si_value):g} {item.si_unit}: Loop takes its values "
                             f"in SI, so give {key} in {item.si_unit} (a loop file's units are "
                             f"converted: symstab.load_loop)")
        given[key] = convert(key, loop.defaults.get(key, 1), unit, where="units")
    for key, value in loop.defaults.items():
        given.setdefault(key, convert(key, value, None, where="values"))
    check_loop_units(loop, given, [], source="units")

def _check_dimensions(loop, file_values, bounds, source):
    system = _Dimensions()
    plant = system.of(loop.plant, "the plant G(s)")
    environment = system.of(loop.environment, "the environment VE(z)")
    system.constraints.append((("loop", None, None),
                               tuple(a + b for a, b in zip(plant, environment, strict=True))))
    known = {"T": _vector({"[time]": 1})}
    for name, entry in file_values.items():
        if entry.info is not None:
            known[name] = entry.info.dimensions
    names = [n for n in loop.parameters if n != "d"]

    def solve(fixed, stiffness):
        """The system with ``fixed`` dimensions and VE's: {name: dims or None}, or None."""
        sub = {}
        for name in fixed:
            sub.update(zip(system.unknown(name), (sp.Rational(x.numerator, x.denominator)
                                                  for x in fixed[name]), strict=True))
        ve = tuple(a - sp.Rational(b.numerator, b.denominator)
                   for a, b in zip(environment, _STIFFNESS[stiffness], strict=True))
        out = {}
        for k in range(len(_BASES)):
            equations = [c[1][k] for c in system.constraints] + [ve[k]]
            unknowns = [system.unknown(n)[k] for n in names if n not in fixed]
            solution = _solve([sp.sympify(e).xreplace(sub) for e in equations], unknowns)
            if solution is None:
                return None
            out[k] = solution
        result = {}
        for name in names:
            if name in fixed:
                result[name] = fixed[name]
                continue
            parts = [out[k].get(system.unknown(name)[k], None) for k in range(len(_BASES))]
            result[name] = (None if any(p is None or p.free_symbols for p in parts)
                            else tuple(fractions.Fraction(int(p.p), int(p.q)) for p in parts))
        return result

    for stiffness in _STIFFNESS:
        result = solve(known, stiffness)
        if result is not None:
            dimensions = {n: v for n, v in result.items() if v is not None}
            _check_bound_dimensions(bounds, dimensions, source)
            return dimensions
    given = [n for n in names if n in known and n != "T"]
    needs = {}
    for name in given:
        fixed = {n: v for n, v in known.items() if n != name}
        for stiffness in _STIFFNESS:
            result = solve(fixed, stiffness)
            if result is not None:
                needs.setdefault(name, set())
                if result[name] is not None:
                    needs[name].add(dimension_name(result[name]))
    reason = _reason(system, known, loop)
    law = ("the plant G(s) maps force to displacement and VE(z) displacement to force, "
           "N/m or N m/rad; s is 1/time, z has no unit")

    def written(name):
        return f"{name} ({_written(file_values[name])})"

    if len(needs) == 1:
        [(name, expected)] = needs.items()
        want = " or ".join(sorted(expected)) or "another unit"
        raise ValueError(f"{source}: parameter {name!r} has unit {_written(file_values[name])}, "
                         f"which does not fit "
                         f"the loop: it needs {want} there ({reason}; {law})")
    if needs:
        options = "; ".join(f"{n} would need {' or '.join(sorted(e)) or 'another unit'}"
                            for n, e in needs.items())
        raise ValueError(f"{source}: the units of {', '.join(written(n) for n in needs)} do not "
                         f"fit together in the loop ({reason}; {law}): one of them is wrong "
                         f"(with the others as given, {options})")
    raise ValueError(f"{source}: the units of {', '.join(written(n) for n in given)} do not fit "
                     f"the loop ({reason}; {law})")


def _check_bound_dimensions(bounds, dimensions, source):
    """A bound written as an expression has its parameter's dimension (where both are known)."""
    for bound in bounds:
        names = {str(x) for x in bound.expression.free_symbols}
        if not names or bound.name not in dimensions or not names <= set(dimensions):
            continue
        sub = {}
        for name in names:
            sub.update(zip(_Dimensions.unknown(name), (sp.Rational(x.numerator, x.denominator)
                                                        for x in dimensions[name]), strict=True))
        system = _Dimensions()
        dims = [sp.expand(sp.sympify(v).xreplace(sub)) for v in system.of(bound.expression, "")]
        broken = [c for c in system.constraints
                  if any(sp.expand(sp.sympify(v).xreplace(sub)) for v in c[1])]
        have = None if broken else tuple(fractions.Fraction(int(v.p), int(v.q)) for v in dims)
        if have != tuple(dimensions[bound.name]):
            what = ("adds terms of different units" if broken
                    else f"is in {dimension_name(have)}")
            raise ValueError(f"{source}: bound {bound.kind} = {bound.text!r} of {bound.name!r} "
                             f"{what}, and {bound.name} is in {dimension_name(dimensions[bound.name])}")


def _written(entry):
    """``'N/mm'`` or ``'g/s' (N s/m)``: a unit as written, with its SI name where that differs."""
    named = dimension_name(entry.info.dimensions)
    return repr(entry.unit) + ("" if named == entry.unit else f" ({named})")


def _reason(system, known, loop):
    """The first constraint that the given units break on their own, in words."""
    sub = {}
    for name, dims in known.items():
        sub.update(zip(_Dimensions.unknown(name), (sp.Rational(x.numerator, x.denominator)
                                                    for x in dims), strict=True))

    def dims_of(expr):
        vec = _Dimensions().of(expr, "")
        values = [sp.sympify(v).xreplace(sub) for v in vec]
        if any(v.free_symbols for v in values):
            return None
        return tuple(fractions.Fraction(int(v.p), int(v.q)) for v in values)

    for (where, a, b), vector in system.constraints:
        values = [sp.expand(sp.sympify(v).xreplace(sub)) for v in vector]
        if any(v.free_symbols for v in values) or not any(values):
            continue
        if where == "loop":
            return (f"the plant G(s) is in {_dimension_text(dims_of(loop.plant))} and the "
                    f"environment VE(z) in {_dimension_text(dims_of(loop.environment))}: the "
                    f"loop gain VE(z) G(s) must have no unit")
        if b is None:
            return f"in {where}, {a} must be dimensionless, and is {_dimension_text(dims_of(a))}"
        return (f"in {where}, {a} ({_dimension_text(dims_of(a))}) and {b} "
                f"({_dimension_text(dims_of(b))}) are added")
    for what, expr, need in (("the plant G(s)", loop.plant, "m/N or rad/(N m)"),
                             ("the environment VE(z)", loop.environment, "N/m or N m/rad")):
        have = dims_of(expr)
        if have is not None:
            return f"{what} is in {_dimension_text(have)}, and must be in {need}"
    return "no dimensions of the parameters without a unit make it fit"


# --------------------------------------------------------------------------
# Bounds


def _evaluate(expr, values):
    """``expr`` (SymPy, parameters by name) at ``values``, as a NumPy array; never code."""
    if not expr.free_symbols:
        return np.asarray(float(expr))
    if expr.is_Symbol:
        return np.asarray(values[str(expr)], dtype=float)
    args = [_evaluate(a, values) for a in expr.args]
    if isinstance(expr, sp.Add):
        return functools.reduce(np.add, args)
    if isinstance(expr, sp.Mul):
        return functools.reduce(np.multiply, args)
    if isinstance(expr, sp.Pow):
        return np.power(args[0], args[1])
    if isinstance(expr, sp.exp):
        return np.exp(args[0])
    raise ValueError(f"cannot evaluate {expr} in a bound")


def check_bounds(parameters, values, *, where, skip=(), missing_ok=False):
    """Refuse a value outside the bounds its loop file declares.

    Parameters
    ----------
    parameters : FileParameters
    values : dict
        Values in SI by name (numbers or arrays of one length, as
        ``classify`` takes them).
    where : str or callable
        Begins the message (the file, or the ``--set`` options); a callable
        is given the names a violated bound involves.
    skip : iterable of str
        Parameters without a single value (a plane's axes): their bounds,
        and bounds that depend on them, are not checked.
    missing_ok : bool
        Skip a bound whose parameters have no value.

    Raises
    ------
    ValueError
        In the words of ``symstab._validate.check_real``, e.g.
        ``f_c must be a finite real number > 0 and < 2000, got 3000.0``,
        with the unit and the bounds as the file writes them.
    """
    from ..._validate import check_real

    by_name = {}
    for bound in parameters.bounds:
        by_name.setdefault(bound.name, []).append(bound)
    for name, bounds in by_name.items():
        needed = {name} | {str(s) for b in bounds for s in b.expression.free_symbols}
        if needed & set(skip):
            continue
        if not needed <= set(values):
            if missing_ok:
                continue
            prefix = where(needed) if callable(where) else where
            raise ValueError(f"{prefix}: no value for {', '.join(sorted(needed - set(values)))}, "
                             f"needed by the bounds of {name!r}")
        with np.errstate(all="ignore"):
            limits = [(b, _evaluate(b.expression, values)) for b in bounds]
            shape = np.broadcast_shapes(np.shape(values[name]), *(np.shape(v) for _, v in limits))
            given = np.broadcast_to(np.asarray(values[name], dtype=float), shape).ravel()
            limits = [(b, np.broadcast_to(v, shape).ravel()) for b, v in limits]
        for k in range(given.size):
            low = high = None
            low_open = high_open = False
            for bound, value in limits:
                is_open, side = _BOUND_KINDS[bound.kind]
                v = float(value[k])
                if side == "low" and (low is None or v > low or (v == low and is_open)):
                    low, low_open = v, is_open
                if side == "high" and (high is None or v < high or (v == high and is_open)):
                    high, high_open = v, is_open
            try:
                check_real(name, float(given[k]), low=low, high=high, low_open=low_open,
                           high_open=high_open)
            except ValueError as exc:
                entry = parameters.values.get(name)
                unit = entry.si_unit if entry is not None and entry.si_unit else ""
                written = ", ".join(f"{b.kind} = {b.text}" + (
                    f" = {float(v[k]):.6g}" if b.expression.free_symbols else "")
                    for b, v in limits)
                prefix = where(needed) if callable(where) else where
                raise ValueError(f"{prefix}: {exc}{' ' + unit if unit else ''} (the loop "
                                 f"file's bounds of {name}: {written})") from None
