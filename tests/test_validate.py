"""Tests of symstab._validate: one place for kind and range checks."""

import fractions
import io
import math

import numpy as np
import pytest

from symstab._validate import check_delay, check_delay_samples, check_real

from conftest import assert_message_names

# check_real ---------------------------------------------------------------

@pytest.mark.parametrize("value, expected", [
    (0, 0.0), (3, 3.0), (-2.5, -2.5), (np.float64(1.25), 1.25), (np.int32(7), 7.0),
    (fractions.Fraction(1, 4), 0.25), (1e300, 1e300),
])
def test_check_real_accepts_finite_reals_and_returns_float(value, expected):
    result = check_real("x", value)
    assert type(result) is float
    assert result == expected


@pytest.mark.parametrize("value", ["1.0", None, 1 + 0j, [1.0], True, False, np.bool_(True)])
def test_check_real_rejects_non_reals_with_type_error(value):
    with pytest.raises(TypeError) as excinfo:
        check_real("kappa", value)
    assert_message_names(excinfo, "kappa")


@pytest.mark.parametrize("value", [math.nan, math.inf, -math.inf, np.float64("nan")])
def test_check_real_rejects_non_finite_with_value_error(value):
    with pytest.raises(ValueError) as excinfo:
        check_real("kappa", value)
    assert_message_names(excinfo, "kappa")


@pytest.mark.parametrize("value, bounds, ok", [
    (0.0, dict(low=0.0), True),
    (0.0, dict(low=0.0, low_open=True), False),
    (-1e-300, dict(low=0.0), False),
    (1.0, dict(high=1.0), True),
    (1.0, dict(high=1.0, high_open=True), False),
    (2.0, dict(low=-1.0, high=1.0), False),
    (0.5, dict(low=-1.0, high=1.0, low_open=True, high_open=True), True),
])
def test_check_real_enforces_range(value, bounds, ok):
    if ok:
        assert check_real("x", value, **bounds) == value
    else:
        with pytest.raises(ValueError, match=r"x must be a finite real number"):
            check_real("x", value, **bounds)


def test_check_real_message_states_allowed_range():
    with pytest.raises(ValueError) as excinfo:
        check_real("m", -1.0, low=0.0, low_open=True)
    assert "> 0" in str(excinfo.value) and "-1.0" in str(excinfo.value)


def test_check_real_huge_integer_raises_value_error():
    with pytest.raises(ValueError):
        check_real("m", 10**400)


# check_delay --------------------------------------------------------------

@pytest.mark.parametrize("d, expected", [
    (0, 0), (3, 3), (3.0, 3), (np.int64(12), 12), (np.float64(40.0), 40), (10_000, 10_000),
])
def test_check_delay_accepts_non_negative_integers(d, expected):
    result = check_delay(d)
    assert type(result) is int and result == expected


@pytest.mark.parametrize("d", [-1, -3.0, 2.5, math.nan, math.inf, fractions.Fraction(5, 2)])
def test_check_delay_rejects_bad_values_naming_d(d):
    with pytest.raises(ValueError) as excinfo:
        check_delay(d)
    assert_message_names(excinfo, "d")
    assert "non-negative integer" in str(excinfo.value)


@pytest.mark.parametrize("d", ["3", None, True, 2j])
def test_check_delay_rejects_non_numbers_with_type_error(d):
    with pytest.raises(TypeError):
        check_delay(d)


def test_check_delay_uses_given_name():
    with pytest.raises(ValueError) as excinfo:
        check_delay(-2, name="lag")
    assert_message_names(excinfo, "lag")


# check_delay_samples ----------------------------------------------------

@pytest.mark.parametrize("Td, T, expected", [
    (40e-3, 1e-3, 40),      # 40.00000000000001 in floating point
    (0.0, 1e-3, 0),
    (3e-4, 1e-4, 3),        # 2.9999999999999996
    (0.7, 0.1, 7),          # 6.999999999999999
])
def test_check_delay_samples_rounds_float_ratios(Td, T, expected):
    assert check_delay_samples(Td / T) == expected


@pytest.mark.parametrize("ratio", [1.5, 40.001, -1.0, math.nan, math.inf])
def test_check_delay_samples_rejects_non_whole_ratios(ratio):
    with pytest.raises(ValueError) as excinfo:
        check_delay_samples(ratio)
    assert "Td / T" in str(excinfo.value)


def test_check_delay_refuses_more_than_the_limit_naming_it(monkeypatch):
    with pytest.raises(ValueError, match=r"delay d must be an integer from 0 to 10000.*SYMSTAB_MAX_DELAY"):
        check_delay(1e20)
    monkeypatch.setenv("SYMSTAB_MAX_DELAY", "20000")
    assert check_delay(20_000) == 20_000
    with pytest.raises(ValueError, match="from 0 to 20000"):
        check_delay(20_001)
    monkeypatch.setenv("SYMSTAB_MAX_DELAY", "lots")
    with pytest.raises(ValueError, match="SYMSTAB_MAX_DELAY must be a positive whole number"):
        check_delay(3)


@pytest.mark.parametrize("value, ok", [(0.0, True), (1e6, True), (-1e-300, False), (1.0000001e6, False)])
def test_check_delta_accepts_zero_up_to_the_limit(value, ok):
    from symstab._validate import check_delta
    if ok:
        assert check_delta(value) == value
    else:
        with pytest.raises(ValueError, match=r"delta must be a finite real number >= 0 and <= 1e\+06"):
            check_delta(value)


def test_a_ragged_list_is_refused_naming_the_parameter():
    from symstab._validate import check_array

    with pytest.raises(ValueError, match="alpha must be a real number or a rectangular array"):
        check_array("alpha", [[1.0, 2.0], [3.0]])


# check_progress (issue 40 item 16: progress=True raised "'bool' object is not callable") ---

def test_check_progress_normalises_every_kind():
    from symstab._validate import check_progress

    bar = object()
    assert check_progress(None) is None and check_progress(False) is None
    assert check_progress(np.False_, lambda: bar) is None
    assert check_progress(True, lambda: bar) is bar and check_progress(np.True_, lambda: bar) is bar
    assert check_progress(True) is None        # a caller without a bar
    assert check_progress(print) is print
    for wrong in (1, 0, "yes", 2.0):
        with pytest.raises(TypeError, match="progress must be True, False, None or a callable"):
            check_progress(wrong)


def _progress_calls():
    """Every public function with a ``progress`` argument, as ``call(progress)``, small and fast."""
    import symstab
    from symstab.numeric.analysis.design import maximize_box, maximize_scalar

    loop = symstab.Loop("1/(m*s**2 + b*s)", "K + B*(z - 1)/(T*z)",
                        values=dict(m=0.0128, b=0.0324, T=1e-3, d=1, K=100.0, B=0.1),
                        plane=("B", "K"))
    return {
        "maximize_scalar": lambda p: maximize_scalar(lambda x: -(x - 0.3) ** 2, 0.0, 1.0, n=5,
                                                     progress=p),
        "maximize_box": lambda p: maximize_box(lambda v: -sum((x - 0.3) ** 2 for x in v),
                                               [(0.0, 1.0), (0.0, 1.0)], n=3, progress=p),
        "simulate": lambda p: symstab.simulate(alpha=0.1, beta=0.1, gamma=0.0, d=1, delta=0.1,
                                               steps=50, progress=p),
        "stability_map": lambda p: symstab.stability_map(alpha=[0.1], beta=[0.1], gamma=0.0, d=1,
                                                         delta=0.1, steps=50, progress=p),
        "Loop.simulate": lambda p: loop.simulate(steps=50, progress=p),
        "Loop.stability_map": lambda p: loop.stability_map([0.1], [100.0], steps=50, progress=p),
        "Loop.stability_probability": lambda p: loop.stability_probability(
            [0.1], [100.0], uncertain={"b": (0.03, 0.035)}, samples=4, progress=p),
        "Loop.robust_region": lambda p: loop.robust_region(uncertain={"b": (0.03, 0.031)},
                                                           strips=2, progress=p),
    }


@pytest.mark.parametrize("name", sorted(_progress_calls()))
def test_every_progress_argument_takes_true_false_none_or_a_callable(name, loop_cache_dir):
    call = _progress_calls()[name]
    done = []
    # None (and False, its equal here) is every other test's default.
    results = [call(p) for p in (True, done.append)]
    assert done, f"{name}: the callable was never called"
    assert type(results[0]) is type(results[1])
    with pytest.raises(TypeError, match="progress must be True, False, None or a callable"):
        call(1)


class _KernelStream(io.StringIO):
    """A stand-in for ipykernel's output stream: not a terminal, and ipykernel's by its module."""


_KernelStream.__module__ = "ipykernel.iostream"


def test_a_progress_bar_draws_in_a_notebook_and_not_in_a_pipe(monkeypatch):
    """Issue 42, item 5: in Jupyter (stderr is ipykernel's stream, not a terminal) progress=True
    drew nothing; a pipe or a log file still gets nothing."""
    from symstab import _progress

    monkeypatch.setattr(_progress, "_notebook_bar", lambda *args: None)   # without tqdm
    notebook, pipe = _KernelStream(), io.StringIO()
    for stream in (notebook, pipe):
        update = _progress.progress_printer("scanning", 4, stream=stream, min_seconds=0.0)
        for done in range(1, 5):
            update(done)
    assert "\rscanning [" in notebook.getvalue() and "100.0%" in notebook.getvalue()
    assert pipe.getvalue() == ""


def test_a_notebook_bar_is_tqdm_s_when_tqdm_is_installed(monkeypatch):
    from symstab import _progress

    calls = []
    monkeypatch.setattr(_progress, "_notebook_bar", lambda *args: calls.append(args) or print)
    assert _progress.progress_printer("scanning", 4, stream=_KernelStream()) is print
    assert calls == [("scanning", 4, 2.0)]
