"""The derivation notebooks in ``derivations/``: stored clean, and they run.

Each notebook walks through one derivation step by calling :mod:`symstab`
and :mod:`paper_checks` (it derives nothing of its own) and asserts the
audit's verdicts as it goes, so executing it is a test of both the library
and the narrative; ``08`` walks one loop of ``examples/loops/``
through :class:`symstab.Loop` and asserts its answers against
python-control's poles; ``09`` answers the velocity filter's cut-off
question (linear model against simulation with the encoder) and asserts
its answer.  The notebooks are stored without outputs; these tests
execute each top to bottom with nbclient and fail on any cell error.  They
share one ``python3`` kernel per test process, its namespace reset
(``%reset -f``) and its figures closed before each notebook, so a notebook
sees no name another defined; what stays is what a user's session keeps
too: the modules imported and the derivation cached in them (each notebook
re-derived the paper's loop in a kernel of its own: 8 kernel starts and
about half of the notebooks' time).  The execution tests are skipped when
nbclient or ipykernel is not installed; the storage tests only need the
standard library.
"""

import json
import os
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


#: Run before each notebook in the shared kernel: a clean namespace, no open figure.
_RESET = ("%reset -f\n"
          "import sys as _sys\n"
          "if 'matplotlib.pyplot' in _sys.modules:\n"
          "    _sys.modules['matplotlib.pyplot'].close('all')\n"
          "del _sys")


@pytest.fixture(scope="module")
def kernel(session_cache_dir):
    """One ``python3`` kernel for the notebooks of this process, started in ``derivations/``.

    It inherits the environment, with a loop's generated kernels going to
    the session's temporary cache (conftest's ``session_cache_dir``), not to
    the user's ~/.cache.
    """
    _notebook_client()
    from jupyter_client.manager import KernelManager

    cache = session_cache_dir
    manager = KernelManager(kernel_name="python3")
    manager.start_kernel(cwd=str(DERIVATIONS), env={**os.environ, "SYMSTAB_CACHE_DIR": str(cache)})
    yield manager
    manager.shutdown_kernel(now=True)


def _execute(nbclient, nb, manager):
    """Execute ``nb`` top to bottom in the kernel of ``manager``; close the client's channels."""
    client = nbclient.NotebookClient(nb, km=manager, timeout=300, kernel_name="python3",
                                     resources={"metadata": {"path": str(DERIVATIONS)}})
    try:
        client.execute()
    finally:
        if client.kc is not None:
            client.kc.stop_channels()


@pytest.mark.parametrize("name", EXPECTED)
def test_notebook_executes_without_errors(name, kernel):
    nbclient = _notebook_client()
    import nbformat

    if not kernel.is_alive():      # a notebook before this one ended the kernel
        kernel.restart_kernel(now=True)
    _execute(nbclient, nbformat.v4.new_notebook(cells=[nbformat.v4.new_code_cell(_RESET)]), kernel)
    nb = nbformat.read(DERIVATIONS / name, as_version=4)
    try:
        _execute(nbclient, nb, kernel)
    except nbclient.exceptions.CellExecutionError as exc:
        pytest.fail(f"{name}: a cell raised\n{exc}", pytrace=False)
    errors = [output for cell in nb.cells if cell.cell_type == "code"
              for output in cell.outputs if output.output_type == "error"]
    assert not errors, f"{name}: error outputs {errors}"
