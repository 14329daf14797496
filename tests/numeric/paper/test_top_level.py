"""The names code written against the first release imports from ``symstab`` itself."""

import numpy as np
import pytest

import symstab
import symstab.numeric.paper.simulate as simulate_module
import symstab.numeric.simulation.simulator as simulator_module


@pytest.mark.parametrize("name, home", [("simulate", simulate_module),
                                        ("stability_map", simulate_module),
                                        ("Nonidealities", simulator_module),
                                        ("Simulation", simulator_module),
                                        ("StabilityMap", simulator_module)])
def test_simulation_api_is_exported_at_the_top_level(name, home):
    assert name in symstab.__all__
    assert getattr(symstab, name) is getattr(home, name)


def test_first_release_call_runs_from_the_top_level():
    # The first release's spelling: symstab.stability_map with the
    # non-idealities of a real device.  A stiff, well damped point of the
    # paper's device at d = 0 decays with or without the velocity filter.
    device = symstab.PAPER_DEVICE
    found = symstab.stability_map(alpha=[device.alpha(30.0)], beta=[device.beta(1.0)], gamma=0.0,
                                  d=0, delta=None, steps=400, x0=0.01, device=device,
                                  nonideal=symstab.Nonidealities(velocity_cutoff=50.0))
    assert isinstance(found, symstab.StabilityMap)
    assert found.stable.shape == (1, 1) and bool(found.stable[0, 0])
    run = symstab.simulate(alpha=0.0, beta=0.0, gamma=0.0, d=0, delta=0.1, steps=8)
    assert isinstance(run, symstab.Simulation) and np.shape(run.stable) == ()


def test_modules_are_attributes_whatever_was_used_first():
    """From a review: with the names loaded on first use, ``symstab.numeric.paper.stability`` failed
    after ``symstab.Device`` (which imports ``symstab.numeric`` but not its other modules)."""
    import subprocess
    import sys

    code = ("import symstab; symstab.Device; "
            "print(symstab.numeric.paper.stability.unstable_root_counts.__name__, "
            "symstab.symbolic.boundary.boundary.__name__, hasattr(symstab.numeric, 'nothing'))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert out.stdout.split() == ["unstable_root_counts", "boundary", "False"], out.stderr
