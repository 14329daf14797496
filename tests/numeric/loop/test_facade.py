"""Loop is the model; its questions are module functions the methods pass through to."""

import inspect

import numpy as np

import symstab
from symstab.numeric.loop import evaluation, plane
from symstab.numeric.loop.evaluation import LoopEvaluation


def _loop():
    return symstab.Loop("1/(m*s**2 + b*s)", "K + B*(z - 1)/(T*z)", plane=("B", "K"),
                        values=dict(m=0.0128, b=0.0324, T=1e-3, d=3))


def test_the_plane_questions_are_module_functions_of_the_loop(loop_cache_dir):
    loop = _loop()
    assert plane.region(loop).x_range == loop.region().x_range
    assert plane.limits(loop).y_max == loop.limits().y_max
    assert plane.stable_intervals(loop, "K", B=0.05) == loop.stable_intervals("K", B=0.05)
    assert np.array_equal(plane.boundary(loop, n=50).theta, loop.boundary(n=50).theta)


def test_chi_in_floats_is_the_evaluation_the_loop_holds(loop_cache_dir):
    loop = _loop()
    assert isinstance(loop.evaluation, LoopEvaluation) and loop.evaluation.loop is loop
    K = np.array([10.0, 100.0, 1e5])
    assert evaluation.classify(loop, K=K, B=0.05).tolist() == loop.classify(K=K, B=0.05).tolist()
    counts = evaluation.unstable_root_counts(loop, K=K, B=0.05)
    assert counts.tolist() == loop.unstable_root_counts(K=K, B=0.05).tolist()
    assert counts[0] == 0 and counts[-1] > 0


def test_every_question_method_is_a_short_pass_through():
    """A question's method is a few lines that say "See" the function that holds its numpydoc."""
    for name in ("region", "robust_region", "stable_intervals", "limits", "boundary",
                 "passive_region", "simulate", "stability_map", "simulated_limit", "design",
                 "stability_probability", "classify", "spectral_radius", "is_stable",
                 "unstable_root_counts", "difference_equations", "friction_spaces"):
        method = getattr(symstab.Loop, name)
        assert "See :func:`symstab.numeric." in inspect.getdoc(method), name
        body = inspect.getsource(method).split('"""')[-1]
        code = [line for line in body.splitlines() if line.strip()]
        assert len(code) <= 10, (name, len(code))
