"""How a loop that cannot be closed is refused: the message says what is wrong."""

import re

import pytest

import symstab

PAPER_VE = "K + B*(z - 1)/(T*z)"


@pytest.mark.parametrize("plant, environment, message", [
    # The first release's wording ("degree of numerator 1 <= degree of
    # denominator 0") stated the condition that fails as if it held.
    ("s", PAPER_VE, "plant G(s) must be proper: the degree of its numerator in s (1) exceeds "
                    "that of its denominator (0); got s"),
    ("1/(m*s**2 + b*s)", "K*z**2/(z - 1)",
     "environment VE(z) must be proper: the degree of its numerator in z (2) exceeds that of "
     "its denominator (1); got K*z**2/(z - 1)"),
])
def test_improper_says_which_degree_exceeds_which(plant, environment, message):
    with pytest.raises(ValueError, match=f"^{re.escape(message)}$"):
        symstab.Loop(plant, environment)


@pytest.mark.parametrize("plant, values", [
    # issue 40 item 16: refused as "cancels beyond 5000 digits: a parameter is too small or too
    # large"; the closed form's residues are 0/0 where poles meet, the realisation is its limit.
    ("1/((m + m_h)*s**2 + (b + b_h)*s + k_h)",      # k_h = 0: a pole on the hold's pole at 0
     dict(m=0.0128, m_h=0.05, b=0.0324, b_h=1.0, k_h=0.0)),
    ("1/((m + m_h)*s**2 + (b + b_h)*s + k_h)",      # critically damped: a double pole
     dict(m=0.5, m_h=0.5, b=1.0, b_h=1.0, k_h=1.0)),
    ("1/(m*s**2 + b*s)", dict(m=0.0128, b=0.0)),
])
def test_a_plant_whose_poles_meet_is_its_limit(plant, values):
    """The spectral radius where poles meet: python-control's c2d of the plant at those values."""
    control = pytest.importorskip("control")
    loop = symstab.Loop(plant, PAPER_VE)
    m, b = values["m"] + values.get("m_h", 0.0), values["b"] + values.get("b_h", 0.0)
    G = control.sample_system(control.tf([1], [m, b, values.get("k_h", 0.0)]), 1e-3, "zoh")
    z = control.tf([1, 0], [1], 1e-3)
    for K, B in ((100.0, 0.5), (3000.0, 2.0), (1e5, 10.0)):
        oracle = max(abs(control.feedback(G, (K + B * (z - 1) / (1e-3 * z)) * z**-1).poles()))
        radius = loop.spectral_radius(K=K, B=B, T=1e-3, d=1, **values)
        assert radius == pytest.approx(oracle, rel=1e-7), (K, B)


@pytest.mark.parametrize("plant, values, says", [
    ("1/((m + m_h)*s**2 + (b + b_h)*s + k_h)", dict(m=0.05, m_h=-0.05, b=0.0324, b_h=1.0, k_h=2.0),
     "degenerate at m = 0.05, m_h = -0.05: the factor k_h + s**2*(m + m_h) + s*(b + b_h) loses "
     "its leading coefficient (the plant's order drops)"),
    ("1/(m*s**2 + b*s)", dict(m=0.0, b=0.0324),
     "degenerate at m = 0: the factor b + m*s loses its leading coefficient"),
])
def test_a_plant_whose_order_drops_names_the_parameter_and_why(plant, values, says):
    loop = symstab.Loop(plant, PAPER_VE)
    with pytest.raises(ValueError) as info:
        loop.classify(K=100.0, B=0.5, T=1e-3, d=1, **values)
    message = str(info.value)
    assert says in message, message
    assert "cancels beyond" not in message
