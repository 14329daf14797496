"""The derivation of a loop is cached on disk as data, and the cache changes no number.

A loop is derived once (the ZOH by residues, the loop polynomial, the
affine parameters) and read back from the cache on later loads; the
numbers must be identical, bit for bit, with and without it.  An entry is
read by building SymPy nodes from an allow-list, never by evaluating text;
a damaged or tampered entry is derived again, not trusted.
"""

import builtins
import json
import shutil

import numpy as np
import pytest
import sympy as sp

from symstab import Loop
from symstab.symbolic import loop_assembly, model


@pytest.fixture
def cache(tmp_path, monkeypatch):
    """A cache folder of this test's own: every test starts with nothing derived."""
    folder = tmp_path / "cache"
    monkeypatch.setenv("SYMSTAB_CACHE_DIR", str(folder))
    return folder


#: A complex pole pair (written with a square root), a float and a rational
#: in the environment: every kind of node a derivation stores.
PLANT = "1/(m*s**2 + b*s + k)"
ENVIRONMENT = "K + B*(z - 1)/(T*z) + 0.5*M*(z - 1)**2/(T**2*z**2)"
VALUES = dict(m=0.0128, b=0.0324, k=20.0, T=1e-3, d=3, M=0.002)
MARKER = "RAN_MARKER"


@pytest.fixture
def zoh_calls(monkeypatch):
    """How many times the ZOH is derived (by residues) from here on."""
    calls = []
    derive = loop_assembly.zoh_pulse_transfer_function

    def counted(*args, **kwargs):
        calls.append(args)
        return derive(*args, **kwargs)

    monkeypatch.setattr(loop_assembly, "zoh_pulse_transfer_function", counted)
    return calls


def numbers(loop):
    """What the loop computes at a few points, and its derivation, exactly."""
    K = np.array([1.0, 30.0, 300.0, 3000.0])
    B = np.array([0.01, 0.5, -0.1, 2.0])
    return (loop.coefficients(K=K, B=B, **VALUES), loop.spectral_radius(K=K, B=B, **VALUES),
            loop.classify(K=K, B=B, **VALUES), loop.affine_parameters(),
            sp.srepr(loop.characteristic_polynomial()))


def assert_identical(a, b):
    for x, y in zip(a, b, strict=True):
        if isinstance(x, np.ndarray):
            np.testing.assert_array_equal(x, y)
        else:
            assert x == y


def entry_files(folder):
    return sorted((folder / "derivations").glob("loop_*.json"))


@pytest.fixture(scope="module")
def derived_once(tmp_path_factory):
    """The loop derived once into a cache of the module's.

    Returns ``(that folder, numbers(loop), {name: the derived value})``.
    The tests that read or damage an entry start from a copy of this one
    instead of deriving the loop afresh (the same entry, the same numbers,
    one derivation).
    """
    folder = tmp_path_factory.mktemp("derived_once") / "cache"
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("SYMSTAB_CACHE_DIR", str(folder))
        loop = Loop(PLANT, ENVIRONMENT, plane=("B", "K"))
        fresh = numbers(loop)
        derived = {name: loop._derivation.get(name) for name in loop._derivation._values}
    return folder, fresh, derived


def test_a_second_load_reads_the_derivation_and_gives_identical_numbers(zoh_calls,
                                                                           cache):
    """issue 18: every load derived the loop again (33 s for operator_arm)."""
    first = Loop(PLANT, ENVIRONMENT, plane=("B", "K"))
    fresh = numbers(first)
    assert len(zoh_calls) == 1
    loop_assembly.forget_derivations()    # this process's shared derivation: read the disk
    again = Loop(PLANT, ENVIRONMENT, plane=("B", "K"))
    cached = numbers(again)
    assert len(zoh_calls) == 1, "derived again"
    assert_identical(fresh, cached)
    assert [sp.srepr(c) for part in again._plant_parts for c in part] == [
        sp.srepr(c) for part in first._plant_parts for c in part]


def test_a_loop_built_again_in_the_same_process_derives_and_reads_nothing(zoh_calls, cache,
                                                                            monkeypatch):
    """The models of one loop share what was derived (``loop_assembly._SHARED``): a sweep or a
    design that builds the loop again neither derives nor reads the cache folder again."""
    from symstab.symbolic.derivation_cache import DerivationCache

    first = numbers(Loop(PLANT, ENVIRONMENT, plane=("B", "K")))
    reads = []
    read = DerivationCache._read

    def counted(self):
        reads.append(self.path)
        return read(self)

    monkeypatch.setattr(DerivationCache, "_read", counted)
    again = numbers(Loop(PLANT, ENVIRONMENT, plane=("B", "K")))
    assert len(zoh_calls) == 1 and reads == []
    assert_identical(first, again)
    # Another plant is another derivation.
    _ = Loop(PLANT.replace("k)", "2*k)"), ENVIRONMENT)._plant_parts
    assert len(zoh_calls) == 2 and len(reads) == 1


def test_the_cache_is_read_without_eval_or_exec(derived_once, cache, monkeypatch):
    from symstab.symbolic.derivation_cache import DerivationCache

    folder, _, expected = derived_once     # what the derivation computed, and wrote
    shutil.copytree(folder, cache)
    loop = Loop(PLANT, ENVIRONMENT, plane=("B", "K"))
    assert {"plant_parts", "parts", "environment_parts", "affine B", "affine B,K"} <= set(expected)

    def refuse(*args, **kwargs):
        raise AssertionError("eval/exec/sympify of cache content")

    with monkeypatch.context() as mp:
        for name in ("eval", "exec", "compile"):
            mp.setattr(builtins, name, refuse)
        mp.setattr(sp, "sympify", refuse)
        mp.setattr(sp, "parse_expr", refuse)
        reread = DerivationCache(loop.plant, loop.environment,
                                 dict(loop.symbols, s=model.s, z=model.z))
        values = {name: reread.get(name) for name in expected}
    assert {k: repr(v) for k, v in values.items()} == {k: repr(v) for k, v in expected.items()}


@pytest.mark.parametrize("damage", ["truncated", "checksum", "symbol", "node", "number",
                                    "plant_parts", "parts", "environment_parts"])
def test_a_damaged_or_tampered_entry_is_derived_again(damage, derived_once, zoh_calls, cache,
                                                      tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    pristine, fresh, _ = derived_once
    shutil.copytree(pristine, cache)
    (path,) = entry_files(cache)
    document = json.loads(path.read_text(encoding="utf-8"))
    payload = document["payload"]
    payload_text = json.dumps(payload)
    if damage == "truncated":
        path.write_text(path.read_text(encoding="utf-8")[:200], encoding="utf-8")
    else:
        if damage == "checksum":     # a coefficient edited by hand, the checksum left
            payload["plant_parts"][1][0][0] = ["Integer", "7"]
        elif damage == "symbol":     # the checksum mended too: still only the loop's symbols
            payload_text = payload_text.replace(
                '["Symbol", "m"]', f'["Symbol", "__import__(\'os\').system(\'touch {MARKER}\')"]')
        elif damage == "node":
            payload_text = payload_text.replace('["Add", ', '["eval", ', 1)
        elif damage == "number":
            payload_text = payload_text.replace('["Integer", "', '["Integer", "__import__', 1)
        else:   # a coefficient changed and the checksum mended: the numbers disagree
            payload[damage][1][0][0] = ["Mul", ["Integer", "2"], payload[damage][1][0][0]]
            payload_text = json.dumps(payload)
        if damage != "checksum":
            from symstab.symbolic.derivation_cache import _checksum

            payload = json.loads(payload_text)
            document["checksum"] = _checksum(payload)
        document["payload"] = payload
        path.write_text(json.dumps(document), encoding="utf-8")
    again = numbers(Loop(PLANT, ENVIRONMENT, plane=("B", "K")))
    # The ZOH is derived again unless only another part was changed (then
    # that part is; the identical numbers say so).  The first derivation was
    # derived_once's, before zoh_calls counted.
    derived = 0 if damage in ("parts", "environment_parts") else 1
    assert len(zoh_calls) == derived, "a damaged entry was trusted"
    assert_identical(fresh, again)
    assert not (tmp_path / MARKER).exists()
    # Rewritten: the next load (in a fresh process: nothing shared) reads it and derives
    # nothing.
    loop_assembly.forget_derivations()
    assert_identical(fresh, numbers(Loop(PLANT, ENVIRONMENT, plane=("B", "K"))))
    assert len(zoh_calls) == derived


def test_another_plant_or_environment_is_another_entry(cache, zoh_calls):
    _ = Loop(PLANT, ENVIRONMENT)._plant_parts
    _ = Loop(PLANT.replace("k)", "2*k)"), ENVIRONMENT)._plant_parts
    _ = Loop(PLANT, ENVIRONMENT.replace("0.5", "0.25"))._plant_parts
    assert len(entry_files(cache)) == 3 and len(zoh_calls) == 3


@pytest.mark.parametrize("expr", [
    sp.Float("0.1", 30) * sp.Symbol("m", real=True) + sp.Rational(-3, 7),
    sp.exp(-sp.Symbol("T", positive=True) * sp.sqrt(sp.Symbol("m", real=True) - 4) / 2),
    sp.I * sp.pi + sp.E**2 + sp.Integer(10)**40,
    sp.cos(sp.Symbol("m", real=True)) / (1 + sp.sinh(sp.Float(2.5))),
])
def test_an_expression_comes_back_identical_from_its_tree(expr):
    from symstab.symbolic.derivation_cache import expression_from_tree, expression_tree

    symbols = {str(x): x for x in expr.free_symbols}
    tree = json.loads(json.dumps(expression_tree(expr)))
    assert sp.srepr(expression_from_tree(tree, symbols)) == sp.srepr(expr)


def test_an_expression_outside_the_allow_list_is_not_stored():
    from symstab.symbolic.derivation_cache import expression_from_tree, expression_tree

    with pytest.raises(ValueError, match="Integral"):
        expression_tree(sp.Integral(sp.Symbol("x"), sp.Symbol("x")))
    with pytest.raises(ValueError, match="not allowed"):
        expression_from_tree(["Function", ["Symbol", "x"]], {"x": sp.Symbol("x")})
    with pytest.raises(ValueError, match="unknown symbol"):
        expression_from_tree(["Symbol", "y"], {"x": sp.Symbol("x")})
