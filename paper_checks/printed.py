"""The paper's numbered equations (1)-(70), transcribed exactly as printed.

Source: Mashayekhi, Shakeri, Khorasani and Verstraten, "Effect of Virtual Mass
and Time Delay on the Stability of Haptic Rendering", IEEE Trans. Haptics
2025, as extracted to ``/work/shared/paper/000_6344edfcd45519c7.txt``.

This module is a transcription, not a derivation.  Each entry holds the LaTeX
string as it stands in the paper file, the 1-based line numbers of that file
where it stands, and a SymPy expression that says the same thing.  Nothing is
corrected: a printed typo is kept as printed, so that an audit comparing these
expressions with :mod:`symstab` finds it.  Nothing here is compared with
anything.

Conventions
-----------
* ``LHS = RHS`` defining a quantity: ``expr`` is the RHS.
* ``... = 0``: ``expr`` is the left-hand side.
* An identity whose left side is not a bare name (e.g. (54), (57)): ``expr``
  is an unevaluated :class:`sympy.Eq`.
* A chain ``X = F1 = F2`` printed in two forms (e.g. (37)-(42)): one entry per
  form, ids ``eqN.lhs`` (first printed form) and ``eqN.rhs`` (second form).
* Multi-part equations: one entry per part, ``eqN.part``.
* The coefficients ``C_1 ... C_11`` stay plain symbols ``C1 ... C11`` wherever
  the paper writes them by name ((7), (11), (36), (48), (66), (69)); their
  printed definitions (20)-(34) are in :data:`PRINTED_COEFFICIENTS` and the
  printed d = 0 forms (37)-(41) in :data:`PRINTED_D0_COEFFICIENTS`.
* The shorthands s_h, sh = sin(theta/2), c_h, ch = cos(theta/2),
  c = cos(theta) and s = sin(theta) of (13), (35) and (50), and the named
  quantities K_1 ... K_4, A, u, A_S, A_D, B, are replaced by their printed
  definitions, so expressions are in ``theta`` and the parameters.
* Symbols the paper uses but never defines stay free: :data:`xi`,
  :data:`eta`, :data:`Delta` and the placeholder :data:`const`.

``kind`` says what the paper claims: ``definition`` (introduces a name),
``closed_form`` (a result in closed form), ``identity`` (an exact equality
between printed forms), ``approximation`` (an approximate equality),
``limit`` (a limiting value) or ``not_checkable`` (a setting, not a claim).
"""

import dataclasses

import sympy as sp

from symstab.symbolic.model import (
    B_w,
    Gamma,
    K_w,
    M_w,
    T,
    alpha,
    b,
    beta,
    d,
    delta,
    gamma,
    m,
    s,
    theta,
    z,
)

__all__ = [
    "Printed", "KINDS", "PRINTED", "PRINTED_COEFFICIENTS",
    "PRINTED_D0_COEFFICIENTS", "printed", "SECTIONS", "section_of",
    "C", "u", "k", "xi", "eta", "Delta", "const",
]

#: The paper's parts as a reader names them, by the first line of the paper
#: file in which each stands (its heading).  Line numbers are provenance
#: only: the report names the part (:func:`section_of`), never the line,
#: since its readers have the paper, not this text file.
SECTIONS = (
    (1, "Abstract"),
    (11, "Sec. I"),
    (57, "Sec. II"),
    (145, "Sec. III"),
    (157, "Sec. IV"),
    (192, "Sec. IV-A"),
    (215, "Sec. IV-B"),
    (237, "Sec. IV-C"),
    (258, "Sec. V"),
    (343, "Sec. VI"),
    (435, "Sec. VII"),
    (500, "Sec. VIII"),
    (529, "Appendix"),
    (531, "Appendix A"),
    (541, "Appendix B"),
    (577, "Appendix C"),
    (637, "Appendix D"),
    (723, "Appendix E"),
    (776, "References"),
)


def section_of(line):
    """The part of the paper (``"Sec. IV-A"``, ``"Appendix C"``, ...) holding a line of its file.

    Parameters
    ----------
    line : int
        A 1-based line of the paper file, ``line >= 1``.

    Returns
    -------
    str
        The name of the section (or subsection) that line belongs to.

    Raises
    ------
    TypeError
        If ``line`` is not an integer.
    ValueError
        If ``line < 1``.

    Examples
    --------
    >>> section_of(175), section_of(545)
    ('Sec. IV', 'Appendix B')
    """
    if isinstance(line, bool) or not isinstance(line, int):
        raise TypeError(f"line must be an integer, got {type(line).__name__}")
    if line < 1:
        raise ValueError(f"line must be >= 1, got {line}")
    return [name for first, name in SECTIONS if first <= line][-1]


#: Allowed values of :attr:`Printed.kind`.
KINDS = (
    "definition", "closed_form", "identity", "approximation", "limit",
    "not_checkable",
)

#: The coefficients C_1 ... C_11 as plain symbols; ``C[0]`` is C_1.
C = sp.symbols("C1:12")
C1, C2, C3, C4, C5, C6, C7, C8, C9, C10, C11 = C

#: u of (9) and (42), kept as a symbol only where (45) treats it as unknown.
u = sp.Symbol("u", real=True)
#: The integer index k of (55).
k = sp.Symbol("k", integer=True)
#: xi of (60) and (65); never defined in the paper.
xi = sp.Symbol("xi")
#: eta of (65) and (67); never defined in the paper (it is not the Newton
#: step theta - theta_0 also called eta in the text of Appendix D).
eta = sp.Symbol("eta")
#: Delta of (65) and (67); never defined in the paper (it is not the
#: characteristic equation Delta of (2) and (5)).
Delta = sp.Symbol("Delta")
#: The "(const)" placeholder of (65); each occurrence may stand for a
#: different number.
const = sp.Symbol("const")


@dataclasses.dataclass(frozen=True)
class Printed:
    """One printed equation, or one part of a multi-part equation.

    Parameters
    ----------
    id : str
        ``eqN`` or ``eqN.part``.
    equation : int
        The paper's equation number N.
    lines : tuple of int
        First and last 1-based line of the paper file holding the equation.
    text : str
        The LaTeX of the equation as it stands in the paper file (the whole
        equation, also for entries that hold one part of it).
    expr : sympy.Basic
        The printed statement as a SymPy object (see the module docstring).
    kind : str
        One of :data:`KINDS`.
    note : str, optional
        How the printed text was read, and symbols left undefined.

    Raises
    ------
    ValueError
        If ``kind`` is not one of :data:`KINDS` or ``lines`` is not an
        increasing pair of positive integers.
    """

    id: str
    equation: int
    lines: tuple[int, int]
    text: str
    expr: sp.Basic
    kind: str
    note: str = ""

    def __post_init__(self):
        if self.kind not in KINDS:
            raise ValueError(
                f"kind of {self.id} must be one of {KINDS}, got {self.kind!r}")
        first, last = self.lines
        if not 0 < first <= last:
            raise ValueError(
                f"lines of {self.id} must satisfy 0 < first <= last, "
                f"got {self.lines}")


# The paper's shorthands (13), (35), (50): s_h, c_h, c, s.
_sh = sp.sin(theta / 2)
_ch = sp.cos(theta / 2)
_c = sp.cos(theta)
_sn = sp.sin(theta)

# ---------------------------------------------------------------------------
# Section III-IV: model and characteristic equation, (1)-(6).

_VE_1 = K_w + B_w * (z - 1) / (T * z) + M_w * (z - 1) ** 2 / (T**2 * z**2)
_ZOH_G_3 = (1 - sp.exp(-T * s)) / s * 1 / (m * s**2 + b * s)
_e4 = sp.exp(-b * T / m)
_Z_ZOH_G_4 = (((_e4 - 1 + b * T / m) * z + 1 - (1 + b * T / m) * _e4)
              / ((z - 1) * b**2 / m * (z - _e4)))
_DELTA_2 = 1 + _VE_1 * z ** (-d) * _Z_ZOH_G_4
_DELTA_5 = (
    Gamma * delta**2 * z ** (d + 4) - (1 + Gamma) * delta**2 * z ** (d + 3)
    + delta**2 * z ** (d + 2)
    + (alpha * (1 + Gamma * (delta - 1)) + beta * delta * Gamma
       + gamma * (1 - Gamma * (1 + delta)) + delta * (1 - Gamma)) * z**3
    - (alpha * (1 + delta - Gamma * (1 - 2 * gamma))
       + beta * (Gamma * (gamma - 2) + delta)
       + gamma * (3 * (1 - Gamma) + delta) + 2 * delta) * z**2
    + (alpha * gamma * Gamma + beta * (gamma - Gamma)
       + gamma * (3 * (1 - Gamma) + 2 * delta) + delta) * z
    - gamma * (1 - Gamma + delta)
)

# ---------------------------------------------------------------------------
# The boundary (7), its special cases (11), (14) and theta_max (8)-(15).

_DEN_7 = C6 + delta**2 * C7 + delta * C8
_ALPHA_7 = (gamma * C1 + gamma * delta**2 * C2 + gamma * delta * C3
            + delta**3 * C4 + delta**2 * C5) / _DEN_7
_BETA_7 = (-gamma * C1 - gamma * delta**2 * C2 + gamma * delta * C3
           + delta**3 * C4 + delta**2 * C5) / _DEN_7

_A_10 = (gamma * ((1 - Gamma) ** 2 - delta * (Gamma**2 - 1) + Gamma * delta**2)
         + Gamma * delta**2 * (1 - Gamma + delta))
_U_9 = -(1 - Gamma) ** 2 * delta**2 * (gamma + 1 + delta) / (2 * _A_10)
_THETA_MAX_8 = 2 * sp.atan(sp.sqrt(_U_9 / (2 - _U_9)))

_ALPHA_11 = (delta**3 * C4 + delta**2 * C5) / _DEN_7
_BETA_11 = (delta**3 * C10 + delta**2 * C11) / _DEN_7

_THETA0_13 = sp.pi / (2 * (d + 1))
_A_S_13 = (2 * delta * (Gamma**2 + 1 - (Gamma + 1) ** 2 * _c + 2 * Gamma * _c**2)
           - 4 * _sh**2 * (Gamma - 1) * (1 + Gamma - 2 * Gamma * _c))
_A_D_13 = -4 * _sh**2 * (Gamma - 1) ** 2


def _at_theta0(expr, theta0):
    return expr.subs(theta, theta0)


_THETA_MAX_12 = _THETA0_13 - (
    (_at_theta0(_A_S_13, _THETA0_13)
     + _at_theta0(_A_D_13, _THETA0_13) * sp.cos(_THETA0_13))
    / (_at_theta0(sp.diff(_A_S_13, theta), _THETA0_13)
       + _at_theta0(sp.diff(_A_D_13, theta), _THETA0_13) * sp.cos(_THETA0_13)
       + d * _at_theta0(_A_D_13, _THETA0_13) * sp.sin(_THETA0_13)))

_K3_14 = Gamma**2 - 2 * sp.cos(theta) * Gamma + 1
_ALPHA_14 = (
    delta * sp.sin(theta / 2) ** 2
    * (delta**2 * _K3_14
       - delta * (Gamma - 1) * (Gamma - 2 * sp.cos(theta) * Gamma + 1))
    / (sp.Rational(1, 4) * delta**2 * _K3_14
       - delta * sp.sin(theta / 2) ** 2 * (Gamma**2 - 1)
       + sp.sin(theta / 2) ** 2 * (Gamma - 1) ** 2))
_BETA_14 = (
    (-delta**3 * _K3_14 + 4 * delta**2 * sp.sin(theta / 2) ** 2 * Gamma * (Gamma - 1))
    / (delta**2 * _K3_14 - 4 * delta * sp.sin(theta / 2) ** 2 * (Gamma**2 - 1)
       + 4 * sp.sin(theta / 2) ** 2 * (Gamma - 1) ** 2))
_THETA_MAX_15 = 2 * sp.atan(sp.sqrt(
    (Gamma - 1) ** 2 * (1 + delta)
    / (4 * Gamma * (Gamma - 1 - delta) - (Gamma - 1) ** 2 * (1 + delta))))

# ---------------------------------------------------------------------------
# Appendix A: real and imaginary parts (18), (19).


def _unit_circle_part(f):
    return (
        -delta**2 * (1 + Gamma) * f(theta * (d + 3))
        + delta**2 * f(theta * (d + 2)) + delta**2 * Gamma * f(theta * (d + 4))
        + (((-beta - 2 * alpha + 3) * gamma + 2 * beta + alpha) * Gamma
           + (-beta - alpha - gamma - 2) * delta - alpha - 3 * gamma) * f(2 * theta)
        + (((beta + alpha - gamma - 1) * delta - alpha - gamma) * Gamma
           + alpha + delta + gamma) * f(3 * theta)
    )


_REAL_18 = (
    _unit_circle_part(sp.cos)
    + (((alpha - 3) * gamma - beta) * Gamma + (2 * gamma + 1) * delta
       + gamma * (beta + 3)) * sp.cos(theta)
    + gamma * (Gamma - delta - 1)
)
_IMAG_19 = (
    _unit_circle_part(sp.sin)
    - sp.sin(theta) * (((-alpha + 3) * gamma + beta) * Gamma
                       + (-2 * gamma - 1) * delta - gamma * (beta + 3))
)

# ---------------------------------------------------------------------------
# Appendix B: K_1 ... K_4 (20)-(23) and C_1 ... C_11 (24)-(34).

_K1 = 32 * sp.sin(theta / 2) ** 5 * sp.cos(theta / 2)
_K2 = (1 - Gamma) ** 2
_K3 = 1 + Gamma**2 - 2 * Gamma * sp.cos(theta)
_K4 = 1 + Gamma + Gamma**2

#: The printed C_1 ... C_11 of (24)-(34), with K_1 ... K_4 of (20)-(23)
#: substituted, and K_1 ... K_4 themselves.  Keys "C1" ... "C11", "K1" ... "K4".
PRINTED_COEFFICIENTS = {
    "K1": _K1,
    "K2": _K2,
    "K3": _K3,
    "K4": _K4,
    "C1": _K1 * _K2,
    "C2": -2 * _K3 * sp.sin(theta) * (sp.cos(theta) - 1),
    "C3": -16 * sp.sin(theta / 2) ** 4 * sp.sin(theta) * (Gamma**2 - 1),
    "C4": (_K4 * (2 * sp.sin(theta * (d + 1)) - sp.sin(d * theta)
                  - sp.sin(theta * (d + 2)))
           - 4 * Gamma * sp.sin(theta * (d + 1)) * sp.sin(theta / 2)
           * sp.sin(3 * theta / 2)),
    "C5": (-8 * sp.sin(theta / 2) ** 3 * (Gamma - 1)
           * (sp.cos(theta * (2 * d + 1) / 2)
              - Gamma * sp.cos(theta * (2 * d + 3) / 2))),
    "C6": -2 * _K2 * sp.sin(theta) * (sp.cos(theta) - 1),
    "C7": _K3 * sp.sin(theta),
    "C8": sp.sin(theta) * (2 * (Gamma**2 - 1)) * (sp.cos(theta) - 1),
    "C9": _K1 * (Gamma**2 - 1),
    "C10": (-2 * sp.cos(theta * (2 * d + 1) / 2)
            * (_K4 * sp.sin(theta / 2) - Gamma * sp.sin(3 * theta / 2))),
    "C11": (4 * sp.sin(theta / 2) ** 2
            * (Gamma**2 * sp.sin(theta + d * theta) + sp.sin(d * theta))
            - 4 * Gamma * sp.sin(theta / 2) * sp.sin(theta / 2 + d * theta)
            * sp.sin(theta)),
}

# ---------------------------------------------------------------------------
# Appendix C: d = 0, (35)-(47).

_PHI_36 = (gamma * C1 + gamma * delta**2 * C2 + gamma * delta * C3
           + delta**3 * C4 + delta**2 * C5)

#: The printed d = 0 forms (37)-(41): ``{"C1": {"lhs": ..., "rhs": ...}}``,
#: "lhs" the first printed form and "rhs" the second, K's substituted.
PRINTED_D0_COEFFICIENTS = {
    "C1": {"lhs": _K2 * _K1, "rhs": 32 * _K2 * _sh**5 * _ch},
    "C2": {"lhs": -2 * _K3 * _sn * (_c - 1), "rhs": 8 * _K3 * _sh**3 * _ch},
    "C3": {"lhs": -16 * _sh**4 * _sn * (Gamma**2 - 1),
           "rhs": -32 * (Gamma**2 - 1) * _sh**5 * _ch},
    "C4": {"lhs": (_K4 * (2 * _sn - sp.sin(2 * theta))
                   - 4 * Gamma * _sn * _sh * sp.sin(3 * theta / 2)),
           "rhs": 8 * _sh * _ch * ((_K4 - 3 * Gamma) * _sh**2
                                   + 4 * Gamma * _sh**4)},
    "C5": {"lhs": (-8 * _sh**3 * (Gamma - 1)
                   * (_ch - Gamma * sp.cos(3 * theta / 2))),
           "rhs": 8 * _sh**3 * _ch * (_K2 - 4 * Gamma * (Gamma - 1) * _sh**2)},
}

_U_42 = 1 - _c
_A_44 = (gamma * ((1 - Gamma) ** 2 - delta * (Gamma**2 - 1) + Gamma * delta**2)
         + Gamma * delta**2 * (1 - Gamma + delta))
_PHI_43 = (8 * _sh * _ch * _U_42
           * (_A_44 * _U_42 + sp.Rational(1, 2) * _K2 * delta**2
              * (gamma + 1 + delta)))
_U_46 = -_K2 * delta**2 * (gamma + 1 + delta) / (2 * _A_44)
_THETA_MAX_47 = 2 * sp.atan(sp.sqrt(_U_46 / (2 - _U_46)))

# ---------------------------------------------------------------------------
# Appendix D: gamma = 0, (48)-(63).

_B_53 = 2 * (Gamma**2 + 1 - (Gamma + 1) ** 2 * _c + 2 * Gamma * _c**2)
_A_S_51 = delta * _B_53 - 4 * _sh**2 * (Gamma - 1) * (1 + Gamma - 2 * Gamma * _c)
_A_D_52 = -4 * _sh**2 * (Gamma - 1) ** 2
_PHI_49 = _A_S_51 * sp.sin((d + 1) * theta) + _A_D_52 * sp.sin(d * theta)
_THETA0_56 = sp.pi / (2 * (d + 1))
_DPHI_59 = (sp.diff(_A_S_51, theta) * sp.sin((d + 1) * theta)
            + _A_S_51 * (d + 1) * sp.cos((d + 1) * theta)
            + sp.diff(_A_D_52, theta) * sp.sin(d * theta)
            + _A_D_52 * d * sp.cos(d * theta))
_THETA_MAX_58 = _THETA0_56 - (_at_theta0(_PHI_49, _THETA0_56)
                              / _at_theta0(_DPHI_59, _THETA0_56))
_DB_62 = 2 * _sn * ((Gamma + 1) ** 2 - 4 * Gamma * _c)
_DA_S_60 = delta * _DB_62 - 4 * (Gamma - 1) * (
    xi / 2 * (1 + Gamma - 2 * Gamma * _c) + 2 * Gamma * _sh**2 * _sn)
_DA_D_61 = -2 * (Gamma - 1) ** 2 * _sn
_THETA_MAX_63 = _THETA0_56 - (
    (_at_theta0(_A_S_51, _THETA0_56)
     + _at_theta0(_A_D_52, _THETA0_56) * sp.cos(_THETA0_56))
    / (_at_theta0(_DA_S_60, _THETA0_56)
       + _at_theta0(_DA_D_61, _THETA0_56) * sp.cos(_THETA0_56)
       + d * _at_theta0(_A_D_52, _THETA0_56) * sp.sin(_THETA0_56)))

# ---------------------------------------------------------------------------
# Appendix E: small theta, (64)-(70).

_ALPHA_67 = ((gamma * delta**2 * _K3 + delta**3 * Delta + delta**2 * eta) * theta**3
             / (_K2 * theta**3 + delta**2 * _K3 * theta
                + delta * (Gamma**2 - 1) * theta**3))
_BETA_69 = (-gamma * C1 - gamma * delta**2 * C2 + gamma * delta * C3
            + delta**3 * C10 + delta**2 * C11) / _DEN_7

# ---------------------------------------------------------------------------
# The printed text, one string per equation (whole equation for multi-part).

_T1 = r"VE(z) = K_w + B_w \frac{z-1}{Tz} + M_w \frac{(z-1)^2}{T^2 z^2}, \quad (1)"
_T2 = r"\Delta = 1 + VE(z) z^{-d} \mathcal{Z}[\text{ZOH } G(s)] = 0, \quad (2)"
_T3 = (r"\mathcal{Z}[\text{ZOH } G(s)] = \mathcal{Z} \left[\frac{1 - e^{-Ts}}{s}"
       r" \frac{1}{ms^2 + bs} \right]. \quad (3)")
_T4 = (r"\mathcal{Z}[\text{ZOH } G(s)] = \frac{\left(e^{-\frac{bT}{m}} - 1 + "
       r"\frac{bT}{m} \right) z + 1 - \left(1 + \frac{bT}{m} \right) "
       r"e^{-\frac{bT}{m}}}{\frac{(z-1)b^2}{m} \left(z - e^{-\frac{bT}{m}} "
       r"\right)}. \quad (4)")
_T5 = (r"\begin{aligned} \Delta = & \Gamma \delta^2 z^{d+4} - (1 + \Gamma) "
       r"\delta^2 z^{d+3} + \delta^2 z^{d+2} \\ & + [\alpha(1 + \Gamma(\delta - "
       r"1)) + \beta \delta \Gamma \\ & + \gamma(1 - \Gamma(1 + \delta)) + "
       r"\delta(1 - \Gamma)] z^3 \\ & - [\alpha(1 + \delta - \Gamma(1 - "
       r"2\gamma)) + \beta(\Gamma(\gamma - 2) + \delta) \\ & + \gamma(3(1 - "
       r"\Gamma) + \delta) + 2\delta] z^2 \\ & + (\alpha\gamma\Gamma + "
       r"\beta(\gamma - \Gamma) + \gamma(3(1 - \Gamma) + 2\delta) + \delta) z "
       r"\\ & - \gamma(1 - \Gamma + \delta) = 0. \end{aligned} \quad (5)")
_T6 = r"z = 1e^{j\theta} = \cos(\theta) + j \sin(\theta) \quad (6)"
_T7 = (r"\begin{cases} \alpha = \frac{\gamma C_1 + \gamma \delta^2 C_2 + "
       r"\gamma \delta C_3 + \delta^3 C_4 + \delta^2 C_5}{C_6 + \delta^2 C_7 "
       r"+ \delta C_8} \\ \beta = \frac{-\gamma C_1 - \gamma \delta^2 C_2 + "
       r"\gamma \delta C_3 + \delta^3 C_4 + \delta^2 C_5}{C_6 + \delta^2 C_7 "
       r"+ \delta C_8} \end{cases} \quad (7)")
_T8 = r"\theta_{\max} = 2 \arctan\left(\sqrt{\frac{u}{2-u}}\right), \quad (8)"
_T9 = (r"u = -\frac{(1-\Gamma)^2 \delta^2 (\gamma + 1 + \delta)}{2A}, "
       r"\quad (9)")
_T10 = (r"A = \gamma [(1-\Gamma)^2 - \delta(\Gamma^2 - 1) + \Gamma\delta^2] + "
        r"\Gamma\delta^2(1-\Gamma + \delta). \quad (10)")
_T11 = (r"\begin{cases} \alpha = \frac{\delta^3 C_4 + \delta^2 C_5}{C_6 + "
        r"\delta^2 C_7 + \delta C_8} \\ \beta = \frac{\delta^3 C_{10} + "
        r"\delta^2 C_{11}}{C_6 + \delta^2 C_7 + \delta C_8} \end{cases} "
        r"\quad (11)")
_T12 = (r"\theta_{\max} = \theta_0 - \frac{A_{S0} + A_{D0} \cos(\theta_0)}"
        r"{A'_{S0} + A'_{D0} \cos(\theta_0) + dA_{D0} \sin(\theta_0)}, "
        r"\quad (12)")
_T13_THETA0 = r"\theta_0 = \frac{\pi}{2(d+1)}"
_T13_A_S = (r"A_S(\theta) = 2\delta \left(\Gamma^2 + 1 - (\Gamma + 1)^2 c + "
            r"2\Gamma c^2 \right) - 4sh^2(\Gamma - 1)(1 + \Gamma - 2\Gamma c),")
_T13_A_D = r"A_D(\theta) = -4sh^2(\Gamma - 1)^2, \quad (13)"
_T14 = (r"\begin{cases} \alpha = \frac{\delta \sin^2(\frac{\theta}{2}) "
        r"[\delta^2(\Gamma^2 - 2 \cos(\theta)\Gamma + 1) - \delta(\Gamma - "
        r"1)(\Gamma - 2 \cos(\theta)\Gamma + 1)]}{\frac{1}{4} \delta^2(\Gamma^2 "
        r"- 2 \cos(\theta)\Gamma + 1) - \delta \sin^2(\frac{\theta}{2})(\Gamma^2 "
        r"- 1) + \sin^2(\frac{\theta}{2})(\Gamma - 1)^2} \\ \beta = "
        r"\frac{-\delta^3(\Gamma^2 - 2 \cos(\theta)\Gamma + 1) + 4\delta^2 "
        r"\sin^2(\frac{\theta}{2})\Gamma(\Gamma - 1)}{\delta^2(\Gamma^2 - 2 "
        r"\cos(\theta)\Gamma + 1) - 4\delta \sin^2(\frac{\theta}{2})(\Gamma^2 - "
        r"1) + 4 \sin^2(\frac{\theta}{2})(\Gamma - 1)^2} \end{cases} \quad (14)")
_T15 = (r"\theta_{\max} = 2 \arctan \left(\sqrt{\frac{(\Gamma - 1)^2(1 + "
        r"\delta)}{4\Gamma(\Gamma - 1 - \delta) - (\Gamma - 1)^2(1 + \delta)}}"
        r" \right). \quad (15)")
_T16 = r"K_p = 600 \text{ mV/A}, \quad K_i = 600 \text{ mV/(A.ms)}. \quad (16)"
_T17 = r"K_p = 6000 \text{ mV/A}, \quad K_i = 6000 \text{ mV/(A.ms)}. \quad (17)"
_T18 = (r"\begin{aligned} \text{Real part} = & -\delta^2 (1 + \Gamma) "
        r"\cos(\theta (d + 3)) \\ & + \delta^2 \cos(\theta (d + 2)) + \delta^2 "
        r"\Gamma \cos(\theta (d + 4)) \\ & + (((-\beta - 2\alpha + 3)\gamma + "
        r"2\beta + \alpha)\Gamma \\ & + (-\beta - \alpha - \gamma - 2)\delta - "
        r"\alpha - 3\gamma) \cos(2\theta) \\ & + (((\beta + \alpha - \gamma - "
        r"1)\delta - \alpha - \gamma)\Gamma \\ & + \alpha + \delta + \gamma) "
        r"\cos(3\theta) \\ & + (((\alpha - 3)\gamma - \beta)\Gamma + (2\gamma + "
        r"1)\delta \\ & + \gamma(\beta + 3)) \cos(\theta) \\ & + \gamma(\Gamma - "
        r"\delta - 1) = 0, \end{aligned} \quad (18)")
_T19 = (r"\begin{aligned} \text{Imag part} = & -\delta^2 (1 + \Gamma) "
        r"\sin(\theta (d + 3)) \\ & + \delta^2 \sin(\theta (d + 2)) + \delta^2 "
        r"\Gamma \sin(\theta (d + 4)) \\ & + (((-\beta - 2\alpha + 3)\gamma + "
        r"2\beta + \alpha)\Gamma \\ & + (-\beta - \alpha - \gamma - 2)\delta - "
        r"\alpha - 3\gamma) \sin(2\theta) \\ & + (((\beta + \alpha - \gamma - "
        r"1)\delta - \alpha - \gamma)\Gamma \\ & + \alpha + \delta + \gamma) "
        r"\sin(3\theta) \end{aligned}"
        "\n"
        r"\begin{aligned} & -\sin(\theta) (((-\alpha + 3)\gamma + \beta)\Gamma "
        r"\\ & + (-2\gamma - 1)\delta - \gamma(\beta + 3)) = 0. \end{aligned} "
        r"\quad (19)")
_T20 = (r"K_1 = 32 \sin^5\left(\frac{\theta}{2}\right) "
        r"\cos\left(\frac{\theta}{2}\right), \quad (20)")
_T21 = r"K_2 = (1 - \Gamma)^2, \quad (21)"
_T22 = r"K_3 = 1 + \Gamma^2 - 2\Gamma \cos(\theta), \quad (22)"
_T23 = r"K_4 = 1 + \Gamma + \Gamma^2. \quad (23)"
_T24 = r"C_1 = K_1 K_2, \quad (24)"
_T25 = r"C_2 = -2 K_3 \sin(\theta) (\cos(\theta) - 1), \quad (25)"
_T26 = (r"C_3 = -16 \sin\left(\frac{\theta}{2}\right)^4 \sin(\theta) "
        r"(\Gamma^2 - 1), \quad (26)")
_T27 = (r"\begin{aligned} C_4 = & K_4 (2 \sin(\theta(d + 1)) - \sin(d\theta) "
        r"- \sin(\theta(d + 2))) \\ & - 4\Gamma \sin(\theta(d + 1)) "
        r"\sin\left(\frac{\theta}{2}\right) \sin\left(\frac{3\theta}{2}\right),"
        r" \end{aligned} \quad (27)")
_T28 = (r"\begin{aligned} C_5 = & -8 \sin\left(\frac{\theta}{2}\right)^3 "
        r"(\Gamma - 1) \\ & \times \left(\cos\left(\frac{\theta(2d + 1)}{2}"
        r"\right) - \Gamma \cos\left(\frac{\theta(2d + 3)}{2}\right) \right), "
        r"\end{aligned} \quad (28)")
_T29 = r"C_6 = -2 K_2 \sin(\theta) (\cos(\theta) - 1), \quad (29)"
_T30 = r"C_7 = K_3 \sin(\theta), \quad (30)"
_T31 = (r"C_8 = \sin(\theta) (2(\Gamma^2 - 1)) (\cos(\theta) - 1), "
        r"\quad (31)")
_T32 = r"C_9 = K_1 (\Gamma^2 - 1), \quad (32)"
_T33 = (r"\begin{aligned} C_{10} = & -2 \cos\left(\frac{\theta(2d + 1)}{2}"
        r"\right) \\ & \times \left(K_4 \sin\left(\frac{\theta}{2}\right) - "
        r"\Gamma \sin\left(\frac{3\theta}{2}\right) \right), \end{aligned} "
        r"\quad (33)")
_T34 = (r"\begin{aligned} C_{11} = & 4 \sin\left(\frac{\theta}{2}\right)^2 "
        r"(\Gamma^2 \sin(\theta + d\theta) + \sin(d\theta)) \\ & - 4\Gamma "
        r"\sin\left(\frac{\theta}{2}\right) \sin\left(\frac{\theta}{2} + "
        r"d\theta\right) \sin(\theta). \end{aligned} \quad (34)")
_T35 = (r"s_h := \sin\left(\frac{\theta}{2}\right), \quad c_h := "
        r"\cos\left(\frac{\theta}{2}\right), \quad c := \cos\theta, "
        r"\quad (35)")
_T36 = (r"\begin{aligned} \Phi(\theta) &= \gamma C_1(\theta) + \gamma "
        r"\delta^2 C_2(\theta) + \gamma \delta C_3(\theta) \\ &+ \delta^3 "
        r"C_4(\theta) + \delta^2 C_5(\theta) = 0. \end{aligned} \quad (36)")
_T37 = r"C_1 = K_2 K_1 = 32 K_2 s_h^5 c_h, \quad (37)"
_T38 = (r"C_2 = -2K_3 \sin \theta (\cos \theta - 1) = 8 K_3 s_h^3 c_h, "
        r"\quad (38)")
_T39 = (r"C_3 = -16 s_h^4 \sin \theta (\Gamma^2 - 1) = -32(\Gamma^2 - 1) "
        r"s_h^5 c_h, \quad (39)")
_T40 = (r"\begin{aligned} C_4 &= K_4(2 \sin \theta - \sin 2\theta) - "
        r"4\Gamma \sin \theta s_h \sin(\frac{3\theta}{2}) \\ &= 8 s_h c_h "
        r"\left[(K_4 - 3\Gamma) s_h^2 + 4\Gamma s_h^4 \right], \end{aligned} "
        r"\quad (40)")
_T41 = (r"\begin{aligned} C_5 &= -8 s_h^3 (\Gamma - 1) (c_h - \Gamma "
        r"\cos(\frac{3\theta}{2})) \\ &= 8 s_h^3 c_h \left[K_2 - 4\Gamma(\Gamma "
        r"- 1) s_h^2 \right]. \end{aligned} \quad (41)")
_T42 = r"u := 1 - \cos \theta = 2s_h^2 \in [0, 2]. \quad (42)"
_T43 = (r"\Phi(\theta) = 8 s_h c_h u \left(A u + \frac{1}{2} K_2 \delta^2 "
        r"(\gamma + 1 + \delta) \right), \quad (43)")
_T44 = (r"A = \gamma \left[(1 - \Gamma)^2 - \delta(\Gamma^2 - 1) + \Gamma "
        r"\delta^2 \right] + \Gamma \delta^2 (1 - \Gamma + \delta). \quad (44)")
_T45 = (r"A u + \frac{1}{2} K_2 \delta^2 (\gamma + 1 + \delta) = 0, "
        r"\quad (45)")
_T46 = (r"u = -\frac{K_2 \delta^2 (\gamma + 1 + \delta)}{2A}, \quad 0 \leq "
        r"u \leq 2. \quad (46)")
_T47 = r"\theta_{\max} = 2 \arctan \sqrt{\frac{u}{2-u}}, \quad (47)"
_T48 = r"\delta C_4(\theta) + C_5(\theta) = 0. \quad (48)"
_T49 = (r"\Phi(\theta) = A_S(\theta) \sin((d+1)\theta) + A_D(\theta) "
        r"\sin(d\theta) = 0, \quad (49)")
_T50 = (r"sh := \sin \frac{\theta}{2}, ch := \cos \frac{\theta}{2}, s := "
        r"\sin \theta, c := \cos \theta, \Gamma = e^\delta, \quad (50)")
_T51 = (r"A_S(\theta) = \delta B(\theta) - 4 sh^2 (\Gamma - 1) (1 + \Gamma - "
        r"2\Gamma c), \quad (51)")
_T52 = r"A_D(\theta) = -4 sh^2 (\Gamma - 1)^2, \quad (52)"
_T53 = (r"B(\theta) = 2 \left(\Gamma^2 + 1 - (\Gamma + 1)^2 c + 2\Gamma c^2 "
        r"\right). \quad (53)")
_T54 = (r"\frac{d}{d\theta} \sin((d+1)\theta) = (d+1) \cos((d+1)\theta) = 0, "
        r"\quad (54)")
_T55 = (r"\theta = \frac{(2k+1)\pi}{2(d+1)}, \quad k \in \mathbb{Z}. "
        r"\quad (55)")
_T56 = r"\theta_0 = \frac{\pi}{2(d+1)}. \quad (56)"
_T57 = (r"\sin(d\theta_0) = \cos\left(\frac{\pi}{2(d+1)}\right) > 0, "
        r"\cos(d\theta_0) = \sin\left(\frac{\pi}{2(d+1)}\right) > 0. "
        r"\quad (57)")
_T58 = (r"\theta_{\max} \approx \theta_0 - \frac{\Phi(\theta_0)}"
        r"{\Phi'(\theta_0)}, \quad (58)")
_T59 = (r"\begin{aligned} \Phi'(\theta) &= A'_S(\theta) \sin((d+1)\theta) \\ "
        r"&+ A_S(\theta) (d+1) \cos((d+1)\theta) \\ &+ A'_D(\theta) "
        r"\sin(d\theta) + A_D(\theta) d \cos(d\theta), \end{aligned} \quad (59)")
_T60 = (r"A'_S(\theta) = \delta B'(\theta) - 4(\Gamma - 1)\left(\frac{\xi}{2}"
        r"(1 + \Gamma - 2\Gamma c) + 2\Gamma s h^2 s\right), \quad (60)")
_T61 = r"A'_D(\theta) = -2(\Gamma - 1)^2 s, \quad (61)"
_T62 = r"B'(\theta) = 2s\left((\Gamma + 1)^2 - 4\Gamma c\right). \quad (62)"
_T63 = (r"\theta_{\max} = \theta_0 - \frac{A_{S0} + A_{D0} \cos(\theta_0)}"
        r"{A'_{S0} + A'_{D0} \cos(\theta_0) + d A_{D0} \sin(\theta_0)}, "
        r"\quad (63)")
_T64 = (r"\begin{aligned} K_1 &\approx 16\theta^5, & K_2 &= (1 - \Gamma)^2, "
        r"\\ K_3 &= 1 + \Gamma^2 - 2\Gamma \cos(\theta), & K_4 &= 1 + \Gamma + "
        r"\Gamma^2. \end{aligned} \quad (64)")
_T65 = (r"\begin{aligned} C_1 &\approx K_2 K_1 \approx (\text{const}) "
        r"\theta^5, & C_2 &\approx K_3 (\text{const}) \theta^3, \\ C_3 "
        r"&\approx (\Gamma^2 - 1) (\text{const}) \theta^5, & C_4 &\approx "
        r"\Delta \theta^3, \\ C_5 &\approx \eta \theta^3, & C_6 &\approx K_2 "
        r"(\text{const}) \theta^3, \\ C_7 &\approx K_3 (\text{const}) \theta, "
        r"& C_8 &\approx (\Gamma^2 - 1) (\text{const}) \theta^3, \\ C_9 "
        r"&\approx (\Gamma^2 - 1) (\text{const}) \theta^5, & C_{10} &\approx "
        r"(3\Gamma - K_4) (\text{const}) \theta, \\ C_{11} &\approx \xi "
        r"\theta^3. \end{aligned} \quad (65)")
_T66 = (r"\alpha = \frac{\gamma C_1 + \gamma \delta^2 C_2 + \gamma \delta C_3 "
        r"+ \delta^3 C_4 + \delta^2 C_5}{C_6 + \delta^2 C_7 + \delta C_8}. "
        r"\quad (66)")
_T67 = (r"\alpha(\theta) \approx \frac{(\gamma \delta^2 K_3 + \delta^3 \Delta "
        r"+ \delta^2 \eta) \theta^3}{K_2 \theta^3 + \delta^2 K_3 \theta + "
        r"\delta (\Gamma^2 - 1) \theta^3}. \quad (67)")
_T68 = r"\lim_{\theta \rightarrow 0^+} \alpha(\theta) = 0^+. \quad (68)"
_T69 = (r"\beta = \frac{-\gamma C_1 - \gamma \delta^2 C_2 + \gamma \delta C_3 "
        r"+ \delta^3 C_{10} + \delta^2 C_{11}}{C_6 + \delta^2 C_7 + \delta "
        r"C_8}. \quad (69)")
_T70 = r"\lim_{\theta \rightarrow 0} \beta = -\delta, \quad (70)"

_SH_NOTE = "sh (printed 'sh', defined as s_h) read as sin(theta/2)."
_PC = PRINTED_COEFFICIENTS
_PD0 = PRINTED_D0_COEFFICIENTS

_ENTRIES = [
    Printed("eq1", 1, (149, 149), _T1, _VE_1, "definition"),
    Printed("eq2", 2, (163, 163), _T2, _DELTA_2, "definition",
            "Characteristic equation; Z[ZOH G(s)] replaced by the printed (4) "
            "and VE(z) by (1), in physical symbols (d = T_d/T)."),
    Printed("eq3", 3, (167, 167), _T3, _ZOH_G_3, "definition",
            "The s-domain argument of the z-transform; Z[.] itself not applied."),
    Printed("eq4", 4, (171, 171), _T4, _Z_ZOH_G_4, "identity",
            "RHS; claimed equal to the z-transform of (3)."),
    Printed("eq5", 5, (175, 175), _T5, _DELTA_5, "identity",
            "LHS of '= 0'; claimed to be (2) in Table I's dimensionless "
            "parameters with Gamma = exp(delta)."),
    Printed("eq6", 6, (179, 179), _T6, sp.exp(sp.I * theta), "definition",
            "j is the imaginary unit."),
    Printed("eq7.alpha", 7, (183, 183), _T7, _ALPHA_7, "closed_form",
            "C_i kept as symbols C1..C11."),
    Printed("eq7.beta", 7, (183, 183), _T7, _BETA_7, "closed_form",
            "C_i kept as symbols; numerator printed with delta^3 C_4 + "
            "delta^2 C_5 (not C_10, C_11 as in (11) and (69))."),
    Printed("eq8", 8, (196, 196), _T8, _THETA_MAX_8, "closed_form",
            "u from (9) and A from (10) substituted."),
    Printed("eq9", 9, (200, 200), _T9, _U_9, "closed_form",
            "A from (10) substituted."),
    Printed("eq10", 10, (204, 204), _T10, _A_10, "definition"),
    Printed("eq11.alpha", 11, (219, 219), _T11, _ALPHA_11, "closed_form",
            "C_i kept as symbols."),
    Printed("eq11.beta", 11, (219, 219), _T11, _BETA_11, "closed_form",
            "C_i kept as symbols."),
    Printed("eq12", 12, (223, 223), _T12, _THETA_MAX_12, "approximation",
            "theta_0, A_S, A_D from (13); A'_{S0}, A'_{D0} are d/dtheta of "
            "(13)'s A_S, A_D at theta_0 (prime defined on line 233). Main text "
            "presents it as theta_max; Appendix D derives it as one Newton "
            "step (58)."),
    Printed("eq13.theta0", 13, (227, 227), _T13_THETA0, _THETA0_13,
            "definition"),
    Printed("eq13.A_S", 13, (229, 229), _T13_A_S, _A_S_13, "definition",
            _SH_NOTE + " c = cos(theta)."),
    Printed("eq13.A_D", 13, (231, 231), _T13_A_D, _A_D_13, "definition",
            _SH_NOTE),
    Printed("eq14.alpha", 14, (241, 241), _T14, _ALPHA_14, "closed_form",
            "Claimed special case d = 0, gamma = 0 of (7)."),
    Printed("eq14.beta", 14, (241, 241), _T14, _BETA_14, "closed_form",
            "Claimed special case d = 0, gamma = 0 of (7)."),
    Printed("eq15", 15, (250, 250), _T15, _THETA_MAX_15, "closed_form",
            "Claimed to be (8) at gamma = 0."),
    Printed("eq16", 16, (398, 398), _T16,
            sp.Tuple(sp.Integer(600), sp.Integer(600)), "not_checkable",
            "Experimental PI gains (K_p in mV/A, K_i in mV/(A.ms)), low gain."),
    Printed("eq17", 17, (402, 402), _T17,
            sp.Tuple(sp.Integer(6000), sp.Integer(6000)), "not_checkable",
            "Experimental PI gains (K_p in mV/A, K_i in mV/(A.ms)), high gain."),
    Printed("eq18", 18, (535, 535), _T18, _REAL_18, "identity",
            "LHS of '= 0'; claimed Re of (5) at z = exp(j theta). Includes "
            "the printed constant term gamma (Gamma - delta - 1)."),
    Printed("eq19", 19, (537, 539), _T19, _IMAG_19, "identity",
            "LHS of '= 0'; claimed Im of (5) at z = exp(j theta). Printed "
            "over two display blocks; the sin(theta) term is printed with a "
            "leading minus; no constant term."),
    Printed("eq20", 20, (545, 545), _T20, _PC["K1"], "definition"),
    Printed("eq21", 21, (547, 547), _T21, _PC["K2"], "definition"),
    Printed("eq22", 22, (549, 549), _T22, _PC["K3"], "definition"),
    Printed("eq23", 23, (551, 551), _T23, _PC["K4"], "definition"),
    Printed("eq24", 24, (555, 555), _T24, _PC["C1"], "definition",
            "K's from (20)-(23) substituted, here and in (25)-(34)."),
    Printed("eq25", 25, (557, 557), _T25, _PC["C2"], "definition"),
    Printed("eq26", 26, (559, 559), _T26, _PC["C3"], "definition"),
    Printed("eq27", 27, (561, 561), _T27, _PC["C4"], "definition"),
    Printed("eq28", 28, (563, 563), _T28, _PC["C5"], "definition"),
    Printed("eq29", 29, (565, 565), _T29, _PC["C6"], "definition"),
    Printed("eq30", 30, (567, 567), _T30, _PC["C7"], "definition"),
    Printed("eq31", 31, (569, 569), _T31, _PC["C8"], "definition"),
    Printed("eq32", 32, (571, 571), _T32, _PC["C9"], "definition",
            "C_9 is defined but appears in none of the printed equations."),
    Printed("eq33", 33, (573, 573), _T33, _PC["C10"], "definition"),
    Printed("eq34", 34, (575, 575), _T34, _PC["C11"], "definition"),
    Printed("eq35.s_h", 35, (581, 581), _T35, _sh, "definition"),
    Printed("eq35.c_h", 35, (581, 581), _T35, _ch, "definition"),
    Printed("eq35.c", 35, (581, 581), _T35, _c, "definition"),
    Printed("eq36", 36, (587, 587), _T36, _PHI_36, "definition",
            "LHS of '= 0' (numerator of (7)'s alpha), C_i kept as symbols; "
            "printed as vanishing at theta_max for d = 0."),
    Printed("eq37.lhs", 37, (591, 591), _T37, _PD0["C1"]["lhs"], "identity",
            "First printed form of C_1 at d = 0 (K's substituted)."),
    Printed("eq37.rhs", 37, (591, 591), _T37, _PD0["C1"]["rhs"], "identity",
            "Second printed form of C_1 at d = 0."),
    Printed("eq38.lhs", 38, (593, 593), _T38, _PD0["C2"]["lhs"], "identity",
            "First printed form of C_2 at d = 0."),
    Printed("eq38.rhs", 38, (593, 593), _T38, _PD0["C2"]["rhs"], "identity",
            "Second printed form of C_2 at d = 0."),
    Printed("eq39.lhs", 39, (595, 595), _T39, _PD0["C3"]["lhs"], "identity",
            "First printed form of C_3 at d = 0."),
    Printed("eq39.rhs", 39, (595, 595), _T39, _PD0["C3"]["rhs"], "identity",
            "Second printed form of C_3 at d = 0."),
    Printed("eq40.lhs", 40, (597, 597), _T40, _PD0["C4"]["lhs"], "identity",
            "First printed form of C_4 at d = 0."),
    Printed("eq40.rhs", 40, (597, 597), _T40, _PD0["C4"]["rhs"], "identity",
            "Second printed form of C_4 at d = 0."),
    Printed("eq41.lhs", 41, (599, 599), _T41, _PD0["C5"]["lhs"], "identity",
            "First printed form of C_5 at d = 0."),
    Printed("eq41.rhs", 41, (599, 599), _T41, _PD0["C5"]["rhs"], "identity",
            "Second printed form of C_5 at d = 0."),
    Printed("eq42.lhs", 42, (603, 603), _T42, _U_42, "definition",
            "u := 1 - cos(theta); the printed range [0, 2] is not encoded."),
    Printed("eq42.rhs", 42, (603, 603), _T42, 2 * _sh**2, "identity",
            "Second printed form of u, 2 s_h^2."),
    Printed("eq43", 43, (609, 609), _T43, _PHI_43, "identity",
            "Claimed equal to (36) at d = 0; u from (42), A from (44), K_2 "
            "from (21) substituted."),
    Printed("eq44", 44, (613, 613), _T44, _A_44, "definition"),
    Printed("eq45", 45, (621, 621), _T45, _A_44 * u
            + sp.Rational(1, 2) * _K2 * delta**2 * (gamma + 1 + delta),
            "identity",
            "LHS of '= 0' with u kept as the unknown symbol u; A from (44), "
            "K_2 from (21)."),
    Printed("eq46", 46, (625, 625), _T46, _U_46, "closed_form",
            "A from (44) and K_2 from (21) substituted; the printed range "
            "0 <= u <= 2 is not encoded."),
    Printed("eq47", 47, (630, 630), _T47, _THETA_MAX_47, "closed_form",
            "u from (46) substituted."),
    Printed("eq48", 48, (647, 647), _T48, delta * C4 + C5, "identity",
            "LHS of '= 0' (alpha = 0 at gamma = 0), C_i kept as symbols."),
    Printed("eq49", 49, (653, 653), _T49, _PHI_49, "identity",
            "LHS of '= 0', A_S, A_D from (51)-(53); claimed exactly equal to "
            "the left side of (48)."),
    Printed("eq50.sh", 50, (657, 657), _T50, _sh, "definition"),
    Printed("eq50.ch", 50, (657, 657), _T50, _ch, "definition"),
    Printed("eq50.s", 50, (657, 657), _T50, _sn, "definition"),
    Printed("eq50.c", 50, (657, 657), _T50, _c, "definition"),
    Printed("eq50.Gamma", 50, (657, 657), _T50, sp.exp(delta), "definition"),
    Printed("eq51", 51, (661, 661), _T51, _A_S_51, "definition",
            "B from (53) substituted."),
    Printed("eq52", 52, (663, 663), _T52, _A_D_52, "definition"),
    Printed("eq53", 53, (665, 665), _T53, _B_53, "definition"),
    Printed("eq54", 54, (675, 675), _T54,
            sp.Eq(sp.Derivative(sp.sin((d + 1) * theta), theta),
                  (d + 1) * sp.cos((d + 1) * theta), evaluate=False),
            "identity",
            "The derivative identity; the trailing '= 0' is the stationarity "
            "condition imposed, not encoded."),
    Printed("eq55", 55, (679, 679), _T55, (2 * k + 1) * sp.pi / (2 * (d + 1)),
            "closed_form", "Roots of cos((d+1) theta) = 0; k an integer."),
    Printed("eq56", 56, (683, 683), _T56, _THETA0_56, "definition"),
    Printed("eq57.sin", 57, (688, 688), _T57,
            sp.Eq(sp.sin(d * _THETA0_56), sp.cos(sp.pi / (2 * (d + 1))),
                  evaluate=False),
            "identity", "theta_0 from (56); the '> 0' claim is not encoded."),
    Printed("eq57.cos", 57, (688, 688), _T57,
            sp.Eq(sp.cos(d * _THETA0_56), sp.sin(sp.pi / (2 * (d + 1))),
                  evaluate=False),
            "identity", "theta_0 from (56); the '> 0' claim is not encoded."),
    Printed("eq58", 58, (698, 698), _T58, _THETA_MAX_58, "approximation",
            "Phi from (49), Phi' from (59), theta_0 from (56)."),
    Printed("eq59", 59, (702, 702), _T59, _DPHI_59, "identity",
            "RHS; A_S, A_D from (51)-(53), A'_S, A'_D taken as d/dtheta of "
            "those (so the claim is the product rule for (49))."),
    Printed("eq60", 60, (707, 707), _T60, _DA_S_60, "identity",
            "B' from (62) substituted. xi is undefined in the paper, kept "
            "free. 's h^2 s' read as sh^2 * s = sin(theta/2)^2 sin(theta). "
            "Claimed d/dtheta of (51). Line 704-705 before it carries a "
            "stray sentence ('and For completeness ... from (8):')."),
    Printed("eq61", 61, (709, 709), _T61, _DA_D_61, "identity",
            "s = sin(theta); claimed d/dtheta of (52)."),
    Printed("eq62", 62, (711, 711), _T62, _DB_62, "identity",
            "s = sin(theta), c = cos(theta); claimed d/dtheta of (53)."),
    Printed("eq63", 63, (716, 716), _T63, _THETA_MAX_63, "approximation",
            "theta_0 from (56); A_S0, A_D0 from (51)-(53) and A'_S0, A'_D0 "
            "from the printed (60)-(62) at theta_0, so the undefined xi "
            "enters. Same printed form as (12)."),
    Printed("eq64.K1", 64, (732, 732), _T64, 16 * theta**5, "approximation",
            "Small-theta form of K_1."),
    Printed("eq64.K2", 64, (732, 732), _T64, (1 - Gamma) ** 2, "definition"),
    Printed("eq64.K3", 64, (732, 732), _T64,
            1 + Gamma**2 - 2 * Gamma * sp.cos(theta), "definition"),
    Printed("eq64.K4", 64, (732, 732), _T64, 1 + Gamma + Gamma**2,
            "definition"),
    Printed("eq65.C1", 65, (737, 737), _T65, const * theta**5, "approximation",
            "Last printed form; the middle form K_2 K_1 is (24). 'const' is an "
            "unspecified placeholder (one symbol for every occurrence)."),
    Printed("eq65.C2", 65, (737, 737), _T65, _K3 * const * theta**3,
            "approximation", "K_3 from (22); 'const' unspecified."),
    Printed("eq65.C3", 65, (737, 737), _T65,
            (Gamma**2 - 1) * const * theta**5, "approximation",
            "'const' unspecified."),
    Printed("eq65.C4", 65, (737, 737), _T65, Delta * theta**3,
            "approximation",
            "Delta is undefined in the paper (not the characteristic "
            "equation), kept free."),
    Printed("eq65.C5", 65, (737, 737), _T65, eta * theta**3, "approximation",
            "eta is undefined in the paper, kept free."),
    Printed("eq65.C6", 65, (737, 737), _T65, _K2 * const * theta**3,
            "approximation", "K_2 from (21); 'const' unspecified."),
    Printed("eq65.C7", 65, (737, 737), _T65, _K3 * const * theta,
            "approximation", "K_3 from (22); 'const' unspecified."),
    Printed("eq65.C8", 65, (737, 737), _T65,
            (Gamma**2 - 1) * const * theta**3, "approximation",
            "'const' unspecified."),
    Printed("eq65.C9", 65, (737, 737), _T65,
            (Gamma**2 - 1) * const * theta**5, "approximation",
            "'const' unspecified."),
    Printed("eq65.C10", 65, (737, 737), _T65,
            (3 * Gamma - _K4) * const * theta, "approximation",
            "K_4 from (23); 'const' unspecified."),
    Printed("eq65.C11", 65, (737, 737), _T65, xi * theta**3, "approximation",
            "xi is undefined in the paper, kept free (same symbol as in "
            "(60); nothing in the paper ties the two)."),
    Printed("eq66", 66, (742, 742), _T66, _ALPHA_7, "closed_form",
            "Restates (7)'s alpha; C_i kept as symbols."),
    Printed("eq67", 67, (747, 747), _T67, _ALPHA_67, "approximation",
            "K_2, K_3 from (21), (22); Delta and eta undefined, kept free."),
    Printed("eq68", 68, (753, 753), _T68, sp.Integer(0), "limit",
            "Limit of alpha as theta -> 0+; printed value 0^+ (approached "
            "from above), stored as 0."),
    Printed("eq69", 69, (758, 758), _T69, _BETA_69, "closed_form",
            "C_i kept as symbols; numerator printed with delta^3 C_10 + "
            "delta^2 C_11 (text says 'obtained from (8)')."),
    Printed("eq70", 70, (762, 762), _T70, -delta, "limit",
            "Limit of beta as theta -> 0."),
]

#: Every entry by id, in equation order.
PRINTED = {p.id: p for p in _ENTRIES}


def printed(id):
    """Return the printed entry with the given id.

    Parameters
    ----------
    id : str
        ``eqN`` or ``eqN.part``, a key of :data:`PRINTED`.

    Returns
    -------
    Printed

    Raises
    ------
    TypeError
        If ``id`` is not a string.
    ValueError
        If no entry has this id.

    Examples
    --------
    >>> printed("eq70").expr
    -delta
    """
    if not isinstance(id, str):
        raise TypeError(f"printed equation id must be a str, got {type(id).__name__}")
    try:
        return PRINTED[id]
    except KeyError:
        raise ValueError(
            f"no printed equation with id {id!r}; ids look like 'eq7.alpha', "
            f"see PRINTED for the list") from None
