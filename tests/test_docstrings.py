"""Every public function documents every parameter (after python-control's docstrings_test).

For each name in ``symstab.__all__`` that is a function, a class or a
class's public method, the docstring must exist, and each parameter of its
signature (``self``, ``cls`` and ``*args``/``**kwargs`` collectors apart)
must appear in its numpydoc ``Parameters`` section (a dataclass's in its
``Attributes``), by name or in a shared
entry such as ``alpha, beta, gamma : float``.  A ``**values``-style
collector must be named in the section as ``**values``.
"""

import inspect
import re

import pytest

import symstab


def _public_callables():
    seen = set()
    for name in symstab.__all__:
        obj = getattr(symstab, name)
        if inspect.isclass(obj):
            if obj.__module__.startswith("symstab") and obj not in seen:
                seen.add(obj)
                yield name, obj
                for attr, member in vars(obj).items():
                    if attr.startswith("_") or not inspect.isfunction(member):
                        continue
                    yield f"{name}.{attr}", member
        elif inspect.isfunction(obj) and obj not in seen:
            seen.add(obj)
            yield name, obj


def _documented(doc, section="Parameters"):
    """Names listed in a section (Parameters, Attributes) of a numpydoc docstring."""
    match = re.search(r"(?:^|\n)\s*" + section + r"\n\s*-+\n(.*?)(\n\s*\n\s*[A-Z][a-z]+\n\s*-+\n|\Z)",
                      doc, re.S)
    if not match:
        return set()
    names = set()
    for line in match.group(1).splitlines():
        head = re.match(r"\s*([*\w][\w, *]*?)\s*(:|$)", line)
        if head and not line.startswith(" " * 8):
            for part in head.group(1).split(","):
                names.add(part.strip())
    return names


CALLABLES = sorted(_public_callables(), key=lambda item: item[0])


@pytest.mark.parametrize("name, obj", CALLABLES, ids=[n for n, _ in CALLABLES])
def test_every_parameter_is_documented(name, obj):
    doc = inspect.getdoc(obj)
    assert doc, f"{name} has no docstring"
    target = obj.__init__ if inspect.isclass(obj) else obj
    # An exception or warning takes its message (a built-in exception's constructor).
    if inspect.isclass(obj) and (target is object.__init__ or issubclass(obj, BaseException)
                                 and "__init__" not in vars(obj)):
        return
    try:
        signature = inspect.signature(target)
    except (TypeError, ValueError):
        return
    wanted = []
    for p in signature.parameters.values():
        if p.name in ("self", "cls"):
            continue
        if p.kind is p.VAR_POSITIONAL:
            continue
        wanted.append(f"**{p.name}" if p.kind is p.VAR_KEYWORD else p.name)
    if not wanted:
        return
    documented = _documented(doc)
    if inspect.isclass(obj):
        # A dataclass documents its fields as Attributes.
        documented |= _documented(doc, "Attributes")
        documented |= _documented(inspect.getdoc(obj.__init__) or "")
    missing = [w for w in wanted if w not in documented]
    assert not missing, f"{name}: parameters not documented: {', '.join(missing)}"
