"""Units in loop files are converted to SI with pint, or refused (issue 18, item 3).

The oracle of each conversion test is the same loop written in SI: a file
whose values are given in ms, kHz, g, g/s, N s/mm, kN/m, N/mm or g cm^2
must give the answer (root counts, spectral radius, the stable K interval)
of the SI file, and the ms file must match python-control's poles of the
loop built at T = 0.25 ms.  Each of these failed before the conversion:
the value was taken as SI and the unit kept as a label.
"""

import math
import re
import sys

import numpy as np
import pytest

if sys.version_info >= (3, 11):
    import tomllib
else:   # pragma: no cover - Python 3.10
    import tomli as tomllib

from symstab import Loop
from symstab.numeric.loop.files import load_loop, parse_loop_text
from symstab.numeric.loop.quantities import check_bounds, unit_info

from conftest import REPO, manual_text
from oracles import eq1_virtual_environment_tf

pytestmark = pytest.mark.usefixtures("loop_cache_dir")

EXAMPLES = REPO / "examples" / "loops"
#: The paper's loop file in linear units (the file gives the paddle's rotary
#: ones): the base of the linear dimensions below, the same numbers.
PAPER_TEXT = ((EXAMPLES / "paper.toml").read_text(encoding="utf-8")
              .replace('"kg m^2"', '"kg"').replace('"N m s/rad"', '"N s/m"')
              .replace('"N m/rad"', '"N/m"'))
LOWPASS_TEXT = (EXAMPLES / "lowpass_velocity.toml").read_text(encoding="utf-8")


def _replace(text, old, new):
    assert old in text, old
    return text.replace(old, new)


def _paper(**entries):
    """The paper's loop file with some [parameters] lines replaced: name -> TOML value."""
    text = PAPER_TEXT
    for name, entry in entries.items():
        text = re.sub(rf"(?m)^{name} = .*$", f"{name} = {entry}", text)
    return text


def _answers(loop, **values):
    """What the loop says at its defaults (and ``values``): the quantities compared."""
    return (np.atleast_1d(loop.unstable_root_counts(**values)).tolist(),
            float(loop.spectral_radius(**values)),
            loop.stable_intervals("K", **{k: v for k, v in values.items() if k != "K"}))


def _same(a, b):
    counts_a, radius_a, runs_a = a
    counts_b, radius_b, runs_b = b
    assert counts_a == counts_b
    assert radius_a == pytest.approx(radius_b, rel=1e-12)
    assert len(runs_a) == len(runs_b)
    for (lo_a, hi_a), (lo_b, hi_b) in zip(runs_a, runs_b, strict=True):
        assert lo_a == pytest.approx(lo_b, rel=1e-9, abs=1e-12)
        assert hi_a == pytest.approx(hi_b, rel=1e-9)


# One test per dimension: (what, the non-SI file, the SI file, values at which to compare).
ROTARY_SI = _paper(m='{ value = 0.0128, unit = "kg m^2" }', b='{ value = 0.0324, unit = "N m s/rad" }',
                   K='{ value = 2.0, unit = "N m/rad" }', B='{ value = 0.1, unit = "N m s/rad" }',
                   M='{ value = 0.0, unit = "kg m^2" }')
DIMENSIONS = {
    "time (ms)": (_paper(T='{ value = 0.25, unit = "ms" }'),
                  _paper(T='{ value = 2.5e-4, unit = "s" }'), dict(d=1)),
    "frequency (kHz)": (_replace(LOWPASS_TEXT, 'value = 50.0, unit = "Hz"', 'value = 0.1, unit = "kHz"'),
                        _replace(LOWPASS_TEXT, 'value = 50.0, unit = "Hz"', 'value = 100.0, unit = "Hz"'),
                        dict(d=1)),
    "mass (g)": (_paper(m='{ value = 12.8, unit = "g" }', M='{ value = 6.4, unit = "g" }'),
                 _paper(M='{ value = 0.0064, unit = "kg" }'), dict(d=4)),
    "damping (g/s, N s/mm)": (_paper(b='{ value = 32.4, unit = "g/s" }',
                                     B='{ value = 1e-4, unit = "N s/mm" }'), PAPER_TEXT, dict(d=4)),
    "stiffness (kN/m)": (_paper(K='{ value = 0.002, unit = "kN/m" }'), PAPER_TEXT, dict(d=4)),
    "stiffness (N/mm)": (_paper(K='{ value = 0.002, unit = "N/mm" }'), PAPER_TEXT, dict(d=4)),
    "inertia (g cm^2, rotary)": (_replace(ROTARY_SI, 'value = 0.0128, unit = "kg m^2"',
                                          'value = 128000, unit = "g cm^2"'), ROTARY_SI, dict(d=4)),
}


@pytest.mark.parametrize("what", list(DIMENSIONS))
def test_a_non_si_unit_gives_the_answer_of_the_si_file(what):
    converted, si, values = DIMENSIONS[what]
    loop, reference = parse_loop_text(converted), parse_loop_text(si)
    for name, value in reference.defaults.items():
        assert loop.defaults[name] == pytest.approx(value, rel=1e-15), name
    assert loop.units == reference.units       # the values are in SI, and so say the labels
    _same(_answers(loop, **values), _answers(reference, **values))


def test_milliseconds_match_python_controls_poles_at_a_quarter_millisecond():
    """The issue's file: T = 0.25 ms was computed as 0.25 s; python-control builds the loop at 2.5e-4 s."""
    import control

    loop = parse_loop_text(_paper(T='{ value = 0.25, unit = "ms" }'))
    m, b, T, d = 0.0128, 0.0324, 2.5e-4, 1
    for K, B in ((300.0, 0.5), (3000.0, 2.0), (60000.0, 1.0)):
        G = control.c2d(control.tf([1], [m, b, 0]), T, "zoh")
        VE = eq1_virtual_environment_tf(K, B, 0.0, T)
        closed = control.feedback(G, VE * control.tf([1], [1] + [0] * d, T))
        expected = max(abs(p) for p in closed.poles())
        assert float(loop.spectral_radius(K=K, B=B, d=d)) == pytest.approx(expected, rel=1e-9)
        assert bool(loop.is_stable(K=K, B=B, d=d)) == (expected < 1)


def test_milliseconds_give_the_si_files_K_max():
    converted = parse_loop_text(_paper(T='{ value = 0.25, unit = "ms" }'))
    reference = parse_loop_text(_paper(T='{ value = 2.5e-4, unit = "s" }'))
    a, b = converted.limits(d=1), reference.limits(d=1)
    assert a.y_max == pytest.approx(b.y_max, rel=1e-9) and a.y_max > 1e4   # 0.12 N/m when T was 0.25 s


# --------------------------------------------------------------------------
# Refused, naming the parameter, the unit given and the one expected


@pytest.mark.parametrize("entries, match", [
    # wrong dimension, found by the loop's dimensions
    (dict(K='{ value = 2.0, unit = "kg" }'), r"parameter 'K' has unit 'kg'.* needs N/m there"),
    (dict(m='{ value = 0.0128, unit = "N/m" }'), r"parameter 'm' has unit 'N/m'.* needs kg there"),
    (dict(B='{ value = 0.1, unit = "N/m" }'), r"parameter 'B' has unit 'N/m'.* needs N s/m there"),
    (dict(T='{ value = 1.0, unit = "kg" }'), r"parameter 'T' has unit 'kg'.*a time"),
    (dict(d='{ value = 40, unit = "ms" }'), r"parameter 'd' has unit 'ms'.*samples"),
    # a linear stiffness in an otherwise rotary loop
    (dict(m='{ value = 0.0128, unit = "kg m^2" }', b='{ value = 0.0324, unit = "N m s/rad" }',
          B='{ value = 0.1, unit = "N m s/rad" }', M='{ value = 0.0, unit = "kg m^2" }'),
     r"parameter 'K' has unit 'N/m'.* needs N m/rad there"),
    # unknown to pint, an offset unit, an angular frequency
    (dict(K='{ value = 2.0, unit = "Nm_per_furlong" }'), r"parameter 'K': unit 'Nm_per_furlong' is not a "
                                                         r"unit a loop file may name"),
    (dict(K='{ value = 2.0, unit = "degC" }'), r"parameter 'K': unit 'degC' is not a unit a loop "
                                               r"file may name: pint reads 'degC' as degree_Celsius"),
    (dict(K='{ value = 2.0, unit = "" }'), r"parameter 'K'.*empty"),
    (dict(K='{ value = 2.0, unit = "m**10**10" }'), r"parameter 'K'.*exponent"),
])
def test_a_wrong_or_unknown_unit_is_refused_naming_the_parameter(entries, match):
    with pytest.raises(ValueError, match=match) as info:
        parse_loop_text(_paper(**entries), source="my_device.toml")
    assert str(info.value).startswith("my_device.toml: ")


def test_an_angular_frequency_is_refused_not_read_as_hertz():
    text = _replace(LOWPASS_TEXT, 'value = 50.0, unit = "Hz"', 'value = 314.159, unit = "rad/s"')
    with pytest.raises(ValueError, match=r"parameter 'f_c' has unit 'rad/s', an angular frequency"):
        parse_loop_text(text)


def test_a_wrong_mass_is_found_by_the_loop_even_where_the_plant_alone_cannot_tell():
    """m s^2 + b s disagree; VE(z) must be a stiffness, so G(s) is 1/(N/m): m is the wrong one."""
    text = _paper(m='{ value = 0.0128, unit = "N/m" }', K="2.0", B="0.1", M="0.0")
    with pytest.raises(ValueError, match=r"parameter 'm' has unit 'N/m'.*it needs kg there.*"
                                         r"b\*s \(kg s\^-2\) and m\*s\*\*2 \(kg s\^-4\) are added"):
        parse_loop_text(text)


def test_two_units_that_do_not_fit_together_name_both():
    """A rotary inertia with a linear friction: either could be the wrong one (VE is bare)."""
    text = _paper(m='{ value = 0.0128, unit = "kg m^2" }', K="2.0", B="0.1", M="0.0")
    with pytest.raises(ValueError, match=r"the units of b \('N s/m'\), m \('kg m\^2'\) do not "
                                         r"fit together.*b would need N m s/rad; m would need kg"):
        parse_loop_text(text)


def test_a_plant_that_is_not_force_to_displacement_is_refused_saying_so():
    """Each term of m s^3 + b s^2 + k s + c agrees, but G(s) is then s^3/kg, not m/N."""
    text = _paper(b='{ value = 0.0324, unit = "kg/s" }').replace(
        'plant = "1/(m*s**2 + b*s)"', 'plant = "1/(m*s**3 + b*s**2 + k*s + c)"').replace(
        "[parameters]", '[parameters]\nk = { value = 50.0, unit = "N/m" }\n'
                        'c = { value = 10.0, unit = "N/(m s)" }')
    with pytest.raises(ValueError, match=r"the units of .* do not fit the loop \(the plant G\(s\) "
                                         r"is in kg\^-1 s\^3 and the environment VE\(z\) in "
                                         r"kg s\^-2: the loop gain VE\(z\) G\(s\) must have no unit"):
        parse_loop_text(text)
    bare = text.replace('K = { value = 2.0, unit = "N/m" }', "K = 2.0").replace(
        'B = { value = 0.1, unit = "N s/m" }', "B = 0.1").replace('M = { value = 0.0, unit = "kg" }',
                                                                 "M = 0.0")
    with pytest.raises(ValueError, match=r"the plant G\(s\) is in kg\^-1 s\^3, and must be in "
                                         r"m/N or rad/\(N m\)"):
        parse_loop_text(bare)


@pytest.mark.parametrize("unit", ["1e99999", "1e-99999 m", ';l""mbp\\+s#2@*', "10**10**10"])
def test_a_unit_that_is_no_size_or_no_unit_is_refused_with_a_value_error(unit):
    with pytest.raises(ValueError, match=r"parameter 'K'"):
        parse_loop_text(_paper(K=f"{{ value = 2.0, unit = '{unit}' }}"))


def test_a_bare_number_is_taken_in_si_and_unchecked():
    loop = parse_loop_text(_paper(K="2.0", T="0.001"))
    assert loop.defaults["K"] == 2.0 and "K" not in loop.units
    assert loop.file_parameters.dimensions["K"] == unit_info("N/m").dimensions   # implied by the loop


# --------------------------------------------------------------------------
# Bounds


def test_the_lowpass_file_bounds_its_cut_off_below_nyquist_with_the_simulators_wording():
    from symstab.numeric.simulation.simulator import Nonidealities

    loop = load_loop(EXAMPLES / "lowpass_velocity.toml")
    values = dict(loop.defaults, T=2.5e-4, f_c=3000.0)
    with pytest.raises(ValueError) as ours:
        check_bounds(loop.file_parameters, values, where="--set")
    with pytest.raises(ValueError) as simulator:
        Nonidealities(velocity_cutoff=3000.0).check(2.5e-4)
    # one threshold and one wording: "must be a finite real number > 0 and < 2000, got 3000.0"
    wording = str(simulator.value).split(" must be ", 1)[1]
    assert wording in str(ours.value) and "f_c must be" in str(ours.value)
    check_bounds(loop.file_parameters, dict(values, f_c=1999.0), where="--set")


def test_a_file_outside_its_own_bounds_is_refused():
    text = _replace(LOWPASS_TEXT, 'value = 50.0, unit = "Hz"', 'value = 0.6, unit = "kHz"')
    with pytest.raises(ValueError, match=r"f_c must be a finite real number > 0 and < 500, got 600\.0"):
        parse_loop_text(text)


@pytest.mark.parametrize("bound, match", [
    ('below = "1/(2*q)"', r"q is not a parameter of the loop"),
    ('below = "2*T"', r"bound below = '2\*T' of 'f_c' is in s, and f_c is in Hz"),
    ('below = "__import__(\'os\')"', r"is not allowed"),
    ('below = true', r"bound below of 'f_c' must be a number"),
])
def test_a_bound_that_is_not_a_bound_is_refused(bound, match):
    text = _replace(LOWPASS_TEXT, 'above = 0, below = "1/(2*T)"', bound)
    with pytest.raises(ValueError, match=match):
        parse_loop_text(text)


def test_a_numeric_bound_is_in_the_parameters_own_unit():
    text = _replace(LOWPASS_TEXT, 'value = 50.0, unit = "Hz", above = 0, below = "1/(2*T)"',
                    'value = 0.05, unit = "kHz", max = 0.2')
    loop = parse_loop_text(text)
    check_bounds(loop.file_parameters, dict(loop.defaults, f_c=200.0), where="x")
    with pytest.raises(ValueError, match=r"f_c must be a finite real number <= 200, got 201\.0"):
        check_bounds(loop.file_parameters, dict(loop.defaults, f_c=201.0), where="x")


# --------------------------------------------------------------------------
# Every unit of the example files and the README


#: The SI factor of each unit the examples and the README use, written out
#: here (not read from pint): a new unit in an example must be added.
FACTORS = {"kg": 1, "N s/m": 1, "s": 1, "Hz": 1, "N/m": 1, "samples": 1, "ms": 1e-3,
           "g": 1e-3, "N/mm": 1e3, "kN/m": 1e3, "g/s": 1e-3, "N s/mm": 1e3, "kHz": 1e3,
           "kg m^2": 1, "g cm^2": 1e-7, "N m s/rad": 1, "N m/rad": 1, "N m/deg": 180 / math.pi}


@pytest.mark.parametrize("path", sorted(EXAMPLES.glob("*.toml")), ids=lambda p: p.stem)
def test_every_unit_of_every_example_file_is_converted(path):
    data = tomllib.loads(path.read_text(encoding="utf-8"))
    loop = load_loop(path)
    for name, entry in data["parameters"].items():
        if not isinstance(entry, dict) or "unit" not in entry:
            continue
        assert entry["unit"] in FACTORS, (name, entry["unit"])
        expected = entry["value"] * FACTORS[entry["unit"]]
        assert loop.defaults[name] == pytest.approx(expected, rel=1e-15), name
        assert loop.file_parameters.values[name].unit == entry["unit"]



FACTORS.update({"us": 1e-6, "N mm/rad": 1e-3, "lbf/in": 4.4482216152605 / 0.0254})


@pytest.mark.parametrize("unit, why", [
    ("N/m%", "'%' has no place"),                       # pint: percent, K / 100
    ("N/m $alpha$", "'\\$' has no place"),                # LaTeX: pint would read the constant
    ("N/m # a comment", "'#' has no place"),          # pint: the rest is a comment
    ("N/m alpha", "pint reads 'alpha' as fine_structure_constant"),
    ("Nm", "pint reads 'Nm' as number_meter"),
    ("c", "pint reads 'c' as speed_of_light"),
    ("1000 N/m", "a number belongs in 'value'"),
])
def test_a_unit_pint_would_read_as_a_silent_factor_is_refused(unit, why):
    """pint reads these as N/m (or no unit) times a number; taken, K = 2 would become 0.02, 0.0146, ..."""
    with pytest.raises(ValueError, match=rf"parameter 'K': unit '{re.escape(unit)}' is not a unit "
                                         rf"a loop file may name: {why}"):
        parse_loop_text(_paper(K=f'{{ value = 2.0, unit = "{unit}" }}'))


def test_every_unit_in_the_readme_is_converted_or_said_to_be_refused():
    """The manual's units (the loop-file format, moved from the README to docs/guide/loop_files.md)."""
    readme = manual_text()
    units = set(re.findall(r'unit = "([^"]*)"', readme))
    assert {"ms", "g", "N/mm"} <= units
    refused = set(re.findall(r'unit = "([^"]*)"[^\n]*# refused', readme))
    assert {"kg", "degC", "rad/s"} <= refused
    listed = re.search(r"exponents \(`\^2`, `\*\*-1`\) — (.*?) — is converted", readme, re.S).group(1)
    named = set(re.findall(r"`([^`]+)`", listed))
    assert len(named) >= 10
    for unit in sorted((units | named) - refused - {"samples"}):
        assert unit in FACTORS, unit
        assert float(unit_info(unit).factor) == pytest.approx(FACTORS[unit], rel=1e-14), unit
    for unit in sorted(refused):
        with pytest.raises(ValueError, match=rf"parameter 'K'.*'{re.escape(unit)}'"):
            parse_loop_text(_paper(K=f'{{ value = 2.0, unit = "{unit}" }}'))


def test_the_readmes_loop_file_is_read_as_its_comments_say():
    """The example of the loop-file format (docs/guide/loop_files.md, once the README's)."""
    readme = (REPO / "docs" / "guide" / "loop_files.md").read_text(encoding="utf-8")
    block = re.search(r"^# Loop files.*?```toml\n(.*?)```", readme, re.S | re.M).group(1)
    loop = parse_loop_text(block, source="README")
    assert loop.name == "my_paddle" and loop.plane == ("B", "K")
    assert loop.defaults == pytest.approx({"m": 0.0128, "b": 0.0324, "T": 0.00025, "d": 1,
                                           "K": 2000.0, "B": 0.5}, rel=1e-15)
    assert loop.units == {"m": "kg", "b": "N s/m", "T": "s", "d": "samples", "K": "N/m"}
    with pytest.raises(ValueError, match=r"K must be a finite real number >= 0, got -1\.0"):
        check_bounds(loop.file_parameters, dict(loop.defaults, K=-1.0), where="--set")


@pytest.mark.parametrize("units, match", [
    ({"T": "ms"}, r"units: 'T' is given in 'ms', which is 0.001 s: Loop takes its values in SI"),
    ({"K": "N/mm"}, r"units: 'K' is given in 'N/mm', which is 1000 N/m"),
    ({"K": "kg"}, r"parameter 'K' has unit 'kg', which does not fit the loop"),
    ({"T": "deg"}, r"parameter 'T' has unit 'deg'.*a time"),
])
def test_the_python_loop_refuses_a_unit_it_would_only_print(units, match):
    """Loop(units=) computes with its values as given: a non-SI unit would label a wrong number."""
    with pytest.raises(ValueError, match=match):
        Loop("1/(m*s**2 + b*s)", "K + B*(z - 1)/(T*z)", values=dict(T=1e-3, K=2.0), units=units)


def test_the_python_loop_keeps_si_units():
    loop = Loop("1/(m*s**2 + b*s)", "K + B*(z - 1)/(T*z)", values=dict(T=1e-3),
                units={"K": "N/m", "T": "s", "m": "kg"})
    assert loop.units == {"K": "N/m", "T": "s", "m": "kg"}


@pytest.mark.parametrize("unit", ["N m/deg^2", "N m/rad^2", "N m rad"])
def test_a_files_unit_with_an_angle_to_another_power_is_refused(unit):
    """issue 40 item 7: a rotary stiffness is N m/rad; pint would take N m/deg^2 as (180/pi)^2 N m/rad."""
    text = _replace((EXAMPLES / "paper.toml").read_text(encoding="utf-8"),
                    'K = { value = 2.0, unit = "N m/rad"', f'K = {{ value = 2.0, unit = "{unit}"')
    with pytest.raises(ValueError, match=rf"parameter 'K' has unit {re.escape(repr(unit))}, whose "
                                         rf"angle is to the power .*K is in N m/rad"):
        parse_loop_text(text)


def test_a_files_unit_per_degree_is_converted_by_hand():
    text = _replace((EXAMPLES / "paper.toml").read_text(encoding="utf-8"),
                    'K = { value = 2.0, unit = "N m/rad"', 'K = { value = 2.0, unit = "N m/deg"')
    assert parse_loop_text(text).defaults["K"] == pytest.approx(2 * 180 / math.pi, rel=1e-15)
