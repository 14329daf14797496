"""A sampled loop as SymPy objects: plant, zero-order hold, delay and environment.

:class:`LoopModel` parses a plant ``G(s)`` and an environment ``VE(z)``
with named parameters, checks that they are proper rational functions, and
derives the closed loop ``1 + VE(z) z**-d Z[ZOH G](z) = 0`` as

    chi(z) = z**d Ve_d(z) P_d(z) + Ve_n(z) P_n(z),

a *delayed part* and a *direct part* (as :mod:`symstab.symbolic.loop` does for the
paper's loop).  The pulse transfer function ``P_n / P_d`` is derived by
residues when the denominator of ``G(s)/s`` factors, over the parameters,
into factors of degree 1 or 2 in ``s``
(:func:`symstab.symbolic.discretize.zoh_pulse_transfer_function`), else
by the matrix exponential at 30 digits once the plant's values are known
(:func:`symstab.symbolic.discretize.numeric_zoh`); :attr:`LoopModel.zoh_method`
says which.  It also decides which parameters enter ``chi`` affinely (the
axes a parameter plane may have) and evaluates the plant's polynomials at
30 digits.  Everything numeric on top of it is :class:`symstab.Loop`.
"""

import ast
import fractions
import functools
import keyword
import math
import re
import warnings

import mpmath
import numpy as np
import sympy as sp
from sympy.polys.polyerrors import CoercionFailed

from .._memo import SharedStores, method_cache, shared_property
from .._validate import check_delay
from . import model
from .derivation_cache import DerivationCache, cache_dir
from .discretize import (
    fractional_zoh_pulse_transfer_function,
    numeric_fractional_zoh,
    numeric_zoh,
    written_poles,
    zoh_pulse_transfer_function,
)
from .forms import NO_DOCSTRING

__all__ = ["LoopModel", "NonPhysicalPlantWarning", "parse_plant", "parse_environment", "parse_actuator", "parse_expression",
           "check_parameter_name", "check_loop_name", "check_text_line", "NAME_PATTERN",
           "is_affine", "poly_coeffs", "shift_to_one", "PLANT_DIGITS", "forget_derivations"]

#: The longest plant, environment or bound expression read (a loop file's
#: physics fits in a few hundred characters; a long chain of + or * nests
#: the parser and SymPy as deep as it is long).
MAX_EXPRESSION_LENGTH = 2000
#: Names with a fixed meaning in every loop.
RESERVED = ("s", "z", "T", "d")
#: Working digits of the plant's pulse transfer function (rounded once to float).
PLANT_DIGITS = 30
#: The fraction ``eps`` of a period in a fractional delay ``(d + eps) T``, in the
#: derivation of the plant that carries it (no parameter's name starts with ``_``).
FRACTION = sp.Symbol("_eps")
#: The most digits a plant's closed form is evaluated with (it cancels for a
#: pole near z = 1; ``LoopModel._closed_form_plant``).
PLANT_MAX_DIGITS = 5000
#: Parameter names the generated NumPy and C kernels cannot take.
_C_KEYWORDS = frozenset(
    "auto break case char const continue default do double else enum extern float for goto if "
    "inline int long register restrict return short signed sizeof static struct switch typedef "
    "union unsigned void volatile while _Bool _Complex _Imaginary".split())
_GENERATED_NAME = re.compile(r"(num|den|pn|pd|x)\d+|numpy|_.*")
#: Keyword arguments of Loop's methods: a parameter of the same name would
#: be taken for them.
_ARGUMENT_NAMES = frozenset({"self", "name", "x", "y", "n", "values", "x_range", "y_range",
                             "damping"})
#: A loop's name: it becomes a file stem, part of C identifiers and a word in
#: generated headers, so it is a word of ASCII letters, digits, ``_``, ``-``
#: and ``.`` (no leading ``-`` or ``.``: not an option, not a hidden file).
NAME_PATTERN = re.compile(r"[A-Za-z0-9_][A-Za-z0-9_.-]{0,63}")
#: A parameter's name: an identifier in Python and C, a symbol in LaTeX.
_PARAMETER_PATTERN = re.compile(r"[A-Za-z][A-Za-z0-9_]{0,39}")
#: Longest description and unit text (one line each).
_TEXT_LIMITS = {"description": 200, "unit": 60}


class NonPhysicalPlantWarning(UserWarning):
    """The plant at the values given is not a physical device's: a pole in the open right half
    plane, or a negative high-frequency gain (a negative mass, friction or stiffness, a typo).

    The loop is analysed as given; the warning names the plant's values
    (:meth:`LoopModel.plant_defect`).  A loop file bounds its physical
    parameters (``min = 0``, ``above = 0``) to refuse such a value instead.
    """


#: The shared stores of :class:`LoopModel`, one per plant, environment, actuator and
#: cache folder: a sweep, a design or a test that builds the same loop again derives
#: nothing again in this process (:func:`forget_derivations` empties them).
_SHARED = SharedStores(32)


def forget_derivations():
    """Forget what this process derived for its loops (the parsed text and the shared stores).

    The next model of each loop reads its derivation from the cache folder,
    or derives it, afresh: for tests of that cache, and to free memory.
    """
    _SHARED.clear()
    _parsed_plant.cache_clear()
    _parsed_rational.cache_clear()


def shift_to_one(coefficients, dtype=None):
    """Coefficients of ``p(w + 1)`` in ``w`` from those of ``p(z)`` (both highest first).

    ``n`` passes of partial sums along the last axis (Horner's scheme of the
    shift): exact for integers and fractions (``dtype=object``), in the
    working precision for mpmath numbers, and with rounding of at most a few
    ulps of the shift of ``|p|`` for floats.  Rows (leading axes) are shifted
    together.

    Examples
    --------
    >>> shift_to_one([1, -3, 3, -1], dtype=object).tolist()    # (z - 1)**3 = w**3
    [1, 0, 0, 0]
    """
    p = np.array(coefficients, dtype=dtype)
    for stop in range(p.shape[-1], 1, -1):
        p[..., :stop] = np.cumsum(p[..., :stop], axis=-1)
    return p


def _defined(p_n, p_d):
    """True when a pulse transfer function's coefficients are finite with a leading ``P_d`` not 0."""
    return p_d[0] != 0 and all(mpmath.isfinite(c) for c in (*p_n, *p_d))


def _fraction(value):
    """An mpmath number that is real up to rounding, as the exact Fraction of its binary value."""
    if isinstance(value, mpmath.mpc):
        value = value.real
    value = mpmath.mpf(value)
    man, exp = value.man_exp            # the mantissa's magnitude
    exact = fractions.Fraction(int(man)) * fractions.Fraction(2) ** int(exp)
    return -exact if value < 0 else exact


def _real_floats(values):
    """Floats of mpmath numbers that are real up to rounding.

    A complex pole pair is written with the square root of a negative
    number; its terms of the pulse transfer function add up to real
    coefficients, with imaginary parts of the working precision's rounding.
    Anything larger is a defect, not rounding, and raises.
    """
    scale = max((abs(v) for v in values), default=mpmath.mpf(0))
    out = []
    for v in values:
        if isinstance(v, mpmath.mpc):
            if abs(v.imag) > mpmath.mpf(10) ** (10 - mpmath.mp.dps) * scale:
                raise ArithmeticError(f"the plant's pulse transfer function has a complex "
                                      f"coefficient {v}")
            v = v.real
        out.append(float(v))
    return out


def check_loop_name(name):
    """Refuse a loop name that is not a plain word: it becomes a file stem and C identifiers.

    Parameters
    ----------
    name : str
        1 to 64 ASCII letters, digits, ``_``, ``-`` and ``.``, starting with
        a letter, a digit or ``_`` (:data:`NAME_PATTERN`).

    Returns
    -------
    str
        ``name``.

    Raises
    ------
    TypeError
        If it is not a string.
    ValueError
        Naming ``name`` and the characters allowed.
    """
    if not isinstance(name, str):
        raise TypeError(f"name must be a string, got {type(name).__name__}")
    if not NAME_PATTERN.fullmatch(name):
        raise ValueError(f"name {name!r} is not allowed: 1 to 64 ASCII letters, digits, '_', "
                         f"'-' and '.', starting with a letter, a digit or '_' (it becomes a "
                         f"file name)")
    return name


def check_text_line(what, text):
    """Refuse text that is not one short line of printable characters.

    A description or a unit is shown by the CLI and written into generated
    files (escaped there too); a line break, a control or a bidirectional
    formatting character could make what is shown differ from what is
    there.

    Parameters
    ----------
    what : str
        ``"description"`` or ``"unit"`` (with the parameter's name after it,
        e.g. ``"unit of 'K'"``): names the item in the message and decides
        the length limit (200 and 60 characters).
    text : str

    Returns
    -------
    str
        ``text``.

    Raises
    ------
    TypeError
        If ``text`` is not a string.
    ValueError
        If it holds a line break or another non-printable character, or is
        longer than the limit.
    """
    if not isinstance(text, str):
        raise TypeError(f"{what} must be a string, got {type(text).__name__}")
    limit = _TEXT_LIMITS[what.split()[0]]
    if not text.isprintable() or len(text) > limit:
        raise ValueError(f"{what} must be one line of at most {limit} printable characters "
                         f"(no line breaks, tabs or control characters), got {text!r}")
    return text


def check_parameter_name(name):
    """Refuse a parameter name the generated kernels cannot use.

    A name that is not ASCII letters, digits and ``_`` starting with a
    letter (at most 40), a Python or C keyword, ``numpy`` (the NumPy module
    in the generated code), or a name the generated code uses
    itself (outputs ``num<k>``, ``den<k>``, ``pn<k>``, ``pd<k>``,
    temporaries ``x<k>``).

    Raises
    ------
    ValueError
        Naming the parameter.
    """
    if not _PARAMETER_PATTERN.fullmatch(name):
        raise ValueError(f"parameter {name!r} cannot be a name in the generated NumPy and C "
                         f"kernels: a parameter is 1 to 40 ASCII letters, digits and '_', "
                         f"starting with a letter; rename it in the loop")
    if name in _ARGUMENT_NAMES:
        raise ValueError(f"parameter {name!r} has the name of an argument of Loop's methods "
                         f"({', '.join(sorted(_ARGUMENT_NAMES))}): rename it in the loop")
    if keyword.iskeyword(name) or name in _C_KEYWORDS or _GENERATED_NAME.fullmatch(name):
        raise ValueError(f"parameter {name!r} cannot be a name in the generated NumPy and C kernels "
                         f"(a Python or C keyword, 'numpy', a leading '_', or a name the kernels "
                         f"use: num<k>, den<k>, pn<k>, pd<k>, x<k>): rename it in the loop")


#: Highest order of a plant and degree of an environment, and the largest
#: literal exponent: the ZOH, the polynomial and its root count grow with
#: them, and a haptic loop needs a few tens at most.
MAX_ORDER = 100

_BINARY = {ast.Add: sp.Add, ast.Mult: sp.Mul,
           ast.Sub: lambda a, b: a - b, ast.Div: lambda a, b: a / b, ast.Pow: lambda a, b: a**b}
_FUNCTIONS = {"exp": sp.exp, "sqrt": sp.sqrt}


def parse_expression(text, what):
    """A SymPy expression from arithmetic text, built from its syntax tree, never evaluated.

    Only numbers, names, ``+ - * / **`` (or ``^``), brackets and calls of
    ``exp`` and ``sqrt`` are allowed: anything else (attributes,
    subscripts, other calls, comparisons, lambdas) is refused, so a string
    from a loop file cannot run code.  A literal exponent is at most
    :data:`MAX_ORDER` and an exponent holds no power (``2**(10**10)`` would
    take SymPy forever).  A decimal is the exact rational it writes (``0.25``
    is 1/4, ``0.1`` is 1/10, ``1e-3`` is 1/1000), not the nearest binary
    float: the derivation stays exact.

    Parameters
    ----------
    text : str
        The expression as written (a plant, an environment, a loop file's bound).
    what : str
        What it is, for the error message (``"plant"``, ``"paper.toml: bound min of 'T'"``).

    Raises
    ------
    ValueError
        Naming ``what`` and ``text``: a syntax error or a construct that is not allowed.
    """
    if len(text) > MAX_EXPRESSION_LENGTH:
        raise ValueError(f"{what} is {len(text)} characters long, above the limit of "
                         f"{MAX_EXPRESSION_LENGTH}")
    source = text.replace("^", "**")
    try:
        tree = ast.parse(source, mode="eval")
    except SyntaxError as exc:
        raise ValueError(f"{what} {text!r} is not a valid expression: {exc.msg}") from None
    except (RecursionError, MemoryError):
        raise ValueError(f"{what} is nested too deeply to parse") from None
    fixed = {"s": model.s, "z": model.z, "T": model.T, "pi": sp.pi}

    def check_exponent(value):
        if abs(value) > MAX_ORDER:
            raise ValueError(f"{what} {text!r}: exponent {value} is above the limit {MAX_ORDER}")

    def build(node, in_exponent=False):
        if isinstance(node, ast.BinOp) and type(node.op) in _BINARY:
            exponent = isinstance(node.op, ast.Pow)
            if exponent and in_exponent:
                raise ValueError(f"{what} {text!r}: a power inside an exponent is not allowed")
            left, right = build(node.left, in_exponent), build(node.right, in_exponent or exponent)
            # An exponent written as a product (2**(10*10)), and powers of
            # powers (((s + 1)**100)**100, which SymPy joins), are checked
            # before and after the power is taken.
            if exponent and right.is_Number:
                check_exponent(right)
            built = _BINARY[type(node.op)](left, right)
            if exponent:
                check_exponent(max((abs(p.exp) for p in sp.sympify(built).atoms(sp.Pow)
                                    if p.exp.is_Number), default=0))
            return built
        if isinstance(node, ast.UnaryOp) and isinstance(node.op, (ast.UAdd, ast.USub)):
            value = build(node.operand, in_exponent)
            return -value if isinstance(node.op, ast.USub) else value
        if isinstance(node, ast.Constant) and type(node.value) in (int, float):
            if in_exponent:
                check_exponent(node.value)
            if isinstance(node.value, int):
                return sp.Integer(node.value)
            if not math.isfinite(node.value):
                raise ValueError(f"{what} {text!r}: {node.value!r} is not a finite number")
            # The decimal as written, exactly (0.25 is 1/4, 0.1 is 1/10): a
            # Float would make the plant's polynomials inexact, which SymPy's
            # factoring over the parameters cannot take.
            written = ast.get_source_segment(source, node) or repr(node.value)
            return sp.Rational(written.replace("_", ""))
        if isinstance(node, ast.Name) and not node.id.startswith("_"):
            return fixed.get(node.id) or sp.Symbol(node.id)
        if (isinstance(node, ast.Call) and isinstance(node.func, ast.Name)
                and node.func.id in _FUNCTIONS and len(node.args) == 1 and not node.keywords):
            inner = node.args[0]
            if node.func.id == "exp" and any(isinstance(n, ast.Call) and
                                             getattr(n.func, "id", None) == "exp"
                                             for n in ast.walk(inner)):
                raise ValueError(f"{what} {text!r}: exp() inside exp() is not allowed")
            return _FUNCTIONS[node.func.id](build(inner, in_exponent))
        shown = ast.get_source_segment(source, node) or type(node).__name__
        raise ValueError(f"{what} {text!r}: {shown!r} is not allowed (numbers, names, + - * / **, "
                         f"brackets, exp() and sqrt() only)")

    try:
        expr = build(tree.body)
    except (TypeError, ValueError, ZeroDivisionError, OverflowError) as exc:
        if isinstance(exc, ValueError) and str(exc).startswith(what):
            raise
        raise ValueError(f"{what} {text!r} is not a valid expression: {exc}") from None
    except RecursionError:
        raise ValueError(f"{what} is nested too deeply to build (a long chain of + or *, "
                         f"say)") from None
    if not isinstance(expr, sp.Expr):
        raise ValueError(f"{what} {text!r} is not an expression")
    return expr


def _exact_decimals(expr):
    """Every SymPy Float in ``expr`` as the exact rational of its decimal digits (0.25 -> 1/4).

    A text is parsed that way already (:func:`parse_expression`); a SymPy
    expression given directly may hold Floats, which make the plant's
    polynomials inexact (SymPy's factoring over the parameters fails on them).
    """
    return expr.xreplace({f: sp.Rational(str(f)) for f in expr.atoms(sp.Float)})


def _real_symbols(expr):
    """Replace every parameter symbol by a real one of the same name (T stays positive)."""
    swap = {}
    for symbol in expr.free_symbols:
        name = str(symbol)
        if name == "d":
            raise ValueError("the delay d is not part of the plant or the environment: "
                             "the loop applies z**-d itself")
        if symbol in (model.s, model.z, model.T):
            continue
        if name in ("s", "z", "T"):
            swap[symbol] = {"s": model.s, "z": model.z, "T": model.T}[name]
        else:
            swap[symbol] = sp.Symbol(name, real=True)
    return expr.xreplace(swap)


def _plant_from_control(plant):
    num, den = plant.num[0][0], plant.den[0][0]
    if plant.ninputs != 1 or plant.noutputs != 1:
        raise ValueError("plant must be a single-input single-output transfer function")
    if plant.dt not in (0, None):
        raise ValueError(f"plant must be continuous-time (dt = 0), got dt = {plant.dt!r}")
    s = model.s

    def poly(coefficients):
        return sp.Add(*[sp.Rational(float(c)) * s**k
                        for k, c in enumerate(reversed(list(coefficients)))])

    return poly(num) / poly(den)


def _clearly_nonzero(expr):
    """True when ``expr`` is visibly not zero: its value at a point of rationals is not.

    A cheap test before ``sp.simplify`` (a third of a second on an
    environment): an expression that is not 0 at some point is not
    identically 0.  Where the value is small or cannot be computed, False:
    the caller then decides with ``simplify``.
    """
    point = {x: sp.Rational(7 + 3 * k, 5 + 2 * k)
             for k, x in enumerate(sorted(expr.free_symbols, key=str))}
    try:
        value = complex(expr.xreplace(point).evalf(30))
    except (TypeError, ValueError, ArithmeticError):
        return False
    return bool(math.isfinite(abs(value)) and abs(value) > 1e-9)


def _check_rational(expr, variable, what, other):
    if expr.has(other):
        raise ValueError(f"{what} must not contain {other}")
    if not expr.is_rational_function(variable):
        raise ValueError(f"{what} must be a rational function of {variable}, got {expr}")
    num, den = sp.fraction(sp.cancel(sp.together(expr)))
    if den == 0 or (not _clearly_nonzero(num) and sp.simplify(num) == 0):
        raise ValueError(f"{what} must not be zero")
    nd, dd = sp.degree(num, variable), sp.degree(den, variable)
    if dd > MAX_ORDER:
        raise ValueError(f"{what} has degree {dd} in {variable}, above the limit {MAX_ORDER}")
    if nd > dd:
        raise ValueError(f"{what} must be proper: the degree of its numerator in {variable} "
                         f"({nd}) exceeds that of its denominator ({dd}); got {expr}")
    return num, den


def parse_plant(plant):
    """The plant ``G(s)`` as a SymPy expression, checked: rational in ``s`` and proper.

    ``plant`` is a string, a SymPy expression or a ``control.TransferFunction``
    (continuous-time, numeric).

    Raises
    ------
    TypeError
        For another kind of object.
    ValueError
        If it is not rational in ``s``, not proper, zero, or uses ``z`` or ``d``.
    """
    if isinstance(plant, (str, sp.Basic)):
        return _parsed_plant(plant)
    if hasattr(plant, "num") and hasattr(plant, "den") and hasattr(plant, "dt"):
        return _checked_plant(_plant_from_control(plant))
    raise TypeError(f"plant must be a string, a SymPy expression or a "
                    f"control.TransferFunction, got {type(plant).__name__}")


@functools.lru_cache(maxsize=128)
def _parsed_plant(plant):
    """:func:`parse_plant` of a string or a SymPy expression, kept: the check costs SymPy time."""
    expr = parse_expression(plant, "plant") if isinstance(plant, str) else sp.sympify(plant)
    return _checked_plant(expr)


def _checked_plant(expr):
    expr = _real_symbols(_exact_decimals(expr))
    _check_rational(expr, model.s, "plant G(s)", model.z)
    return expr


def parse_actuator(actuator, plant):
    """The actuator ``A(s)`` (force command to the force on the driven mass), checked.

    ``None`` is ``1``: the command acts on the mass itself.  The rest of the
    plant, ``G / A``, is the driven mass's force to position: a rational,
    proper function of ``s`` in the plant's parameters whose relative
    degree is 2 (a force accelerates a mass), so that the mass's velocity
    is a state, driven by no input directly, on which Coulomb friction acts
    (:meth:`LoopModel.driven_mass`).

    Raises
    ------
    TypeError
        For another kind than a string or a SymPy expression.
    ValueError
        If ``A`` is not rational and proper in ``s``, has a parameter the
        plant has not, or leaves a ``G / A`` that is not a mass's.
    """
    if actuator is None:
        return None
    expr = _rational(actuator, "actuator", "actuator A(s)", model.s, model.z)
    extra = expr.free_symbols - plant.free_symbols
    if extra:
        raise ValueError(f"actuator A(s) = {expr}: {', '.join(sorted(map(str, extra)))} "
                         f"is not a parameter of the plant (A is a factor of G)")
    _mass_parts(plant, expr)
    return expr


def _mass_parts(plant, actuator):
    """``(N, D)`` of the driven mass ``G / A``, or ValueError saying why it is not a mass's."""
    mass = sp.cancel(sp.together(plant / (1 if actuator is None else actuator)))
    num, den = sp.fraction(mass)
    relative = sp.degree(den, model.s) - sp.degree(num, model.s)
    if relative != 2:
        where = ("the plant" if actuator is None else f"the plant over the actuator, {mass},")
        hint = (" (a lag or filter between the command and the mass? give it as the loop's "
                "actuator, e.g. actuator = \"1/(tau*s + 1)\")" if relative > 2 else "")
        raise ValueError(f"Coulomb friction acts on the driven mass, whose position per force "
                         f"has relative degree 2; {where} has relative degree {relative}{hint}")
    return num, den


def parse_environment(environment):
    """The environment ``VE(z)`` as a SymPy expression, checked: rational in ``z`` and proper.

    Raises
    ------
    TypeError
        If it is not a string or a SymPy expression.
    ValueError
        If it is not rational in ``z``, not proper (not causal), zero, or uses
        ``s`` or ``d``.
    """
    return _rational(environment, "environment", "environment VE(z)", model.z, model.s)


def _rational(value, what, label, variable, other):
    """``value`` (text or SymPy) as a checked rational function of ``variable`` (:func:`_check_rational`)."""
    if not isinstance(value, (str, sp.Basic)):
        raise TypeError(f"{what} must be a string or a SymPy expression, "
                        f"got {type(value).__name__}")
    return _parsed_rational(value, what, label, variable, other)


@functools.lru_cache(maxsize=128)
def _parsed_rational(value, what, label, variable, other):
    """:func:`_rational` of a string or a SymPy expression, kept: the check costs SymPy time."""
    expr = parse_expression(value, what) if isinstance(value, str) else sp.sympify(value)
    expr = _real_symbols(_exact_decimals(expr))
    _check_rational(expr, variable, label, other)
    return expr


def poly_coeffs(expr, z):
    """Coefficients of a polynomial ``expr`` in ``z``, highest power first.

    As ``sp.Poly(sp.expand(expr), z).all_coeffs()`` gives them; where that
    would hold them in SymPy's expression domain EX anyway (see
    ``_in_expression_domain``), without its search for a smaller one
    (most of the time on a loop's parts, which hold ``exp`` of the poles).
    """
    expanded = sp.expand(expr)
    if _non_polynomial(expanded):
        try:
            coefficients = sp.Poly(expanded, z, domain=sp.EX).all_coeffs()
        except CoercionFailed:    # nan or zoo: not in EX, the search below says what they are
            coefficients = []
        if _in_expression_domain(coefficients):
            return coefficients
    return sp.Poly(expanded, z).all_coeffs()


def _non_polynomial(expr):
    """Whether ``expr`` holds a function or a power that is not an integer one (``sqrt(2)``)."""
    return bool(expr.atoms(sp.Function)) or any(not p.exp.is_Integer for p in expr.atoms(sp.Pow))


def _in_expression_domain(coefficients, tries=3):
    """True when SymPy's ``construct_domain(coefficients)`` is sure to be EX; False: not known.

    For coefficients with a symbol SymPy tries a polynomial ring or a
    fraction field over generators (the bases of the factors of their
    numerators and denominators) and falls back to EX when two generators
    share a symbol (``exp(-b*T/m)`` and ``m``) or one is an irrational
    algebraic number.  The generators of a list are those of its members
    together, so a single coefficient with a symbol that already falls back
    to EX is a witness for the whole list.  A few of the smallest candidates
    are tried (each try costs its ``as_numer_denom``).
    """
    candidates = sorted((c for c in coefficients if c.free_symbols and _non_polynomial(c)),
                        key=lambda c: len(sp.Add.make_args(c)))
    return any(sp.construct_domain([c])[0] == sp.EX for c in candidates[:tries])


def is_affine(coefficients, symbols):
    """Whether every coefficient is a polynomial of total degree <= 1 in ``symbols``.

    A symbol inside a function (``exp(-b*T/m)``), under a root or in a
    denominator makes a coefficient no polynomial in it: not affine.
    """
    for c in coefficients:
        if not c.has(*symbols):
            continue
        # Poly expands ``c`` itself, and its generators are exactly ``symbols``;
        # the ground domain EX skips the search for a smaller one (half the
        # time, spent in construct_domain) that a degree does not depend on.
        try:
            poly = sp.Poly(c, *symbols, domain="EX")
        except sp.PolynomialError:
            return False
        if poly.total_degree() > 1 or any(coef.has(*symbols) for coef in poly.coeffs()):
            return False
    return True


class LoopModel:
    """The symbolic loop: plant, environment, their parameters and the loop polynomial.

    Parameters
    ----------
    plant : str, sympy.Expr or control.TransferFunction
        ``G(s)``, force to position, proper and rational in ``s``.
    environment : str or sympy.Expr
        ``VE(z)``, sampled position to force, proper and rational in ``z``.
    values : dict, optional
        Default values of parameters.
    name : str, optional
        A label for reprs and generated files: it becomes a file stem, so
        it is a word (:func:`check_loop_name`); default ``"loop"``.
    units : dict, optional
        Unit of each parameter, as one line of text (:func:`check_text_line`).
    description : str, optional
        One line of printable text on what the loop is (:func:`check_text_line`).
    plane : (str, str), optional
        The default ``(x, y)`` parameter plane; checked to be jointly affine.
    actuator : str or sympy.Expr, optional
        ``A(s)``, the factor of ``G`` from the force command to the force
        on the driven mass (an amplifier's lag); default ``1``.  It says
        where Coulomb friction acts (:func:`parse_actuator`).

    Attributes
    ----------
    parameters : tuple of str
        The names of the loop's parameters: the plant's and the
        environment's, then ``T`` and ``d``.
    zoh_method : str
        How the plant's pulse transfer function was derived:
        ``'residues'`` (symbolically) or ``'matrix exponential'``
        (numerically, at 30 digits, once the plant's values are known).

    Raises
    ------
    TypeError, ValueError
        If the plant or the environment is not a proper rational function
        of its variable, uses ``d``, or names a parameter the generated
        kernels cannot take (:func:`check_parameter_name`); if the name,
        the description or a unit is not the text allowed.
    """

    def __init__(self, plant, environment, *, values=None, name=None, units=None,
                 description="", plane=None, actuator=None):
        self.plant = parse_plant(plant)
        self.environment = parse_environment(environment)
        self.actuator = parse_actuator(actuator, self.plant)
        #: What depends only on the plant, the environment and the actuator (the
        #: derivation, the plant at numbers): shared by every model of this loop
        #: in this process (``symstab._memo``).
        self.shared_memo = _SHARED((self.plant, self.environment, self.actuator, str(cache_dir())))
        self.name = check_loop_name("loop" if name is None else name)
        self.description = check_text_line("description", description)
        symbols = {str(x): x for x in self.plant.free_symbols | self.environment.free_symbols}
        symbols.pop("s", None)
        symbols.pop("z", None)
        symbols.pop("T", None)
        for name in symbols:
            check_parameter_name(name)
        #: ``{name: SymPy symbol}`` of the loop's parameters (``T`` last), read-only.
        self.symbols = dict(sorted(symbols.items()))
        self.symbols["T"] = model.T
        #: The parameters that appear in the plant ``G(s)``, and in the environment.
        self.plant_names = tuple(n for n in self.symbols
                                  if self.symbols[n] in self.plant.free_symbols)
        self.environment_names = tuple(n for n in self.symbols
                                        if self.symbols[n] in self.environment.free_symbols)
        self.parameters = tuple(self.symbols) + ("d",)
        self.defaults = {}
        for key, value in (values or {}).items():
            if key not in self.parameters and key != "Td":
                raise ValueError(f"values: {key!r} is not a parameter of this loop "
                                 f"(parameters: {', '.join(self.parameters)}, or Td for d)")
            self.defaults[key] = value
        if "d" in self.defaults and "Td" in self.defaults:
            raise ValueError("values: give the delay once, d (in samples) or Td (in seconds)")
        self.units = {}
        for key, unit in (units or {}).items():
            if key not in self.parameters:
                raise ValueError(f"units: {key!r} is not a parameter of this loop "
                                 f"(parameters: {', '.join(self.parameters)})")
            self.units[key] = check_text_line(f"unit of {key!r}", str(unit))
        self.zoh_method = self._zoh_method
        self.plane = None
        if plane is not None:
            plane = tuple(plane)
            if len(plane) != 2:
                raise ValueError(f"plane must be two parameter names, got {plane!r}")
            self.check_plane(plane)
            self.plane = plane

    @shared_property
    def _zoh_method(self):
        poles = written_poles(sp.together(self.plant / model.s))
        numeric_plant = not (self.plant.free_symbols - {model.s})
        return "residues" if poles is not None and not numeric_plant else "matrix exponential"

    def __repr__(self):
        return (f"Loop(plant={str(self.plant)!r}, environment={str(self.environment)!r}, "
                f"zoh={self.zoh_method!r})")

    @shared_property
    def _derivation(self):
        """The loop's derivation cached on disk (:mod:`symstab.symbolic.derivation_cache`)."""
        return DerivationCache(self.plant, self.environment,
                               dict(self.symbols, s=model.s, z=model.z, _eps=FRACTION))

    def _derived(self, name, derive, agrees=None):
        """``derive()``, or what an earlier derivation of this loop stored under ``name``.

        ``agrees(value)`` checks a stored value against an independent
        computation at numbers (:meth:`_check_point`): one that disagrees,
        or cannot be evaluated, is derived again, not trusted.
        """
        value = self._derivation.get(name)
        if value is not DerivationCache.MISSING and agrees is not None:
            try:
                trusted = agrees(value)
            except (ArithmeticError, TypeError, ValueError):
                trusted = False
            if not trusted:
                value = DerivationCache.MISSING
        if value is DerivationCache.MISSING:
            value = derive()
            self._derivation.put(name, value)
        return value

    #: The point z0 on which cached polynomials are checked (off the unit circle
    #: and the real axis, where poles and their cancellations live).
    _CHECK_Z = complex(1.3, 0.4)

    @shared_property
    def _check_point(self):
        """Parameter values (none 0, 1 or equal to another) for checking cached parts."""
        point = {model.T: sp.Float("0.0213", PLANT_DIGITS)}
        others = [n for n in self.symbols if n != "T"]
        for k, name in enumerate(others):
            point[self.symbols[name]] = sp.Float(repr(1 + 0.3183098861837907 * (k + 1)), PLANT_DIGITS)
        return point

    #: The fraction of a period the fractional plant is checked at (:meth:`_fractional_agrees`).
    _CHECK_FRACTION = sp.Float("0.3183098861837907", PLANT_DIGITS)

    def _at_check_point(self, coefficients, point=None):
        """A polynomial (coefficients highest first) at :attr:`_CHECK_Z` and :meth:`_check_point`."""
        point = self._check_point if point is None else point
        total = 0j
        for c in coefficients:
            total = total * self._CHECK_Z + complex(sp.N(c.xreplace(point), PLANT_DIGITS))
        return total

    @staticmethod
    def _close(a, b):
        return bool(abs(a - b) <= 1e-9 * max(abs(a), abs(b)) and np.isfinite(abs(a)))

    def _environment_agrees(self, parts):
        at = {**self._check_point, model.z: sp.Float("1.3", PLANT_DIGITS) + sp.I * sp.Float("0.4", PLANT_DIGITS)}
        expected = complex(sp.N(self.environment.xreplace(at), PLANT_DIGITS))
        return self._close(self._at_check_point(parts[0]) / self._at_check_point(parts[1]),
                           expected)

    def _pulse_agrees(self, parts, fraction=None):
        """Whether (P_n, P_d) give the matrix exponential's Z[ZOH G] at the check point.

        With a ``fraction`` of a period of delay, whether ``(N_eps, z P_d)`` in
        :data:`FRACTION` give :func:`numeric_fractional_zoh`'s ``P_eps`` there.
        """
        point = dict(self._check_point)
        if fraction is not None:
            point[FRACTION] = fraction
        num, den = sp.fraction(sp.together(self.plant.xreplace(point)))
        with mpmath.workdps(PLANT_DIGITS):
            num, den = ([mpmath.mpf(sp.Float(c, PLANT_DIGITS)) for c in sp.Poly(p, model.s).all_coeffs()]
                        for p in (num, den))
            T = mpmath.mpf(point[model.T])
            p_n, p_d = (numeric_zoh(num, den, T, dps=PLANT_DIGITS) if fraction is None else
                        numeric_fractional_zoh(num, den, T, mpmath.mpf(fraction),
                                               dps=PLANT_DIGITS))
            z0 = mpmath.mpc(self._CHECK_Z.real, self._CHECK_Z.imag)
            expected = complex(mpmath.polyval(p_n, z0) / mpmath.polyval(p_d, z0))
        return self._close(self._at_check_point(parts[0], point)
                           / self._at_check_point(parts[1], point), expected)

    def _parts_agree(self, parts):
        """Whether the delayed and direct parts are Ve_d P_d and Ve_n P_n at the check point."""
        (ve_n, ve_d), (p_n, p_d) = self.environment_parts, self._plant_parts
        at = self._at_check_point
        return (self._close(at(parts[0]), at(ve_d) * at(p_d))
                and self._close(at(parts[1]), at(ve_n) * at(p_n)))

    @shared_property
    def environment_parts(self):
        """``(Ve_n, Ve_d)``: the environment's numerator and denominator coefficients in ``z``.

        Lists of SymPy expressions in the loop's symbols, highest power of
        ``z`` first, from ``VE(z)`` brought over one denominator and
        cancelled (derived once, and kept in the derivation cache).
        """
        def derive():
            num, den = sp.fraction(sp.cancel(sp.together(self.environment)))
            return poly_coeffs(num, model.z), poly_coeffs(den, model.z)

        return self._derived("environment_parts", derive, self._environment_agrees)

    @shared_property
    def _plant_parts(self):
        """(P_n, P_d) coefficient lists in z (symbolic), or None for the numeric path."""
        if self.zoh_method != "residues":
            return None

        def derive():
            pulse = zoh_pulse_transfer_function(self.plant)
            num, den = sp.fraction(sp.cancel(pulse))
            return poly_coeffs(num, model.z), poly_coeffs(den, model.z)

        return self._derived("plant_parts", derive, self._pulse_agrees)

    @shared_property
    def _fractional_plant_parts(self):
        """``(N_eps, z P_d)``: the plant with a fraction ``eps`` of a period of delay, or None.

        Coefficient lists in ``z`` (symbolic, highest power first) of the
        modified z-transform
        (:func:`~symstab.symbolic.discretize.fractional_zoh_pulse_transfer_function`)
        over the denominator of :attr:`_plant_parts` times ``z``, with
        :data:`FRACTION` for ``eps``: ``P_eps = N_eps / (z P_d)``, so that a
        loop delay of ``(d + eps) T`` has ``chi = z**d (z P_d) Ve_d + N_eps
        Ve_n``, the integer-delay form of this plant.  None for the numeric
        path (:func:`~symstab.symbolic.discretize.numeric_fractional_zoh`
        gives the same at numbers).
        """
        if self._plant_parts is None:
            return None

        def derive():
            z = model.z
            den = list(self._plant_parts[1]) + [sp.Integer(0)]
            pulse = fractional_zoh_pulse_transfer_function(self.plant, FRACTION)
            num, scale = sp.fraction(sp.cancel(
                pulse * sp.Add(*[c * z**k for k, c in enumerate(reversed(den))])))
            # A factor free of z may stay below (exp(eps p T) of a complex pair's poles).
            if scale.has(z) or not num.is_polynomial(z):
                # SymPy did not cancel the integer-delay denominator out of it (the
                # exponentials of a complex pair as unrelated generators): the numeric path.
                return [], []
            return [c / scale for c in poly_coeffs(num, z)], den

        parts = self._derived("fractional_plant_parts", derive,
                              lambda parts: not parts[0] or self._fractional_agrees(parts))
        return parts if parts[0] else None

    @shared_property
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

    def plant_parts_of(self, fraction=False):
        """The symbolic plant's ``(P_n, P_d)``, or with ``fraction`` ``(N_eps, z P_d)`` (or None)."""
        return self._fractional_plant_parts if fraction else self._plant_parts

    def _fractional_agrees(self, parts):
        """:meth:`_pulse_agrees` of ``(N_eps, z P_d)`` at :attr:`_CHECK_FRACTION`."""
        return self._pulse_agrees(parts, self._CHECK_FRACTION)

    def pulse_transfer_function(self):
        """``Z[ZOH G](z)`` as a SymPy rational function of ``z``.

        Raises
        ------
        ValueError
            If the loop's plant is discretised numerically (see
            :attr:`zoh_method`).
        """
        if self._plant_parts is None:
            raise ValueError("this plant's denominator has a factor of degree 3 or more in s: "
                             "its pulse transfer function is computed numerically "
                             "(zoh_method = 'matrix exponential') once its values are given")
        num, den = self._plant_parts
        z = model.z
        return sp.Add(*[c * z**k for k, c in enumerate(reversed(num))]) / sp.Add(
            *[c * z**k for k, c in enumerate(reversed(den))])

    def characteristic_polynomial(self, **values):
        """``chi(z) = z**d Ve_d P_d + Ve_n P_n`` with a symbolic integer delay ``d``.

        Parameters
        ----------
        **values
            Parameter values to substitute (optional).  A plant discretised
            numerically needs the values of all its parameters and ``T``.

        Returns
        -------
        sympy.Expr
            Its roots in ``z`` are the closed-loop poles.
        """
        unknown = set(values) - set(self.parameters)
        if unknown:
            raise TypeError(f"unknown parameter(s) {', '.join(sorted(unknown))}; "
                            f"parameters: {', '.join(self.parameters)}")
        z = model.z
        # The residue path's parts do not depend on the values: derived (or
        # read from the cache) once.
        delayed, direct = (self._parts if self._plant_parts is not None
                           else self._symbolic_parts(values))
        poly = (z**model.d * sp.Add(*[c * z**k for k, c in enumerate(reversed(delayed))])
                + sp.Add(*[c * z**k for k, c in enumerate(reversed(direct))]))
        sub = {self.symbols[k]: v for k, v in values.items() if k != "d"}
        poly = poly.subs(sub)
        if "d" in values:
            poly = poly.subs(model.d, check_delay(values["d"]))
        return poly

    def _symbolic_parts(self, values=None):
        ve_n, ve_d = self.environment_parts
        if self._plant_parts is None:
            need = [n for n in self.plant_names + ("T",) if n not in (values or {})]
            if need:
                raise ValueError(f"the plant is discretised numerically: give "
                                 f"{', '.join(need)} to get its polynomial")
            p_n, p_d = self._numeric_plant(tuple(float(values[n]) for n in self.plant_names),
                                           float(values["T"]))[:2]
            p_n = [sp.Float(str(c), PLANT_DIGITS) for c in p_n]
            p_d = [sp.Float(str(c), PLANT_DIGITS) for c in p_d]
        else:
            p_n, p_d = self._plant_parts
        z = model.z

        def product(a, b):
            pa = sp.Add(*[c * z**k for k, c in enumerate(reversed(a))])
            pb = sp.Add(*[c * z**k for k, c in enumerate(reversed(b))])
            return poly_coeffs(pa * pb, z)

        return product(ve_d, p_d), product(ve_n, p_n)

    @shared_property
    def _parts(self):
        """Delayed and direct coefficient lists (symbolic path only)."""
        return self._derived("parts", self._symbolic_parts, self._parts_agree)

    def affine_parameters(self):
        """Names of the parameters in which the characteristic polynomial is affine.

        These can be the axes of a parameter plane (:meth:`boundary`,
        :meth:`limits`) or the variable of :meth:`~symstab.Loop.stable_intervals`.  With a
        plant discretised numerically only environment parameters qualify.
        """
        out = []
        for name in self.symbols:
            if self.affine_in((name,)):
                out.append(name)
        return tuple(out)

    @method_cache(shared=True)
    def affine_in(self, names):
        """Whether the characteristic polynomial is affine in the parameters ``names`` jointly.

        Parameters
        ----------
        names : tuple of str
            One or two parameter names of the loop.

        Returns
        -------
        bool
            True when every coefficient of chi is ``c0 + sum(c_i p_i)``
            with no product of the ``p_i``: the parameters then span a plane
            (or a line) the D-decomposition and the line engine can take.
        """
        return self._derived(f"affine {','.join(names)}", lambda: self._decide_affine(names))

    def _decide_affine(self, names):
        symbols = [self.symbols[n] for n in names]
        # P_n and P_d hold the plant's parameters and T; Ve_n and Ve_d the environment's.
        in_plant = [n in self.plant_names or n == "T" for n in names]
        in_environment = [n in self.environment_names for n in names]
        if self.zoh_method != "residues":
            if any(in_plant):
                return False
            ve_n, ve_d = self.environment_parts
            return is_affine(ve_n + ve_d, symbols)
        if len(names) == 2 and any(n in self.plant_names for n in names) and not all(
                n in self.plant_names for n in names):
            # One in each block: affine only if the cross terms cancel, which
            # the slopes computed block by block would miss; refuse instead.
            return False
        if any(n in self.plant_names and n in self.environment_names for n in names):
            return False
        # chi's parts are Ve_d P_d and Ve_n P_n, none of them 0: a product is
        # affine in parameters its one factor is free of exactly when its
        # other factor is (a square's term times the other's leading
        # coefficient survives), so the factors decide, without the product.
        if not any(in_plant):
            ve_n, ve_d = self.environment_parts
            return is_affine(ve_n + ve_d, symbols)
        if not any(in_environment):
            p_n, p_d = self._plant_parts
            return is_affine(p_n + p_d, symbols)
        delayed, direct = self._parts
        return is_affine(delayed + direct, symbols)

    def check_plane(self, names):
        """Refuse a plane (or line) whose parameters the loop cannot decompose over.

        Parameters
        ----------
        names : tuple of str
            The plane's one or two parameter names.

        Raises
        ------
        TypeError
            A name that is not a string.
        ValueError
            A name that is not a parameter of the loop, the same name twice,
            or parameters that do not enter chi (jointly) affinely.
        """
        for name in names:
            if not isinstance(name, str):
                raise TypeError(f"a plane parameter must be a name (str), got {type(name).__name__}")
            if name not in self.symbols:
                raise ValueError(f"{name!r} is not a parameter of this loop "
                                 f"(parameters: {', '.join(self.symbols)})")
        if len(set(names)) != len(names):
            raise ValueError(f"the plane's parameters must differ, got {names[0]!r} twice")
        for name in names:
            if not self.affine_in((name,)):
                raise ValueError(
                    f"parameter {name!r} does not enter the characteristic polynomial affinely; "
                    f"a plane or a line needs affine parameters: "
                    f"{', '.join(self.affine_parameters()) or 'none'}")
        if len(names) == 2 and not self.affine_in(tuple(names)):
            raise ValueError(f"parameters {names[0]!r} and {names[1]!r} do not enter the "
                             f"characteristic polynomial jointly affinely (a product of the two "
                             f"appears)")

    def _numeric_plant(self, plant_values, T, eps=None):
        plant_values = tuple(plant_values)
        self._warn_if_not_physical(plant_values, T)
        return self._plant_cache(plant_values, T, None if eps is None else float(eps))

    @method_cache(maxsize=4096)
    def _warn_if_not_physical(self, plant_values, T):
        """A :class:`NonPhysicalPlantWarning` where :meth:`plant_defect` finds one: once per
        point and model (the plant's numbers themselves are shared by the models of a loop)."""
        defect = self._plant_defect(plant_values, T)
        if defect is not None:
            warnings.warn(defect, NonPhysicalPlantWarning, stacklevel=4)

    @method_cache(maxsize=4096, shared=True)
    def _plant_defect(self, plant_values, T):
        return self.plant_defect(plant_values, T)

    @shared_property
    def _plant_functions(self):
        """mpmath functions of (plant values..., T) giving P_n and P_d (symbolic path)."""
        num, den = self._plant_parts
        return self._plant_function([list(num), list(den)])

    @shared_property
    def _fractional_plant_functions(self):
        """mpmath function of (plant values..., T, eps) giving N_eps and z P_d (symbolic path)."""
        num, den = self._fractional_plant_parts
        return self._plant_function([list(num), list(den)], fraction=True)

    def _plant_function(self, exprs, fraction=False):
        """An mpmath function of (plant values..., T) giving ``exprs`` (``..., T, eps)`` with ``fraction``).

        The arguments are renamed ``_plant0``, ``_plant1``, ...: a parameter
        named like an mpmath name (``e``, ``exp``) would otherwise shadow it
        in the generated function (``e`` for Euler's number), and ``T`` in
        the plant would be an argument twice.  Plain symbols, not dummies:
        lambdify replaces dummy arguments once more, one tree walk per
        argument over the whole closed form (most of its time), and prints
        the terms in an order that follows the dummies' counter.  The
        plant's own ``T``, when it has one, is given the same value by the
        caller as the last argument.
        """
        names = [self.symbols[n] for n in self.plant_names]
        args = [sp.Symbol(f"_plant{i}") for i in range(len(self.plant_names) + 1 + fraction)]
        rename = dict(zip(names, args, strict=False))
        rename.setdefault(model.T, args[len(names)])
        if fraction:
            rename[FRACTION] = args[-1]
        exprs = [[sp.sympify(c).xreplace(rename) for c in part] for part in exprs]
        return sp.lambdify(args, exprs, modules="mpmath", **NO_DOCSTRING)

    def _closed_form_plant(self, point, T, eps=None):
        """P_n, P_d of the derived closed form at ``point``, to :data:`PLANT_DIGITS` digits.

        With a fraction ``eps`` of a period of delay, ``N_eps`` and ``z P_d``
        of :attr:`_fractional_plant_parts` instead, the same way.

        The closed form cancels: ``1/(m s**2 + b s)`` has ``(exp(-b T/m) - 1
        + b T/m) m / b**2``, whose leading terms' difference loses ``2
        log10(m / (b T))`` digits (28 at ``b T/m = 1e-14``; at 1e-300 every
        digit of any fixed precision, so that two precisions agree on a wrong
        value).  The working digits therefore start above the loss that
        extreme values can cause -- the plant's order times the decades of
        the values and ``T`` away from 1 -- and are doubled until two
        evaluations agree to ``PLANT_DIGITS`` digits of each part's largest
        coefficient (not beyond :data:`PLANT_MAX_DIGITS`); the more precise
        one is kept, and returned with its digits ``(P_n, P_d, digits)``.

        The loss comes from the plant's poles ``p`` in ``s`` (``exp(p T) -
        1`` and its Taylor terms cancel when ``|p T|`` is small, ``exp(p_i
        T) - exp(p_j T)`` when ``|p_i - p_j| T`` is), not from the size of
        the values: ``m = b = 1e300`` is the benign ``b T / m = T``.  So the
        start is the plant's order times the decades of ``|p T|`` and
        ``|p_i - p_j| T`` below 1, from the poles at the point.
        """
        order = len(self._plant_parts[1]) - 1
        digits = PLANT_DIGITS + order * self._cancelled_decades(point, T)
        if digits > PLANT_MAX_DIGITS:
            self._refuse_plant(point, T)
        before = None
        while digits <= PLANT_MAX_DIGITS:
            with mpmath.workdps(digits):
                try:
                    parts = (self._plant_functions(*point, T) if eps is None else
                             self._fractional_plant_functions(*point, T, mpmath.mpf(eps)))
                except ZeroDivisionError:
                    return [mpmath.nan], [mpmath.mpf(0)], digits
                parts = [[mpmath.mpmathify(c) for c in part] for part in parts]
            if not all(mpmath.isfinite(c) for part in parts for c in part):
                return (*parts, digits)
            if before is not None and all(
                    max(abs(a - b) for a, b in zip(old, new, strict=True))
                    <= mpmath.mpf(10) ** -PLANT_DIGITS * max(abs(c) for c in new)
                    for old, new in zip(before, parts, strict=True)):
                return (*parts, digits)
            if before is not None and self._meeting_poles(point, T) is not None:
                # Two precisions disagree because poles meet exactly (k_h = 0):
                # every precision would; the realisation takes the limit.
                return [mpmath.nan], [mpmath.mpf(0)], digits
            before, digits = parts, 2 * digits
        self._refuse_plant(point, T)

    def _refuse_plant(self, point, T):
        self._check_distinct_poles(point, T)
        given = ", ".join(f"{n} = {float(v):g}"
                          for n, v in zip(self.plant_names, point, strict=True))
        raise ValueError(f"the plant's pulse transfer function at {given}, T = {float(T):g} "
                         f"cancels beyond {PLANT_MAX_DIGITS} digits: a parameter is too small "
                         f"or too large for its closed form")

    @shared_property
    def _pole_conditions(self):
        """``[(expression, why)]``: where an expression of the parameters vanishes, poles meet.

        The residues are derived for the poles of ``G(s)/s`` as the symbols
        write them: a factor of the denominator whose leading coefficient
        vanishes loses its order, one whose constant term vanishes puts a
        pole on the hold's pole at ``s = 0``, a quadratic whose discriminant
        vanishes has a double pole, and two factors whose resultant vanishes
        share a pole.  Each is a 0/0 of the closed form that no precision
        resolves.
        """
        s = model.s
        _, den = sp.fraction(sp.cancel(sp.together(self.plant)))
        factors = [f for f, _ in sp.factor_list(den, s)[1] if f.has(s)]
        out = []
        for f in factors:
            c = sp.Poly(f, s).all_coeffs()
            if c[0].free_symbols:
                out.append((c[0], f"the factor {f} loses its leading coefficient (the "
                                  f"plant's order drops)"))
            if len(c) > 1 and c[-1].free_symbols:
                out.append((c[-1], f"the factor {f} has a pole at s = 0, on the pole of "
                                   f"G(s)/s at 0 (the hold's integrator)"))
            if len(c) == 3:
                disc = sp.expand(c[1] ** 2 - 4 * c[0] * c[2])
                if disc.free_symbols:
                    out.append((disc, f"the factor {f} has a double pole (its discriminant "
                                      f"{disc} is 0)"))
        for i, f in enumerate(factors):
            for g in factors[i + 1:]:
                r = sp.resultant(f, g, s)
                if r.free_symbols:
                    out.append((r, f"the factors {f} and {g} share a pole"))
        return out

    def _meeting_poles(self, point, T):
        """``(expression, why, values)`` of the first of :attr:`_pole_conditions` that holds, or None."""
        values = {self.symbols[n]: sp.Rational(float(v))
                  for n, v in zip(self.plant_names, point, strict=True)}
        values.setdefault(model.T, sp.Rational(float(T)))
        for expr, why in self._pole_conditions:
            if expr.xreplace(values) == 0:
                return expr, why, values
        return None

    def _check_distinct_poles(self, point, T):
        """Refuse, naming the parameters and why, a point where :attr:`_pole_conditions` holds.

        Called where neither the closed form nor the realisation gives the
        pulse transfer function (a factor that loses its order); poles that
        merely meet are the realisation's limit, not refused.
        """
        meeting = self._meeting_poles(point, T)
        if meeting is None:
            return
        expr, why, values = meeting
        names = sorted(str(x) for x in expr.free_symbols)
        given = ", ".join(f"{n} = {float(values[self.symbols[n]]):g}" for n in names)
        zero = " and ".join(f"{n} = 0" for n in names
                            if values[self.symbols[n]] == 0) or f"{expr} = 0"
        raise ValueError(
            f"the plant G(s) = {self.plant} is degenerate at {given}: {why}; give "
            f"{' or '.join(names)} another value, or write the plant as it is at {zero} "
            f"(a loop of its own)")

    @shared_property
    def driven_mass(self):
        """mpmath function of (plant values..., T): the actuator's and the driven mass's coefficients.

        ``[A_n, A_d, N, D]`` in ``s``, highest power first: the actuator
        ``A = A_n / A_d`` and the mass ``G / A = N / D`` (relative degree 2),
        from which :mod:`symstab.numeric.simulation.friction` builds the state space on
        which Coulomb friction acts.

        Raises
        ------
        ValueError
            When the plant (over the actuator) is not a mass's force to
            position (:func:`parse_actuator`): said when friction is asked
            for, the loop itself is fine without it.
        """
        actuator = sp.Integer(1) if self.actuator is None else self.actuator
        num, den = _mass_parts(self.plant, self.actuator)
        a_num, a_den = sp.fraction(sp.cancel(sp.together(actuator)))
        return self._plant_function([poly_coeffs(p, model.s) for p in (a_num, a_den, num, den)])

    @shared_property
    def _plant_pole_factors(self):
        """mpmath function of (plant values..., T): coefficients of the denominator's factors in ``s``.

        The closed-form path has factors of degree 2 at most, so each
        factor's poles come from the quadratic formula (in its stable form)
        rather than from a root finder, which would round ``s + 1e-300`` to
        ``s``.
        """
        _, den = sp.fraction(sp.cancel(sp.together(self.plant)))
        return self._plant_function([poly_coeffs(f, model.s)
                                     for f, _ in sp.factor_list(den, model.s)[1]])

    def _cancelled_decades(self, point, T):
        """Decades of ``|p T|`` and ``|p_i - p_j| T`` below 1 over the plant's poles ``p`` at ``point``."""
        poles = []
        with mpmath.workdps(PLANT_DIGITS):
            try:
                factors = self._plant_pole_factors(*point, T)
            except (ZeroDivisionError, TypeError, ValueError):
                return 0
            for factor in factors:
                c = [mpmath.mpmathify(x) for x in factor]
                if not all(mpmath.isfinite(x) for x in c):
                    return 0
                while c and c[0] == 0:
                    c.pop(0)
                if len(c) == 2:
                    poles.append(-c[1] / c[0])
                elif len(c) == 3:
                    a, b, k = c
                    root = mpmath.sqrt(b * b - 4 * a * k)
                    q = -(b + (root if b >= 0 else -root)) / 2 if b != 0 else root / 2
                    poles += [q / a, k / q] if q != 0 else [mpmath.mpf(0), mpmath.mpf(0)]
            T = mpmath.mpf(T)
            sizes = [abs(p) * T for p in poles]
            # An integrator's pole at 0 is exact: its distance to p is |p| again.
            poles = [p for p in poles if p != 0]
            sizes += [abs(a - b) * T for i, a in enumerate(poles) for b in poles[i + 1:]]
            total = sum(-mpmath.log10(x) for x in sizes if 0 < x < 1)
        return int(mpmath.ceil(total))

    @shared_property
    def _plant_fraction(self):
        """mpmath function of (plant values..., T): the plant's numerator and denominator in ``s``."""
        num, den = sp.fraction(sp.cancel(sp.together(self.plant)))
        return self._plant_function([poly_coeffs(num, model.s), poly_coeffs(den, model.s)])

    def plant_defect(self, plant_values, T):
        """Why the plant at these values is not a physical device's (one line), or None.

        A pole in the open right half plane (the plant alone would diverge),
        or a negative high-frequency gain (the leading coefficients of its
        numerator and denominator in ``s`` of opposite signs: a negative
        mass, say).  The poles are the roots of the denominator (NumPy); one
        counts as in the right half plane when its real part exceeds 1e-9 of
        its size (a pole on the imaginary axis, computed with rounding, does
        not).

        Parameters
        ----------
        plant_values : sequence of float
            The values of the plant's parameters, in the order of its names
            (sorted; ``T`` apart).
        T : float
            The sample period (the plant may use it).

        Returns
        -------
        str or None
        """
        with mpmath.workdps(PLANT_DIGITS):
            try:
                num, den = self._plant_fraction(*(mpmath.mpf(float(v)) for v in plant_values),
                                                mpmath.mpf(float(T)))
                num, den = ([float(mpmath.mpmathify(c)) for c in part] for part in (num, den))
            except (ZeroDivisionError, TypeError, ValueError, OverflowError):
                return None
        num, den = np.trim_zeros(num, "f"), np.trim_zeros(den, "f")
        if not len(num) or not len(den) or not np.all(np.isfinite(np.concatenate([num, den]))):
            return None
        problems = []
        with np.errstate(all="ignore"):
            try:
                poles = np.roots(den)
            except (ValueError, np.linalg.LinAlgError):
                # Coefficients whose ratios overflow (b = 1e308): the loop
                # itself says what is wrong with them; no warning is made up.
                poles = []
        unstable = [p for p in poles if p.real > 1e-9 * abs(p)]
        if unstable:
            p = max(unstable, key=lambda p: p.real)
            shown = f"{p.real:.4g}" if p.imag == 0 else f"{p.real:.4g} {'+-'} {abs(p.imag):.4g}j"
            problems.append(f"a pole in the open right half plane (s = {shown})")
        if num[0] * den[0] < 0:
            problems.append("a negative high-frequency gain (the leading coefficients of its "
                            "numerator and denominator in s have opposite signs)")
        if not problems:
            return None
        given = ", ".join(f"{n} = {float(v):g}"
                          for n, v in zip(self.plant_names, plant_values, strict=True))
        return (f"the plant G(s) = {self.plant} at {given} has {' and '.join(problems)}: not a "
                f"physical device's (a negative mass, friction or stiffness?); the results are "
                f"those of that plant")

    @method_cache(maxsize=4096, shared=True)
    def _plant_digits(self, plant_values, T, eps=None):
        """``(P_n, P_d, digits)``: the pulse transfer function's coefficients as mpmath numbers.

        At :data:`PLANT_DIGITS` digits, or more where the closed form needs
        them (:meth:`_closed_form_plant`); refused where it is not defined.
        (A plant that is not a physical device's at these values is warned
        of by :meth:`_numeric_plant` and :meth:`_exact_plant`, the entries.)
        With a fraction ``0 <= eps < 1`` of a period of delay (not None),
        ``(N_eps, z P_d)`` of the modified z-transform instead
        (:attr:`_fractional_plant_parts`, or :func:`numeric_fractional_zoh`):
        the loop's ``chi`` is then that plant's with the whole samples ``d``.
        """
        digits = PLANT_DIGITS
        fraction = eps
        with mpmath.workdps(PLANT_DIGITS):
            point = [mpmath.mpf(float(v)) for v in plant_values]
            if self._plant_parts is None:
                sub = {self.symbols[n]: sp.Float(float(v), PLANT_DIGITS)
                       for n, v in zip(self.plant_names, plant_values, strict=True)}
                num, den = sp.fraction(sp.together(self.plant.subs(sub)))
                num = [mpmath.mpf(sp.Float(c, PLANT_DIGITS)) for c in sp.Poly(num, model.s).all_coeffs()]
                den = [mpmath.mpf(sp.Float(c, PLANT_DIGITS)) for c in sp.Poly(den, model.s).all_coeffs()]
                if fraction is None:
                    p_n, p_d = numeric_zoh(num, den, mpmath.mpf(float(T)), dps=PLANT_DIGITS)
                else:
                    p_n, p_d = numeric_fractional_zoh(num, den, mpmath.mpf(float(T)), fraction,
                                                      dps=PLANT_DIGITS)
            elif fraction is not None and self._fractional_plant_parts is None:
                p_n, p_d = self._realised_plant(plant_values, T, fraction)
            else:
                p_n, p_d, digits = self._closed_form_plant(point, mpmath.mpf(float(T)), fraction)
                if not _defined(p_n, p_d):
                    # The closed form divides by a parameter at 0 (b = 0 in
                    # 1/(m s**2 + b s)) or poles meet: the realisation is its limit.
                    digits = PLANT_DIGITS
                    p_n, p_d = self._realised_plant(plant_values, T, fraction)
        with mpmath.workdps(digits):
            if not _defined(p_n, p_d):
                if self._plant_parts is not None:
                    self._check_distinct_poles(plant_values, T)   # says which poles meet
                given = ", ".join(f"{n} = {float(v):g}"
                                  for n, v in zip(self.plant_names, plant_values, strict=True))
                raise ValueError(f"the plant's pulse transfer function is not defined at "
                                 f"{given}, T = {float(T):g} (its leading coefficient in s "
                                 f"vanishes there, or a value is not finite)")
        return p_n, p_d, digits

    def _realised_plant(self, plant_values, T, eps=None):
        """P_n, P_d of the plant at ``plant_values`` by :func:`numeric_zoh` (its realisation).

        With a fraction ``eps`` of a period of delay, ``(N_eps, z P_d)`` by
        :func:`numeric_fractional_zoh` (and the closed form's lengths of those).

        From the plant as SymPy cancels it (:attr:`_plant_fraction`, the
        form the closed form is derived from), so a factor written on both
        sides changes nothing.  Where the closed form exists, ``P_n`` has
        its length (the realisation pads it with a leading zero).  The
        marker of an undefined plant where the order drops (``m = 0``):
        another plant, not this one's limit.
        """
        undefined = [mpmath.nan], [mpmath.mpf(0)]
        with mpmath.workdps(PLANT_DIGITS):
            num, den = self._plant_fraction(*(mpmath.mpf(float(v)) for v in plant_values),
                                            mpmath.mpf(float(T)))
            num, den = ([mpmath.mpmathify(c) for c in part] for part in (num, den))
            if not den or den[0] == 0 or not all(mpmath.isfinite(c) for c in num + den):
                return undefined
            while len(num) > 1 and num[0] == 0:
                num.pop(0)
            if eps is None:
                p_n, p_d = numeric_zoh(num, den, mpmath.mpf(float(T)), dps=PLANT_DIGITS)
            else:
                p_n, p_d = numeric_fractional_zoh(num, den, mpmath.mpf(float(T)), eps,
                                                  dps=PLANT_DIGITS)
            if self._plant_parts is not None:
                parts = self._plant_parts if eps is None else self._fractional_plant_parts
                if parts is None:
                    # The numeric path's own: n + 1 coefficients over z P_d's n + 2.
                    parts = (p_n[1:], p_d)
                length = len(parts[0])
                scale = max(abs(c) for c in p_n)
                while len(p_n) > length and abs(p_n[0]) <= mpmath.mpf(10) ** -PLANT_DIGITS * scale:
                    p_n = p_n[1:]
                p_n = [mpmath.mpf(0)] * (length - len(p_n)) + list(p_n)
                if len(p_n) != length or len(p_d) != len(parts[1]):
                    return undefined
            return list(p_n), list(p_d)

    def _exact_plant(self, plant_values, T, eps=None):
        """``(P_n, P_d)`` with monic ``P_d``, as exact Fractions of their 30-digit values.

        With a fraction ``eps`` of a period of delay, ``(N_eps, z P_d)``
        (:meth:`_plant_digits`).

        For the arc's brackets (:class:`symstab.numeric.engine.arcs.CramerArc`):
        rounded to doubles, the coefficients of a plant with a zero or a
        pole next to ``z = +-1`` lose what the arc needs there.
        """
        plant_values = tuple(plant_values)
        self._warn_if_not_physical(plant_values, T)
        p_n, p_d, digits = self._plant_digits(plant_values, T, None if eps is None else float(eps))
        with mpmath.workdps(digits):
            lead = p_d[0]
            return tuple(tuple(_fraction(c / lead) for c in part) for part in (p_n, p_d))

    @method_cache(maxsize=4096, shared=True)
    def _plant_cache(self, plant_values, T, eps=None):
        """(P_n, P_d, ends, P_d in z - 1) as float arrays, monic P_d, evaluated at 30 digits.

        ``ends`` is ``(P_n(1), P_d(1), P_n(-1), P_d(-1))``, summed at 30
        digits: a pole at z = 1 then gives ``P_d(1)`` of 1e-30, not of the
        coefficients' rounding, and the line z = 1 of a plane comes out
        where it is.  The last part is ``P_d(w + 1)``'s coefficients in
        ``w = z - 1`` (highest first), shifted at 30 digits: a pole
        ``exp(p T)`` near 1 gives a small coefficient with its own digits,
        which the root count needs next to ``z = 1``.  Where the closed form
        needed more digits (:meth:`_closed_form_plant`), all of this is done
        at those: a pole ``exp(-1e-30)`` keeps its ``1e-30`` after the shift.
        """
        p_n, p_d, digits = self._plant_digits(tuple(plant_values), T, eps)
        with mpmath.workdps(digits):
            lead = p_d[0]
            ends = [sum(c * sign**k for k, c in enumerate(reversed(part)))
                    for sign in (1, -1) for part in (p_n, p_d)]
            # A pole at z = 1 (an integrator) makes P_d(1) vanish, but the sum
            # keeps the 30-digit rounding of its terms (1e-30 of them: K =
            # 6e-25 N/m for the z = 1 line at T = 0.25 ms); an end within
            # 1000 ulps of its terms is that zero.
            ends = [mpmath.mpf(0) if abs(end) <= mpmath.mpf(10)**(3 - PLANT_DIGITS) * sum(abs(c) for c in part)
                    else end for end, part in zip(ends, (p_n, p_d, p_n, p_d), strict=True)]
            monic = [c / lead for c in p_d]
            near_one = list(shift_to_one(monic, dtype=object))
            return tuple(np.array(_real_floats(part)) for part in
                         ([c / lead for c in p_n], monic, [c / lead for c in ends], near_one))
