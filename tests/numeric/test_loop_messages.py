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


@pytest.mark.parametrize("plant, values, says", [
    # issue 40 item 16: "cancels beyond 5000 digits: a parameter is too small or too large"
    ("1/((m + m_h)*s**2 + (b + b_h)*s + k_h)",
     dict(m=0.0128, m_h=0.05, b=0.0324, b_h=1.0, k_h=0.0),
     "degenerate at k_h = 0: the factor k_h + s**2*(m + m_h) + s*(b + b_h) has a pole at s = 0"),
    ("1/((m + m_h)*s**2 + (b + b_h)*s + k_h)",      # critically damped: (b + b_h)^2 = 4 (m + m_h) k_h
     dict(m=0.5, m_h=0.5, b=1.0, b_h=1.0, k_h=1.0),
     "degenerate at b = 1, b_h = 1, k_h = 1, m = 0.5, m_h = 0.5: the factor "
     "k_h + s**2*(m + m_h) + s*(b + b_h) has a double pole"),
    ("1/(m*s**2 + b*s)", dict(m=0.0128, b=0.0),
     "degenerate at b = 0: the factor b + m*s has a pole at s = 0"),
])
def test_a_plant_whose_poles_meet_names_the_parameter_and_why(plant, values, says):
    loop = symstab.Loop(plant, "K + B*(z - 1)/(T*z)")
    with pytest.raises(ValueError) as info:
        loop.classify(K=100.0, B=0.5, T=1e-3, d=1, **values)
    message = str(info.value)
    assert says in message, message
    assert "residues at distinct poles" in message and "cancels beyond" not in message
