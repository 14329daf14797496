"""The derivation notebooks in ``derivations/``: stored clean, and they run.

Each notebook walks through one derivation step by calling :mod:`symstab`
and :mod:`paper_checks` (it derives nothing of its own) and asserts the
audit's verdicts as it goes, so executing it is a test of both the library
and the narrative; ``08`` walks one loop of ``examples/loops/``
through :class:`symstab.Loop` and asserts its answers against
python-control's poles; ``09`` answers the velocity filter's cut-off
question (linear model against simulation with the encoder) and asserts
its answer.  The notebooks are stored without outputs; these tests
execute them in a fresh ``python3`` kernel with nbclient and fail on any cell
error.  The execution tests are skipped when nbclient or ipykernel is not
installed; the storage tests only need the standard library.
"""

import json
import pathlib

import pytest

DERIVATIONS = pathlib.Path(__file__).resolve().parents[1] / "derivations"

#: The notebooks, one per derivation step, in order; then any loop.
EXPECTED = (
    "01_zoh_plant.ipynb",
    "02_characteristic_polynomial.ipynb",
    "03_unit_circle_split.ipynb",
    "04_boundary_and_coefficients.ipynb",
    "05_theta_max.ipynb",
    "06_small_theta_limits.ipynb",
    "07_code_generation.ipynb",
    "08_any_loop.ipynb",
    "09_cutoff.ipynb",
)

KERNELSPEC = {"name": "python3", "display_name": "Python 3", "language": "python"}


def _load(name):
    with open(DERIVATIONS / name, encoding="utf-8") as fh:
        return json.load(fh)


def test_the_notebooks_exist_in_order():
    found = tuple(sorted(path.name for path in DERIVATIONS.glob("*.ipynb")))
    assert found == EXPECTED


@pytest.mark.parametrize("name", EXPECTED)
def test_notebook_is_stored_clean(name):
    nb = _load(name)
    assert nb["nbformat"] == 4
    assert nb["metadata"].get("kernelspec") == KERNELSPEC
    code = [cell for cell in nb["cells"] if cell["cell_type"] == "code"]
    assert code, f"{name} has no code cells"
    for index, cell in enumerate(nb["cells"]):
        if cell["cell_type"] != "code":
            continue
        assert cell.get("outputs") == [], f"{name}: cell {index} has stored outputs"
        assert cell.get("execution_count") is None, f"{name}: cell {index} has an execution count"
    assert nb["cells"][0]["cell_type"] == "markdown", f"{name} does not open with prose"


def _notebook_client():
    reason = "nbclient and ipykernel are needed to execute the notebooks (pip install nbclient ipykernel)"
    pytest.importorskip("nbclient", reason=reason)
    pytest.importorskip("ipykernel", reason=reason)
    pytest.importorskip("nbformat", reason=reason)
    import nbclient

    return nbclient


@pytest.mark.parametrize("name", EXPECTED)
def test_notebook_executes_without_errors(name, tmp_path, monkeypatch):
    nbclient = _notebook_client()
    import nbformat

    # The kernel inherits the environment: a loop's generated kernels go to a
    # temporary cache, not to the user's ~/.cache.
    monkeypatch.setenv("SYMSTAB_CACHE_DIR", str(tmp_path / "cache"))
    nb = nbformat.read(DERIVATIONS / name, as_version=4)
    client = nbclient.NotebookClient(nb, timeout=300, kernel_name="python3",
                                     resources={"metadata": {"path": str(DERIVATIONS)}})
    try:
        client.execute()
    except nbclient.exceptions.CellExecutionError as exc:
        pytest.fail(f"{name}: a cell raised\n{exc}", pytrace=False)
    errors = [output for cell in nb.cells if cell.cell_type == "code"
              for output in cell.outputs if output.output_type == "error"]
    assert not errors, f"{name}: error outputs {errors}"
