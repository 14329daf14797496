"""Generate the numeric kernels (NumPy and C99) from the derived expressions.

The expressions come from :mod:`symstab.codegen.float_forms` (proved equal to the
derivation); this module only prints them.  Following SymPy's code
generators, the layers are separate:

* :class:`Kernel` -- one entry point: its name, its argument list and its
  outputs as SymPy expressions.  Construction fails when an expression uses a
  symbol that is not an argument.
* :class:`NumPyKernelPrinter`, :class:`CKernelPrinter` -- print expressions,
  strictly: anything they cannot print raises.
* :func:`numpy_module`, :func:`c_source`, :func:`c_header` -- lay out a file
  (pure: they return strings); :func:`generated_files` collects them, and
  :func:`symstab.proof.derive.write` writes them.

Every kernel goes through ``cse()`` with temporaries named ``x0, x1, ...``.
The files carry no date or version, so they change only when the math or
the printers change, and ``symstab derive --check`` reports any drift.
"""

import dataclasses
import functools
import re
import textwrap

import sympy as sp
from sympy.printing.c import C99CodePrinter
from sympy.printing.numpy import NumPyPrinter

from ..symbolic import model
from . import float_forms as kf

__all__ = [
    "Kernel", "kernels", "NumPyKernelPrinter", "CKernelPrinter",
    "numpy_module", "c_source", "c_header", "generated_files",
    "COMMAND", "C_PREFIX", "OWNED", "one_line", "comment_text", "docstring_text",
    "python_function", "c_signature", "c_comment", "c_function", "c_argument_names",
    "C_ARGUMENT_PREFIX",
]

#: The command that regenerates the files, named in their headers.
COMMAND = "symstab derive"
#: Glob patterns of the files the generator owns in its folder (for drift).
OWNED = ("*.py", "*.c", "*.h")
#: Prefix of every C symbol.
C_PREFIX = "symstab_"


#: Put before an argument's name in C where the name itself cannot stand there.
C_ARGUMENT_PREFIX = "arg_"

#: Keywords of C (C89 to C23) and of C++ (the header is read by C++ too, in
#: ``extern "C"``), and the alternative spellings of <iso646.h>.
_C_WORDS = frozenset("""
    auto break case char const continue default do double else enum extern float for goto if
    inline int long register restrict return short signed sizeof static struct switch typedef
    union unsigned void volatile while alignas alignof bool constexpr false nullptr
    static_assert thread_local true typeof typeof_unqual entry fortran asm
    and and_eq bitand bitor catch char8_t char16_t char32_t class compl concept consteval
    constinit const_cast co_await co_return co_yield decltype delete dynamic_cast explicit
    export friend mutable namespace new noexcept not not_eq operator or or_eq private protected
    public reinterpret_cast requires static_cast template this throw try typeid typename using
    virtual wchar_t xor xor_eq
""".split())
#: The functions of <math.h> and <complex.h> (C99 to C23, POSIX and glibc),
#: without their float/long double suffixes; a ``c`` before one is a
#: <complex.h> function (or a name it reserves, ``cerf``, ``cexp2``).
#: glibc's obsolete ``gamma`` is left out: a parameter may be called gamma
#: (the paper's M_w / m), and no kernel calls that function (SymPy prints
#: the gamma function as ``tgamma``).
_MATH_FUNCTIONS = """
    acos asin atan atan2 cos sin tan acosh asinh atanh cosh sinh tanh exp exp2 expm1 frexp ilogb
    ldexp log log10 log1p log2 logb modf scalbn scalbln cbrt fabs abs hypot pow sqrt erf erfc
    lgamma tgamma ceil floor nearbyint rint lrint llrint round lround llround trunc fmod
    remainder remquo copysign nan nextafter nexttoward fdim fmax fmin fma acospi asinpi atanpi
    atan2pi cospi sinpi tanpi exp10 exp10m1 exp2m1 log10p1 logp1 log2p1 compoundn pown powr
    rootn rsqrt fromfp fromfpx ufromfp ufromfpx roundeven fmaximum fminimum fmaximum_mag
    fminimum_mag fmaximum_num fminimum_num fmaximum_mag_num fminimum_mag_num nextup nextdown
    canonicalize iscanonical issignaling issubnormal iszero isinf isnan isfinite isnormal
    signbit fpclassify isgreater isgreaterequal isless islessequal islessgreater isunordered
    iseqsig fadd fsub fmul fdiv ffma fsqrt dadd dsub dmul ddiv dfma dsqrt llogb quantum
    samequantum quantize encodedec decodedec encodebin decodebin totalorder totalordermag
    getpayload setpayload setpayloadsig j0 j1 jn y0 y1 yn drem finite significand scalb pow10
    sincos matherr lgamma_r carg cproj conj creal cimag
""".split()
_MATH_NAME = re.compile(
    r"c?(?:%s)(?:f|l|f\d+x?|d\d+)?" % "|".join(sorted(_MATH_FUNCTIONS, key=len, reverse=True)))
#: Macros, types and variables of <math.h> and <complex.h> (with POSIX's and
#: glibc's): ``M_PI``, ``HUGE_VAL``, ``FP_NAN``, ``I`` ...
_MATH_MACROS = frozenset("""
    HUGE HUGE_VAL HUGE_VALF HUGE_VALL INFINITY NAN SNAN MAXFLOAT math_errhandling float_t
    double_t long_double_t signgam complex imaginary I CMPLX CMPLXF CMPLXL DOMAIN SING OVERFLOW
    UNDERFLOW TLOSS PLOSS X_TLOSS exception
""".split())
_MATH_MACRO = re.compile(r"(?:M|FP|MATH|HUGE_VAL|SNAN|DEC|FLT|DBL|LDBL)_\w*|_\w*|symstab_\w*")


#: Names SymPy's C99 printer would print with a ``_`` after them.
_PRINTER_WORDS = frozenset(C99CodePrinter().reserved_words)


def _needs_c_prefix(name):
    """Whether ``name`` cannot be a C argument as it is (see :func:`c_argument_names`)."""
    return (name in _C_WORDS or name in _MATH_MACROS or name in _PRINTER_WORDS
            or _MATH_NAME.fullmatch(name) is not None or _MATH_MACRO.fullmatch(name) is not None)


def c_argument_names(kernel):
    """``{symbol: name}``: the name each argument of ``kernel`` has in C.

    A name that is a keyword of C (C89 to C23) or C++, a function, macro,
    type or constant of ``<math.h>`` or ``<complex.h>`` (``exp``, ``pow``,
    ``HUGE_VAL``, ``INFINITY``, ``NAN``, ``M_PI``, ``I``, ``complex``; with
    their ``f``/``l`` forms and POSIX's and glibc's additions), a reserved
    identifier (a leading ``_``; ``FP_``, ``MATH_``, ``M_`` ...) or a name
    of symstab's C symbols (``symstab_...``) is written
    :data:`C_ARGUMENT_PREFIX` + name (``arg_HUGE_VAL``), with the prefix
    repeated while that is another argument's name; every other name stays.
    A macro of that name would otherwise be expanded (a parameter
    ``HUGE_VAL`` compiled and read garbage), and a function would be hidden
    in the body that calls it.  The mapping depends only on the argument
    names, and :func:`c_comment` documents it.

    Parameters
    ----------
    kernel : Kernel

    Returns
    -------
    dict
    """
    names = [str(symbol) for symbol, _, _ in kernel.args]
    taken = set(names)
    out = {}
    for (symbol, _, _), name in zip(kernel.args, names, strict=True):
        if _needs_c_prefix(name):
            new = C_ARGUMENT_PREFIX + name
            while new in taken:
                new = C_ARGUMENT_PREFIX + new
            taken.add(new)
            name = new
        out[symbol] = name
    return out


@dataclasses.dataclass(frozen=True)
class Kernel:
    """One generated entry point.

    Attributes
    ----------
    name : str
        Function name (``symstab_`` is prepended in C).
    args : tuple of (sympy.Symbol, str, str)
        ``(symbol, C type, description)`` in call order; ``"int"`` marks the
        delay.
    outputs : tuple of (str, sympy.Expr, str)
        ``(name, expression, description)``.
    doc : str
        One paragraph for the generated docstring and comment.
    python_body, c_body : tuple of str
        Hand-written body lines, for a helper whose floating-point steps
        SymPy would simplify away (an error-free product); empty for a
        kernel printed from its outputs.  The outputs then state what the
        body computes.
    complex_arithmetic : bool
        C only: the temporaries are ``double complex`` (C99's
        ``<complex.h>``), printed by :class:`CComplexKernelPrinter`, and each
        output is the real part (:class:`RealPart`) of a complex expression:
        a plant whose poles are written with square roots that are
        imaginary for a complex pair.
    """

    name: str
    args: tuple
    outputs: tuple
    doc: str
    python_body: tuple = ()
    c_body: tuple = ()
    complex_arithmetic: bool = False

    def __post_init__(self):
        allowed = {symbol for symbol, _, _ in self.args}
        for out_name, expr, _ in self.outputs:
            extra = sp.sympify(expr).free_symbols - allowed
            if extra:
                names = ", ".join(sorted(str(s) for s in extra))
                raise ValueError(f"kernel {self.name}: output {out_name} uses {names}, "
                                 f"which are not arguments")

    def cse(self):
        """``(replacements, reduced)`` with temporaries x0, x1, ... in order."""
        exprs = [sp.sympify(expr) for _, expr, _ in self.outputs]
        return sp.cse(exprs, symbols=sp.numbered_symbols("x"))


_ARG = {
    "theta": (model.theta, "double", "angle on the unit circle, z = exp(j theta) (rad)"),
    "gamma": (model.gamma, "double", "gamma = M_w / m, virtual mass ratio"),
    "d": (model.d, "int", "loop delay in samples, d >= 0"),
    "delta": (model.delta, "double", "delta = b T / m >= 0"),
    "alpha": (model.alpha, "double", "alpha = K_w T^2 / m, dimensionless stiffness"),
    "beta": (model.beta, "double", "beta = B_w T / m, dimensionless damping"),
    "position": (kf.position, "double", "position x(k)"),
    "velocity": (kf.velocity, "double", "velocity times T, v(k) T"),
    "force": (kf.force, "double", "force held over the period times T^2 / m"),
    "x_k": (kf.position_history[0], "double", "sampled position x(k)"),
    "x_km1": (kf.position_history[1], "double", "sampled position x(k-1)"),
    "x_km2": (kf.position_history[2], "double", "sampled position x(k-2)"),
}


#: The integer multiple and the angle of the multiple-angle helpers.
_K, _X = sp.Symbol("k", integer=True), sp.Symbol("x", real=True)

#: NumPy has no fused multiply-add: the error-free product of the
#: multiple-angle helpers is Dekker's, with Veltkamp's splits.
_EXACT_PRODUCT = '''def _exact_product(k, x):
    """k x = hi + lo exactly (Dekker's product; Veltkamp's split in halves of 26 bits)."""
    hi = k*x
    c = 134217729.0*k
    k_hi = c - (c - k)
    k_lo = k - k_hi
    c = 134217729.0*x
    x_hi = c - (c - x)
    x_lo = x - x_hi
    return hi, ((k_hi*x_hi - hi) + k_hi*x_lo + k_lo*x_hi) + k_lo*x_lo'''


def _multiple_angle_kernel(function):
    """The generated helper of a :class:`~symstab.codegen.float_forms.MultipleAngle` function."""
    name = function.__name__
    f = function.function.__name__
    derivative = {"sin": ("+", "cos"), "cos": ("-", "sin")}[f]
    return Kernel(
        name, ((_K, "int", "the integer multiple"), (_X, "double", "the angle (rad)")),
        ((name, function.function(_K * _X), f"{f}(k x)"),),
        f"{f}(k x) for an integer k, with the product k x carried exactly as hi + lo, so the "
        f"value keeps its relative accuracy where k x is large and {f}(k x) small; {f}(hi + lo) "
        f"= {f}(hi) {derivative[0]} lo {derivative[1]}(hi) to within lo^2.",
        python_body=("hi, lo = _exact_product(k, x)",
                     f"return numpy.{f}(hi) {derivative[0]} lo*numpy.{derivative[1]}(hi)"),
        c_body=("const double hi = k * x;",
                "const double lo = fma((double)k, x, -hi);",
                f"return {f}(hi) {derivative[0]} lo * {derivative[1]}(hi);"))


@functools.lru_cache(maxsize=None)
def kernels():
    """Return the kernels, in file order."""
    x = model.delta
    alpha, beta = kf.boundary_forms()
    delayed, direct = kf.loop_coefficient_forms()
    Phi, Gamma_u = kf.plant_step_forms()
    state = sp.Matrix([kf.position, kf.velocity])
    step_x, step_v = Phi * state + Gamma_u * kf.force
    names = ["z^(d+4)", "z^(d+3)", "z^(d+2)", "z^3", "z^2", "z^1", "z^0"]
    coefficient_outputs = tuple(
        (f"c{k}", kf.as_evaluable(expr), f"coefficient of {name}")
        for k, (expr, name) in enumerate(zip(delayed + direct, names, strict=True)))
    return (
        *(Kernel(f.__name__, (_ARG["delta"],),
                 ((f.__name__, f.evaluation(x), f.formula),),
                 f"{f.formula}: {f.__doc__[0].lower()}{f.__doc__[1:].rstrip('.')}, for delta >= 0; a Taylor "
                 f"polynomial below delta = {f.switch}, exp(-delta) and expm1(-delta) above.")
          for f in kf.SERIES_FUNCTIONS),
        *(_multiple_angle_kernel(f) for f in kf.MULTIPLE_ANGLE_FUNCTIONS),
        Kernel("boundary", tuple(_ARG[k] for k in ("theta", "gamma", "d", "delta")),
               (("alpha", kf.as_evaluable(alpha), "dimensionless stiffness on the boundary"),
                ("beta", kf.as_evaluable(beta), "dimensionless damping on the boundary")),
               "The stability boundary alpha(theta), beta(theta): the (alpha, beta) at which "
               "z = exp(j theta) is a root of the characteristic polynomial."),
        Kernel("loop_coefficients", tuple(_ARG[k] for k in ("alpha", "beta", "gamma", "delta")),
               coefficient_outputs,
               "Coefficients of chi(z) / (delta^2 Gamma) = z^(d+2) (z-1) (z - exp(-delta)) "
               "+ V(z) (b1 z + b0), "
               "highest power first: three of the delayed part (z^(d+4), z^(d+3), z^(d+2)) "
               "and four of the direct part (z^3 .. z^0)."),
        Kernel("plant_step_coefficients", (_ARG["delta"],),
               (("phi01", kf.as_evaluable(Phi[0, 1]), "Phi[0,1]: position gained per unit v T"),
                ("phi11", kf.as_evaluable(Phi[1, 1]), "Phi[1,1] = exp(-delta): velocity kept"),
                ("gamma0", kf.as_evaluable(Gamma_u[0]), "Gamma_u[0]: position gained per unit force"),
                ("gamma1", kf.as_evaluable(Gamma_u[1]), "Gamma_u[1]: v T gained per unit force")),
               "The exact one-period plant step (x, v T)(k+1) = Phi (x, v T)(k) + Gamma_u "
               "f(k) T^2/m under a held force; Phi[0,0] = 1 and Phi[1,0] = 0."),
        Kernel("plant_step", tuple(_ARG[k] for k in ("position", "velocity", "force", "delta")),
               (("position_next", kf.as_evaluable(step_x), "position x(k+1)"),
                ("velocity_next", kf.as_evaluable(step_v), "v(k+1) T")),
               "One period of the device m x'' + b x' = f under a force held constant "
               "(zero-order hold), exactly, in Table I's units."),
        Kernel("environment_force", tuple(_ARG[k] for k in ("x_k", "x_km1", "x_km2",
                                                             "alpha", "beta", "gamma")),
               (("force", kf.environment_force_form(), "force f(k) T^2 / m"),),
               "The virtual environment's force of eq. (1) on the sampled positions: "
               "-(alpha x(k) + beta (x(k) - x(k-1)) + gamma (x(k) - 2 x(k-1) + x(k-2))), "
               "in units of m / T^2."),
    )


class NumPyKernelPrinter(NumPyPrinter):
    """NumPy printer for the kernels.

    The series and multiple-angle functions of :mod:`symstab.codegen.float_forms`
    print as calls of their generated helpers.
    """

    def __init__(self, settings=None):
        super().__init__(dict({"strict": True}, **(settings or {})))

    def _print_Function(self, expr):
        # SymPy's printers skip subclass names of a Function's bases, so the
        # series functions are recognised here rather than by _print_<name>.
        if isinstance(expr, (kf.SeriesFunction, kf.MultipleAngle)):
            return f"{type(expr).__name__}({', '.join(self._print(a) for a in expr.args)})"
        return super()._print_Function(expr)

    def _print_Max(self, expr):
        args = [self._print(a) for a in expr.args]
        out = args[0]
        for a in args[1:]:
            out = f"numpy.maximum({out}, {a})"
        return out

    def _print_Piecewise(self, expr):
        if expr.args[-1].cond is not sp.true:
            raise NotImplementedError("a Piecewise needs a final True branch")
        out = self._print(expr.args[-1].expr)
        for e, c in reversed(expr.args[:-1]):
            out = f"numpy.where({self._print(c)}, {self._print(e)}, {out})"
        return out


class CKernelPrinter(C99CodePrinter):
    """C99 printer for the kernels: series and multiple-angle functions call their generated helpers."""

    def __init__(self, settings=None):
        super().__init__(dict({"strict": True}, **(settings or {})))

    def _print_Function(self, expr):
        if isinstance(expr, (kf.SeriesFunction, kf.MultipleAngle)):
            return f"{C_PREFIX}{type(expr).__name__}({', '.join(self._print(a) for a in expr.args)})"
        return super()._print_Function(expr)


class RealPart(sp.Function):
    """The real part of a complex C99 expression, left unevaluated (printed ``creal``).

    SymPy's ``re`` would try to split a large expression of unknown sign
    into real and imaginary parts symbolically; the C kernel only needs the
    real part of the number it computes.
    """

    nargs = 1


class CComplexKernelPrinter(CKernelPrinter):
    """C99 printer in complex arithmetic: ``cexp``, ``csqrt``, ``cpow``, ``creal``.

    For the kernels with ``complex_arithmetic``: a square root of a negative
    number is the imaginary one (``csqrt``), and the exponentials of complex
    arguments are C99's ``cexp``.  Any other function is refused (its real
    C version would be wrong for a complex argument).
    """

    def _print_exp(self, expr):
        return f"cexp({self._print(expr.args[0])})"

    def _print_Pow(self, expr):
        base = self._print(expr.base)
        if expr.exp == sp.Rational(1, 2):
            return f"csqrt({base})"
        if expr.exp == -sp.Rational(1, 2):
            return f"1.0/csqrt({base})"
        if expr.exp == -1:
            return f"1.0/({base})"
        return f"cpow({base}, {self._print(expr.exp)})"

    def _print_Function(self, expr):
        if isinstance(expr, RealPart):
            return f"creal({self._print(expr.args[0])})"
        raise NotImplementedError(f"{type(expr).__name__} has no complex C99 kernel here")


def one_line(text):
    """``text`` on one line of printable characters: every other character escaped.

    A line break, a control or a formatting character becomes its Python
    escape (``\\n``, ``\\x1b``, ``\\u202e``), so text from a loop file can
    neither end a comment nor hide what follows it.

    Parameters
    ----------
    text : str

    Returns
    -------
    str
    """
    return "".join(c if c.isprintable() else c.encode("unicode_escape").decode("ascii")
                   for c in str(text))


def comment_text(text, language):
    """``text`` made safe inside a comment of ``language``: one line that cannot end it.

    Parameters
    ----------
    text : str
    language : {"python", "c", "latex"}
        ``"python"``: a ``#`` comment (:func:`one_line`).  ``"c"``: a ``//``
        line or a ``/* */`` block: also ``*/`` is broken up, a backslash
        (which would join the next line to a ``//`` comment) is written
        ``\\x5c`` and ``??`` (a trigraph's start) ``? ?``.  ``"latex"``: a
        ``%`` comment (:func:`one_line`).

    Returns
    -------
    str

    Raises
    ------
    ValueError
        For another language.
    """
    line = one_line(text)
    if language == "c":
        return line.replace("\\", "\\x5c").replace("*/", "* /").replace("??", "? ?")
    if language in ("python", "latex"):
        return line
    raise ValueError(f"language must be 'python', 'c' or 'latex', got {language!r}")


def docstring_text(text):
    """``text`` safe inside a triple-quoted Python docstring (backslashes and quotes escaped).

    Parameters
    ----------
    text : str

    Returns
    -------
    str
    """
    return one_line(text).replace("\\", "\\\\").replace('"', '\\"')


def _header_lines(comment, what):
    return [f"{comment} Generated by `{COMMAND}` from symstab.codegen.float_forms; do not edit.",
            f"{comment} {what}",
            f"{comment} Every expression is proved equal to the derivation by `{COMMAND}`"
            " (step 07_proofs),",
            f"{comment} except the Taylor branches of {', '.join(f.__name__ for f in kf.SERIES_FUNCTIONS)},",
            f"{comment} approximations exact to the last bit below their switch, and the error-free",
            f"{comment} products of {', '.join(f.__name__ for f in kf.MULTIPLE_ANGLE_FUNCTIONS)}.", ""]


def python_function(kernel, printer):
    """The text of one NumPy kernel: a ``def`` with a numpydoc docstring and the CSE'd body.

    Parameters
    ----------
    kernel : Kernel
    printer : NumPyKernelPrinter
        Prints each expression (the paper's or a loop file's kernel module).
    """
    replacements, reduced = kernel.cse()
    args = [str(symbol) for symbol, _, _ in kernel.args]
    doc = textwrap.wrap(docstring_text(kernel.doc), 72, break_long_words=False)
    lines = [f"def {kernel.name}({', '.join(args)}):", f'    """{doc[0]}']
    lines += [f"    {line}" for line in doc[1:]]
    lines += ["", "    Parameters", "    ----------"]
    for symbol, ctype, description in kernel.args:
        kind = "int" if ctype == "int" else "float or ndarray"
        lines += [f"    {symbol} : {kind}", f"        {docstring_text(description)}"]
    lines += ["", "    Returns", "    -------"]
    for name, _, description in kernel.outputs:
        lines += [f"    {name} : float or ndarray", f"        {docstring_text(description)}"]
    lines.append('    """')
    if kernel.python_body:
        return "\n".join(lines + [f"    {line}" for line in kernel.python_body])
    for symbol, expr in replacements:
        lines.append(f"    {symbol} = {printer.doprint(expr)}")
    results = [printer.doprint(expr) for expr in reduced]
    if len(results) == 1:
        lines.append(f"    return {results[0]}")
    else:
        lines.append("    return (")
        lines += [f"        {r}," for r in results]
        lines.append("    )")
    return "\n".join(lines)


def numpy_module():
    """Return the text of ``symstab/_generated/kernels.py``."""
    printer = NumPyKernelPrinter()
    names = [k.name for k in kernels()]
    parts = ["\n".join(_header_lines("#", "NumPy kernels, vectorised over theta, gamma, delta, "
                                          "alpha, beta (arrays broadcast); d is an int.")),
             '"""Generated NumPy kernels of symstab (see symstab.codegen.generator)."""', "",
             "import numpy", "",
             f"__all__ = {names!r}", "", "", _EXACT_PRODUCT, ""]
    for kernel in kernels():
        parts += ["", python_function(kernel, printer), ""]
    return "\n".join(parts).rstrip("\n") + "\n"


def c_signature(kernel):
    """The C prototype of ``kernel``, without ``;``: returns a double, or writes its outputs.

    Parameters
    ----------
    kernel : Kernel
    """
    names = c_argument_names(kernel)
    params = [f"{ctype} {names[symbol]}" for symbol, ctype, _ in kernel.args]
    if len(kernel.outputs) == 1:
        return f"double {C_PREFIX}{kernel.name}({', '.join(params)})"
    params += [f"double *{name}" for name, _, _ in kernel.outputs]
    return f"void {C_PREFIX}{kernel.name}({', '.join(params)})"


def c_comment(kernel):
    """The ``/* ... */`` comment above a C kernel: what it computes, each argument and output.

    Parameters
    ----------
    kernel : Kernel
    """
    doc = textwrap.wrap(comment_text(kernel.doc, "c"), 72, break_long_words=False)
    lines = ["/*"] + [f" * {line}" for line in doc] + [" *"]
    names = c_argument_names(kernel)
    for symbol, _, description in kernel.args:
        renamed = ("" if names[symbol] == str(symbol) else
                   f" (the argument {symbol}, renamed in C: a C keyword, a name of <math.h> or "
                   f"<complex.h>, or a reserved one)")
        lines.append(f" * {names[symbol]}: {comment_text(description, 'c')}{renamed}")
    for name, _, description in kernel.outputs:
        role = "returns" if len(kernel.outputs) == 1 else f"*{name}"
        lines.append(f" * {role}: {comment_text(description, 'c')}")
    lines.append(" */")
    return "\n".join(lines)


def c_function(kernel, printer):
    """The text of one C kernel: its comment, its signature and the CSE'd body.

    Parameters
    ----------
    kernel : Kernel
    printer : CKernelPrinter
    """
    replacements, reduced = kernel.cse()
    # Each argument printed under its C name (the same Symbol class, so the
    # printers see what they saw; integer-ness is kept for the delay).
    names = c_argument_names(kernel)
    rename = {symbol: sp.Symbol(names[symbol], **symbol.assumptions0)
              for symbol in names if isinstance(symbol, sp.Symbol) and names[symbol] != str(symbol)}
    if rename:
        replacements = [(t, sp.sympify(e).xreplace(rename)) for t, e in replacements]
        reduced = [sp.sympify(e).xreplace(rename) for e in reduced]
    if kernel.complex_arithmetic:
        printer = CComplexKernelPrinter()
    lines = [c_comment(kernel), c_signature(kernel), "{"]
    if kernel.c_body:
        return "\n".join(lines + [f"    {line}" for line in kernel.c_body] + ["}"])
    # An argument the kernel does not use (a slope kernel shares its
    # environment's signature) is cast to void: the C compiles warning-free
    # under -Wextra, whose -Wunused-parameter would flag it.
    used = set().union(*(e.free_symbols for _, e in replacements), *(e.free_symbols
                                                                      for e in reduced))
    lines += [f"    (void){names[symbol]};" for symbol, _, _ in kernel.args
              if isinstance(symbol, sp.Symbol) and rename.get(symbol, symbol) not in used]
    for symbol, expr in replacements:
        # An integer temporary (d + 1) stays an int: it is passed as one.
        ctype = "int" if expr.is_integer else ("double complex" if kernel.complex_arithmetic
                                               else "double")
        lines.append(f"    const {ctype} {symbol} = {printer.doprint(expr)};")
    if len(reduced) == 1:
        lines.append(f"    return {printer.doprint(reduced[0])};")
    else:
        for (name, _, _), expr in zip(kernel.outputs, reduced, strict=True):
            lines.append(f"    *{name} = {printer.doprint(expr)};")
    lines.append("}")
    return "\n".join(lines)


def c_header():
    """Return the text of ``symstab/_generated/symstab_kernels.h``."""
    guard = "SYMSTAB_KERNELS_H"
    lines = _header_lines("//", "C99 kernels; they need only <math.h> (link with -lm).")
    lines += [f"#ifndef {guard}", f"#define {guard}", "", "#ifdef __cplusplus",
              'extern "C" {', "#endif", ""]
    for kernel in kernels():
        lines += [c_comment(kernel), c_signature(kernel) + ";", ""]
    lines += ["#ifdef __cplusplus", "}", "#endif", "", f"#endif /* {guard} */"]
    return "\n".join(lines) + "\n"


def c_source():
    """Return the text of ``symstab/_generated/symstab_kernels.c``."""
    printer = CKernelPrinter()
    lines = _header_lines("//", "C99 kernels; they need only <math.h> (link with -lm).")
    lines += ['#include <math.h>', '#include "symstab_kernels.h"', ""]
    for kernel in kernels():
        lines += [c_function(kernel, printer), ""]
    return "\n".join(lines).rstrip("\n") + "\n"


def generated_files():
    """Return ``{filename: text}`` for ``symstab/_generated/``."""
    init = "\n".join(_header_lines("#", "The generated code of symstab; it imports nothing from symstab.")
                     + ['"""Code generated by `symstab derive`; see symstab.codegen.generator."""', ""])
    return {
        "__init__.py": init,
        "kernels.py": numpy_module(),
        "symstab_kernels.c": c_source(),
        "symstab_kernels.h": c_header(),
    }
