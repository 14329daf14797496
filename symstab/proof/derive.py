"""Regenerate every derived object and write it as LaTeX and SymPy srepr.

Each derivation step becomes two files in the output folder:
``NN_step.json`` (for machines: every object's ``srepr`` and LaTeX) and
``NN_step.tex`` (for people).  The bytes depend only on the mathematics and
on SymPy's printers: no dates, versions or paths are written, and a second
run gives identical files.

:func:`derivation_steps` builds the content (pure, no I/O); :func:`write`
writes it atomically; :func:`check` compares it with what is on disk.
"""

import pathlib

import sympy as sp

from .._io import write_bytes
from ..codegen import float_forms as kernel_forms
from ..symbolic import model
from ..symbolic.boundary import beta_relations, boundary, coefficients
from ..symbolic.discretize import dimensionless_pulse_transfer_function, pulse_transfer_function
from ..symbolic.loop import characteristic_polynomial
from ..symbolic.small_theta import small_theta_limits
from ..symbolic.theta_max import closed_form_d0, newton_form_gamma0
from ..symbolic.unit_circle import unit_circle_split
from . import loop_derive, necessity
from .identity import check_identity
from .steps import Step, render  # noqa: F401  (part of this module's API)

__all__ = ["Step", "derivation_steps", "render", "write", "write_bytes", "check", "proofs", "OWNED"]


def proofs():
    """The identities every derivation run proves with the exact checker.

    Returns
    -------
    list of (name, statement, lhs, rhs)
    """
    bd = boundary()
    c = coefficients()
    g, dl = model.gamma, model.delta
    # Each part is affine in alpha and beta: part = a alpha + b beta + r, so
    # D * part(alpha = N_alpha / D, beta = N_beta / D) = a N_alpha + b N_beta + r D.
    A, rhs = sp.linear_eq_to_matrix(list(unit_circle_split()), [model.alpha, model.beta])
    cleared = [A[i, 0] * bd.alpha_numerator + A[i, 1] * bd.beta_numerator - rhs[i] * bd.denominator
               for i in range(2)]
    nf = newton_form_gamma0()
    out = [
        ("boundary_solves_real_part", "Re chi(e^{j theta}) = 0 on (alpha(theta), beta(theta))",
         cleared[0], sp.S.Zero),
        ("boundary_solves_imag_part", "Im chi(e^{j theta}) = 0 on (alpha(theta), beta(theta))",
         cleared[1], sp.S.Zero),
        ("alpha_numerator_c_form", "N_alpha = gamma C1 + gamma delta^2 C2 + gamma delta C3 + delta^3 C4 + delta^2 C5",
         bd.alpha_numerator,
         g * c["C1"] + g * dl**2 * c["C2"] + g * dl * c["C3"] + dl**3 * c["C4"] + dl**2 * c["C5"]),
        ("beta_numerator_c_form", "N_beta = -gamma C1 - gamma delta^2 C2 + gamma delta C9 + delta^3 C10 + delta^2 C11",
         bd.beta_numerator,
         -g * c["C1"] - g * dl**2 * c["C2"] + g * dl * c["C9"] + dl**3 * c["C10"] + dl**2 * c["C11"]),
        ("denominator_c_form", "D = C6 + delta^2 C7 + delta C8",
         bd.denominator, c["C6"] + dl**2 * c["C7"] + dl * c["C8"]),
        ("C1_is_K1_K2", "C1 = K1 K2", c["C1"], c["K1"] * c["K2"]),
        ("C7_is_K3_sin", "C7 = K3 sin(theta)", c["C7"], c["K3"] * sp.sin(model.theta)),
        ("gamma0_split", "N_alpha(gamma=0) / delta^2 = A_S sin((d+1) theta) + A_D sin(d theta)",
         nf.phi, nf.A_S * sp.sin((model.d + 1) * model.theta) + nf.A_D * sp.sin(model.d * model.theta)),
    ]
    for key, (lhs, rhs) in beta_relations().items():
        out.append((f"beta_monomial_{'_'.join(map(str, key))}",
                    f"coefficient of monomial {key} in N_beta", lhs, rhs))
    # The forms the numeric kernels are generated from (symstab.codegen.generator).
    out += kernel_forms.proofs()
    # The paper's loop built by the general path (symstab.Loop) is this one.
    out += loop_derive.paper_loop_proofs()
    # The identities of the necessity proofs (alpha > 0, the z = -1 line, |gamma| bound).
    out += necessity.proofs()
    return out


#: ``{(lhs, rhs): note}`` of the identities proved in this process.
_PROVED = {}


def _proof_note(name, lhs, rhs):
    """Prove ``lhs == rhs`` with the exact checker (once per process); return its note.

    The proof of an identity depends only on its two sides, so a second
    derivation in the same process (``symstab derive --check`` after a
    derivation, the tests) reuses it; a changed identity is a new key and
    is proved afresh.  Failures are never cached.
    """
    key = (sp.sympify(lhs), sp.sympify(rhs))
    if key not in _PROVED:
        result = check_identity(lhs, rhs)
        if result.equal is not True:
            raise AssertionError(f"derivation identity {name} not proved: {result.note}")
        _PROVED[key] = result.note
    return _PROVED[key]


def derivation_steps():
    """Build every derivation step (no I/O).

    Returns
    -------
    list of Step
    """
    chi = characteristic_polynomial()
    real, imag = unit_circle_split()
    bd = boundary()
    lim = small_theta_limits()
    cf = closed_form_d0()
    nf = newton_form_gamma0()
    steps = [
        Step("01_zoh", "Zero-order-hold pulse transfer function", (
            ("G", "plant G(s) = 1/(m s^2 + b s)", model.plant()),
            ("ZOH", "zero-order hold", model.zero_order_hold()),
            ("VE", "virtual environment VE(z), eq. (1)", model.virtual_environment()),
            ("pulse_transfer_function", "Z[ZOH G(s)] by residues (compare eq. (4))",
             pulse_transfer_function()),
            ("dimensionless_pulse_transfer_function", "(m/T^2) Z[ZOH G(s)] with delta, Gamma",
             dimensionless_pulse_transfer_function()),
        )),
        Step("02_characteristic_polynomial", "Closed-loop characteristic polynomial", (
            ("chi", "chi(z) with z^(d+k) symbolic (compare eq. (5))", chi.as_expr()),
            ("delayed_part", "coefficients of z^(d+4), z^(d+3), z^(d+2)",
             sp.Tuple(*chi.delayed.all_coeffs()[:3])),
            ("direct_part", "coefficients of z^3, z^2, z^1, z^0",
             sp.Tuple(*[sp.factor(x) for x in chi.direct.all_coeffs()])),
        )),
        Step("03_unit_circle", "Real and imaginary parts on z = exp(j theta)", (
            ("real_part", "Re chi(exp(j theta)) (compare eq. (18))", real),
            ("imag_part", "Im chi(exp(j theta)) (compare eq. (19))", imag),
        )),
        Step("04_boundary", "Closed-form boundary and C-coefficients", (
            ("alpha", "alpha(theta) = N_alpha / D (compare eq. (7))", bd.alpha),
            ("beta", "beta(theta) = N_beta / D (compare eq. (7))", bd.beta),
            ("alpha_numerator", "N_alpha", bd.alpha_numerator),
            ("beta_numerator", "N_beta", bd.beta_numerator),
            ("denominator", "D = C6 + delta^2 C7 + delta C8", bd.denominator),
        ) + tuple((name, f"derived {name} (compare eqs. (20)-(34))", expr)
                  for name, expr in coefficients().items())),
        Step("05_small_theta_limits", "Taylor limits at theta -> 0", (
            ("alpha_limit", "lim alpha (compare eq. (68))", lim.alpha_limit),
            ("beta_limit", "lim beta (compare eq. (70))", lim.beta_limit),
            ("alpha_theta2", "alpha = alpha_theta2 theta^2 + O(theta^4)", lim.alpha_theta2),
            ("beta_theta2", "beta = -delta + beta_theta2 theta^2 + O(theta^4)", lim.beta_theta2),
            ("start_slope", "d alpha / d beta at the starting point", lim.start_slope),
            ("alpha_sign_condition", "alpha > 0 near theta = 0 exactly when", lim.alpha_sign_condition),
        )),
        Step("06_theta_max", "End of the boundary arc", (
            ("d0_A", "d = 0: N_alpha/sin(theta) ~ u (A u + B), u = 1 - cos(theta)", cf.A),
            ("d0_B", "d = 0: B", cf.B),
            ("d0_u_root", "d = 0: u_max = -B/A (compare eqs. (9), (46))", cf.u_root),
            ("d0_theta_max", "d = 0: theta_max (compare eqs. (8), (47))", cf.theta_max),
            ("gamma0_phi", "gamma = 0: N_alpha / delta^2 (compare eq. (48))", nf.phi),
            ("gamma0_A_S", "gamma = 0: A_S (compare eqs. (13), (51))", nf.A_S),
            ("gamma0_A_D", "gamma = 0: A_D (compare eqs. (13), (52))", nf.A_D),
            ("gamma0_theta0", "gamma = 0: Newton start (compare eq. (56))", nf.theta0),
            ("gamma0_theta_newton", "gamma = 0: one Newton step (compare eqs. (12), (63))",
             nf.theta_newton),
        )),
    ]
    proved = []
    for name, statement, lhs, rhs in proofs():
        # The object is the verdict itself: True means proved identical.
        proved.append((name, f"{statement} [proved: {_proof_note(name, lhs, rhs)}]", sp.S.true))
    steps.append(Step("07_proofs", "Identities proved by the exact checker", tuple(proved)))
    # Their signs and exponent comparisons are decided when the conditions are built
    # (a failure raises); their identities are in 07_proofs.
    steps.append(Step("08_necessity", "Necessary conditions for stability, for every delay d",
                      necessity.objects()))
    return steps


def write(out_dir, files):
    """Write ``files`` (``{name: text}``) into ``out_dir`` atomically, file by file."""
    out = pathlib.Path(out_dir)
    for name, text in sorted(files.items()):
        write_bytes(out / name, text.encode("utf-8"))
    return sorted(out / name for name in files)


#: Glob patterns of the files :func:`render` owns in its folder (for drift).
OWNED = ("[0-9][0-9]_*.json", "[0-9][0-9]_*.tex")


def check(out_dir, files, *, owned=OWNED):
    """Return the paths in ``out_dir`` that differ from ``files`` or are extra.

    ``owned`` are the glob patterns of the files a generator writes in
    ``out_dir``: one that matches and is not in ``files`` (a former step's
    output) is drift too.
    """
    out = pathlib.Path(out_dir)
    stale = []
    for name, text in sorted(files.items()):
        path = out / name
        if not path.is_file() or path.read_text(encoding="utf-8") != text:
            stale.append(str(path))
    if out.is_dir():
        extra = {path for pattern in owned for path in out.glob(pattern)
                 if path.is_file() and path.name not in files}
        stale += sorted(str(path) for path in extra)
    return stale
