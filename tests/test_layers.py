"""The package is laid out by layer, and no layer imports a layer above it.

From the bottom: the private base (``_project``, ``_resources``,
``_signals``, ``_validate``, ``_workers``, ``_generated``), ``symbolic`` (the derivation in SymPy),
``codegen`` (float-safe forms, printers, generated kernels), ``proof``
(the identity checker, every proof obligation, the derivation files),
``numeric`` (the numeric API on the kernels), and the front ends (``cli``,
``figures``, ``reproduce``).  ``paper_checks`` sits between the library and
the front ends: the front ends may import it, the library may not.  Imports
are read from the source (static, lazy ones inside functions included).

Besides the layers: no import cycle (strongly connected components of the
module graph of symstab and of paper_checks), no private name imported
from another module (:data:`PRIVATE_IMPORTS_ALLOWED` lists the few left, each
with its reason), and the command line one module per command.
"""

import ast
import pathlib

import pytest

import symstab

PACKAGE = pathlib.Path(symstab.__file__).resolve().parent

#: Rank of each layer; a module may import its own rank or lower.
RANK = {"base": 0, "symbolic": 1, "codegen": 2, "proof": 3, "numeric": 4, "front": 5}
_BASE = {"_project", "_resources", "_signals", "_validate", "_workers", "_generated"}
_FRONT = {"cli", "drawing", "figures", "reproduce", "__main__"}


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


# --------------------------------------------------------------------------
# No import cycle, no private name across modules

#: Private names a module may still take from another module of symstab or
#: paper_checks: ``{(importer, "source.name"): reason}``.  Keep it short: a
#: name another module needs is public, with a docstring, in one home.
PRIVATE_IMPORTS_ALLOWED = {}

_ROOTS = {"symstab": PACKAGE, "paper_checks": PACKAGE.parent / "paper_checks"}


def _module_names():
    """``{dotted name: path}`` of every module of symstab (generated kernels included) and paper_checks."""
    out = {}
    for root, folder in _ROOTS.items():
        if not folder.is_dir():
            continue
        for path in sorted(folder.rglob("*.py")):
            parts = path.relative_to(folder).with_suffix("").parts
            if parts[-1] == "__init__":
                parts = parts[:-1]
            out[".".join((root,) + parts)] = path
    return out


MODULE_NAMES = _module_names()


def _package_of(name, path):
    """The package a relative import of module ``name`` starts from."""
    return name if path.name == "__init__.py" else name.rpartition(".")[0]


def _module_of(dotted):
    """The longest prefix of ``dotted`` that is one of our modules, or None."""
    parts = dotted.split(".")
    for k in range(len(parts), 0, -1):
        candidate = ".".join(parts[:k])
        if candidate in MODULE_NAMES:
            return candidate
    return None


def _imports_of(name, path):
    """``(line, imported module, imported name or None)`` of every import in module ``name``.

    Module-level imports and those inside functions; relative ones resolved.
    ``from package import x`` where ``x`` is a submodule imports the
    submodule (not the package's ``__init__``), and its name is None.
    """
    tree = ast.parse(path.read_text(encoding="utf-8"))
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                target = _module_of(alias.name)
                if target is not None:
                    yield node.lineno, target, None, alias.asname
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = _package_of(name, path).split(".")
                base = base[: len(base) - (node.level - 1)]
                source = ".".join(base + ([node.module] if node.module else []))
            else:
                source = node.module or ""
            if _module_of(source) is None:
                continue
            for alias in node.names:
                child = f"{source}.{alias.name}"
                if child in MODULE_NAMES:
                    yield node.lineno, child, None, alias.asname or alias.name
                else:
                    yield node.lineno, _module_of(source), alias.name, None


def _graph():
    edges = {name: set() for name in MODULE_NAMES}
    for name, path in MODULE_NAMES.items():
        for _, target, _, _ in _imports_of(name, path):
            if target != name:
                edges[name].add(target)
    return edges


def _cycles(edges):
    """The strongly connected components of more than one module (iterative Tarjan), sorted."""
    index, low, on_stack, stack, found = {}, {}, set(), [], []
    counter = 0
    for start in sorted(edges):
        if start in index:
            continue
        work = [(start, iter(sorted(edges[start])))]
        index[start] = low[start] = counter
        counter += 1
        stack.append(start)
        on_stack.add(start)
        while work:
            node, children = work[-1]
            for child in children:
                if child not in index:
                    index[child] = low[child] = counter
                    counter += 1
                    stack.append(child)
                    on_stack.add(child)
                    work.append((child, iter(sorted(edges[child]))))
                    break
                if child in on_stack:
                    low[node] = min(low[node], index[child])
            else:
                work.pop()
                if work:
                    parent = work[-1][0]
                    low[parent] = min(low[parent], low[node])
                if low[node] == index[node]:
                    component = []
                    while True:
                        member = stack.pop()
                        on_stack.discard(member)
                        component.append(member)
                        if member == node:
                            break
                    if len(component) > 1:
                        found.append(sorted(component))
    return sorted(found)


def test_the_cycle_finder_finds_cycles():
    """The finder on a made-up graph: a 3-cycle, a 2-cycle, a self-contained chain."""
    edges = {"a": {"b"}, "b": {"c"}, "c": {"a", "d"}, "d": {"e"}, "e": {"d"}, "f": {"a"}, "g": set()}
    assert _cycles(edges) == [["a", "b", "c"], ["d", "e"]]


@pytest.mark.parametrize("root", sorted(_ROOTS))
def test_no_import_cycle(root):
    """No module of ``root`` imports itself through others (imports inside functions included).

    A package ``__init__`` that re-exports its children is no cycle: a child
    that imports a sibling reaches it directly, not through the package.
    """
    if not _ROOTS[root].is_dir():
        pytest.skip(f"{root} is not installed beside the package")
    cycles = [c for c in _cycles(_graph()) if any(m.split(".")[0] == root for m in c)]
    for cycle in cycles:
        print("import cycle: " + " <-> ".join(cycle))
    assert cycles == [], f"{len(cycles)} import cycle(s): " + "; ".join(
        " <-> ".join(c) for c in cycles)


def _private_imports():
    """``(importer, line, source module, name)`` of every private name taken from another module.

    ``from .x import _y`` (single or parenthesised, at any depth), and
    ``module._y`` on a module imported as a name (``from . import x``,
    ``import a.b as x``).  A private module (``from . import _common``) is a
    module, not a private name; dunders are not private.
    """
    def private(text):
        return text.startswith("_") and not (text.startswith("__") and text.endswith("__"))

    found = []
    for name, path in MODULE_NAMES.items():
        tree = ast.parse(path.read_text(encoding="utf-8"))
        aliases = {}
        for line, target, imported, alias in _imports_of(name, path):
            if imported is not None and private(imported) and target != name:
                found.append((name, line, target, imported))
            elif imported is None and alias is not None and target != name:
                aliases[alias] = target
        for node in ast.walk(tree):
            if (isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name)
                    and node.value.id in aliases and private(node.attr)):
                found.append((name, node.lineno, aliases[node.value.id], node.attr))
    return sorted(set(found))


def test_no_private_name_is_imported_across_modules():
    """A name used by another module is public (documented, in one home), not ``_private``."""
    found = _private_imports()
    offenders = [(importer, line, source, imported) for importer, line, source, imported in found
                 if (importer, f"{source}.{imported}") not in PRIVATE_IMPORTS_ALLOWED]
    for importer, line, source, imported in offenders:
        print(f"{importer}:{line} imports {source}.{imported}")
    stale = sorted(set(PRIVATE_IMPORTS_ALLOWED) - {(i, f"{s}.{n}") for i, _, s, n in found})
    assert stale == [], f"allowlist entries no longer needed: {stale}"
    assert offenders == [], f"{len(offenders)} private name(s) imported across modules"


def test_the_cli_is_one_module_per_command_over_shared_modules():
    """Each command is a module with ``register`` and ``run``; none imports another command.

    ``symstab.cli.commands`` builds the parser from
    :func:`~symstab.cli.commands.command_modules`; what two commands share
    lives in a shared module of ``symstab/cli/``.
    """
    from symstab.cli import commands

    modules = commands.command_modules()
    names = {module.__name__ for module in modules}
    assert len(names) == len(modules) == len(commands.COMMAND_NAMES)
    for module in modules:
        assert callable(module.register) and callable(module.run), module.__name__
    parser_commands = set(commands.build_parser()._subparsers._group_actions[0].choices)
    assert parser_commands == {name.rpartition(".")[2] for name in names}
    crossing = sorted(f"{name} imports {target} (line {line})"
                      for name in names
                      for line, target, _, _ in _imports_of(name, MODULE_NAMES[name])
                      if target in names and target != name)
    assert crossing == [], crossing
