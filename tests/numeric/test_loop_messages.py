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
