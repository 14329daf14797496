"""The package is laid out by layer, and no layer imports a layer above it.

From the bottom: the private base (``_project``, ``_resources``,
``_validate``, ``_generated``), ``symbolic`` (the derivation in SymPy),
``codegen`` (float-safe forms, printers, generated kernels), ``proof``
(the identity checker, every proof obligation, the derivation files),
``numeric`` (the numeric API on the kernels), and the front ends (``cli``,
``figures``, ``reproduce``).  ``paper_checks`` sits between the library and
the front ends: the front ends may import it, the library may not.  Imports
are read from the source (static, lazy ones inside functions included).
"""

import ast
import pathlib

import pytest

import symstab

PACKAGE = pathlib.Path(symstab.__file__).resolve().parent

#: Rank of each layer; a module may import its own rank or lower.
RANK = {"base": 0, "symbolic": 1, "codegen": 2, "proof": 3, "numeric": 4, "front": 5}
_BASE = {"_project", "_resources", "_validate", "_workers", "_generated"}
_FRONT = {"cli", "figures", "reproduce", "__main__"}


def _layer(parts):
    """Layer of a module given its path parts below ``symstab``."""
    head = parts[0]
    if head in _BASE:
        return "base"
    if head in _FRONT:
        return "front"
    if head in RANK:
        return head
    raise AssertionError(f"symstab/{'/'.join(parts)} is in no layer: put it in one")


def _modules():
    for path in sorted(PACKAGE.rglob("*.py")):
        parts = path.relative_to(PACKAGE).with_suffix("").parts
        if parts == ("__init__",) or "_generated" in parts:
            continue
        yield path, parts


def _imports(path, parts):
    """(line, absolute module path below symstab or 'paper_checks...') of every import."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    package = list(parts[:-1]) if parts[-1] != "__init__" else list(parts[:-1])
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = package[: len(package) - (node.level - 1)] if node.level > 1 else package
                target = base + (node.module.split(".") if node.module else [])
                names = [a.name for a in node.names] if not node.module else [None]
                for name in names:
                    yield node.lineno, ["symstab"] + target + ([name] if name else [])
            elif node.module:
                yield node.lineno, node.module.split(".")
        elif isinstance(node, ast.Import):
            for alias in node.names:
                yield node.lineno, alias.name.split(".")


MODULES = list(_modules())


@pytest.mark.parametrize("path, parts", MODULES, ids=["/".join(p) for _, p in MODULES])
def test_no_layer_imports_a_layer_above(path, parts):
    own = _layer(parts)
    for line, target in _imports(path, parts):
        if target[0] == "paper_checks":
            assert own == "front", (f"symstab/{'/'.join(parts)}.py:{line} imports {'.'.join(target)}: "
                                    f"only the front ends may use paper_checks")
            continue
        if target[0] != "symstab" or len(target) < 2:
            continue
        theirs = _layer(target[1:])
        assert RANK[theirs] <= RANK[own], (
            f"symstab/{'/'.join(parts)}.py:{line} ({own}) imports {'.'.join(target)} ({theirs}), "
            f"a layer above it")


def test_every_layer_is_a_folder_and_every_module_in_one():
    folders = {p.name for p in PACKAGE.iterdir() if p.is_dir() and not p.name.startswith("__")}
    assert {"symbolic", "codegen", "proof", "numeric", "cli", "_generated"} <= folders
    for _, parts in MODULES:
        _layer(parts)


def test_the_test_folders_are_the_layers():
    """The tests mirror the package: ``tests/<layer>/`` for each layer folder, no other folder.

    The front ends' tests (``cli``, ``figures``, ``reproduce``) are in
    ``tests/cli``; the tests about the whole project (README, notebooks,
    layers, docstrings, the audit) at the top of ``tests/``.
    """
    tests = pathlib.Path(__file__).resolve().parent
    folders = {p.name for p in tests.iterdir() if p.is_dir() and not p.name.startswith((".", "_"))}
    layers = {p.name for p in PACKAGE.iterdir() if p.is_dir() and (p / "__init__.py").exists()
              and not p.name.startswith("_")}
    assert folders == layers == {"symbolic", "codegen", "proof", "numeric", "cli"}


def test_no_public_name_shadows_a_submodule():
    """``symstab.boundary`` is the function, and there is no module of that name to hide."""
    submodules = {p.stem for p in PACKAGE.glob("*.py")} | {
        p.name for p in PACKAGE.iterdir() if p.is_dir() and (p / "__init__.py").exists()}
    clash = sorted(name for name in symstab.__all__ if name in submodules)
    assert clash == []
    for layer in ("symbolic", "codegen", "proof", "numeric", "cli"):
        package = __import__(f"symstab.{layer}", fromlist=["__all__"])
        inner = {p.stem for p in (PACKAGE / layer).glob("*.py")}
        exported = set(getattr(package, "__all__", ()))
        assert not (exported & inner), f"symstab.{layer} exports a name that hides a submodule"


def test_paper_checks_uses_the_library_and_no_front_end():
    """No cycle: the front ends use paper_checks, so it must not use them."""
    root = PACKAGE.parent / "paper_checks"
    if not root.is_dir():
        pytest.skip("paper_checks is not installed beside the package")
    for path in sorted(root.glob("*.py")):
        tree = ast.parse(path.read_text(encoding="utf-8"))
        for node in ast.walk(tree):
            module = node.module if isinstance(node, ast.ImportFrom) else None
            names = [a.name for a in node.names] if isinstance(node, ast.Import) else [module or ""]
            for name in names:
                parts = (name or "").split(".")
                if parts[0] == "symstab" and len(parts) > 1:
                    assert parts[1] not in _FRONT, f"{path.name} imports a front end ({name})"


def test_every_public_name_still_works():
    """The names of symstab.__all__ before the layout, each still importable from symstab."""
    before = [
        "boundary", "coefficients", "pulse_transfer_function", "dimensionless_pulse_transfer_function",
        "IdentityResult", "check_identity", "assert_identity", "small_theta_limits",
        "characteristic_polynomial", "dimensionless_values", "closed_form_d0", "newton_form_gamma0",
        "theta_max", "theta_max_newton", "unit_circle_split", "Device", "PAPER_DEVICE",
        "BoundaryCurve", "arc_end_angle", "boundary_curve", "STABLE", "MARGINAL", "UNSTABLE",
        "classify", "is_stable", "spectral_radius", "StabilityRegion", "Limits", "limits",
        "BestVirtualMass", "best_virtual_mass", "Loop", "LoopBoundary", "LoopLimits", "load_loop",
    ]
    missing = [name for name in before if not hasattr(symstab, name) or name not in symstab.__all__]
    assert missing == []
    assert callable(symstab.boundary) and callable(symstab.theta_max)
