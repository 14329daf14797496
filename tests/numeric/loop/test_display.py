"""A loop in Jupyter shows its model and its characteristic equation (issue 42, item 5)."""

import symstab
from symstab.numeric.loop.display import loop_latex

from conftest import REPO


def test_the_paper_loop_shows_its_characteristic_equation():
    shown = symstab.PAPER_LOOP._repr_latex_()
    assert shown.startswith("$$") and shown.endswith("$$")
    assert r"G(s) &= \frac{1}{b s + m s^{2}}" in shown
    # VE(z) T**2 z**2, multiplied out by hand: (B T + K T**2 + M) z**2 - (B T + 2 M) z + M.
    assert r"\left(B T + K T^{2} + M\right) z^{2} + \left(- B T - 2 M\right) z + M" in shown
    assert r"\chi(z) &= z^{d} \left(T^{2} z^{2}\right)" in shown and shown.count("= 0") == 1


def test_a_plant_discretised_numerically_says_so():
    shown = symstab.load_loop(REPO / "examples" / "loops" / "two_mass.toml")._repr_latex_()
    assert r"\mathcal{Z}\{\mathrm{ZOH}\; G(s)\}" in shown and r"P_d(z)" in shown


def test_polynomials_are_written_highest_power_first_with_signs():
    shown = loop_latex(symstab.PAPER_LOOP.plant, symstab.PAPER_LOOP.environment,
                       ([1, 0, -2], [3, 1]))
    assert r"z^{d} \left(3 z + 1\right)" in shown and r"\left(z^{2} - 2\right)" in shown
