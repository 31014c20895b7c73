"""Cube-set algebra of the wide engine against brute force: every operation is compared with
the truth table of the cubes over n <= 10 inputs (the definition of what it must compute).

Each property runs twice: with the small-support table leaf on (the default) and with it off,
so the Shannon recursions themselves are exercised on these small cases.
"""

from __future__ import annotations

import numpy as np
import pytest

from mechc.logic import espresso as E
from mechc.logic.cubes import Cube
from tests.logic.bruteforce import rand_cubes, truth


def point_set(m: np.ndarray, v: np.ndarray, n: int) -> np.ndarray:
    """Points of a single packed cube (one word)."""
    idx = np.arange(1 << n, dtype=np.int64)
    return (idx & int(m[0])) == int(v[0])


@pytest.fixture(params=[True, False], ids=["leaf", "recursive"])
def leaf(request, monkeypatch):
    if not request.param:
        monkeypatch.setattr(E, "LEAF_VARS", 0)
    return request.param


def cases(seed: int, count: int):
    rng = np.random.default_rng(seed)
    for _ in range(count):
        n = int(rng.integers(1, 11))
        k = int(rng.choice([0, 1, 2, 3, 5, 8, 13, 30, 45]))
        yield n, rand_cubes(rng, n, k, float(rng.choice([0.3, 0.5, 0.7, 0.85])))


def test_tautology_and_uncovered_point(leaf):
    seen = {True: 0, False: 0}
    for n, cubes in cases(1, 300):
        t = truth(cubes, n)
        S = E.pack(cubes, n)
        assert E.tautology(S) == t.all()
        seen[bool(t.all())] += 1
        hole = E.find_uncovered(S)
        if t.all():
            assert hole is None
        else:
            inside = point_set(*hole, n)
            assert inside.any() and not (inside & t).any()  # a real cube outside the cover
    assert min(seen.values()) > 20  # both answers were exercised


def test_complement_is_exact(leaf):
    for n, cubes in cases(2, 250):
        comp = E.unpack(E.complement(E.pack(cubes, n)))
        assert (truth(comp, n) == ~truth(cubes, n)).all()


def test_smallest_cube_outside_is_the_supercube_of_the_complement(leaf):
    full = None
    for n, cubes in cases(3, 300):
        t = truth(cubes, n)
        sc = E.smallest_cube_outside(E.pack(cubes, n))
        if t.all():
            assert sc is None
            continue
        holes = np.flatnonzero(~t)
        full = (1 << n) - 1
        ones = int(np.bitwise_and.reduce(holes))
        zeros = int(np.bitwise_and.reduce(~holes & full))
        assert (int(sc[0][0]), int(sc[1][0])) == (ones | zeros, ones)
    assert full is not None


def test_sharp_and_cofactor():
    rng = np.random.default_rng(4)
    for _ in range(150):
        n = int(rng.integers(2, 10))
        a = rand_cubes(rng, n, int(rng.integers(1, 6)), 0.5)
        b = rand_cubes(rng, n, int(rng.integers(0, 12)), 0.5)
        got = E.unpack(E.sharp(E.pack(a, n), E.pack(b, n)))
        assert (truth(got, n) == (truth(a, n) & ~truth(b, n))).all()
        # cofactor: F restricted to cube c, seen as a function of the free inputs
        c = a[0]
        cm, cv = E.pack([c], n)
        cof = E.unpack(E.cofactor(E.pack(b, n), cm[0], cv[0]))
        inside = truth([c], n)
        assert (truth(cof, n)[inside] == truth(b, n)[inside]).all()
        assert all(d.mask & c.mask == 0 for d in cof)


def test_scc_keeps_the_union_and_drops_contained_cubes():
    rng = np.random.default_rng(5)
    for _ in range(100):
        n = int(rng.integers(2, 9))
        cubes = rand_cubes(rng, n, int(rng.integers(1, 25)), 0.5)
        cubes += cubes[: len(cubes) // 3]  # duplicates too
        kept = E.unpack(E.scc(E.pack(cubes, n)))
        assert (truth(kept, n) == truth(cubes, n)).all()
        assert len(set(kept)) == len(kept)
        assert not any(a != b and a.contains(b) for a in kept for b in kept)


def spread(c: Cube, positions: list[int]) -> Cube:
    m = sum(1 << p for j, p in enumerate(positions) if c.mask >> j & 1)
    v = sum(1 << p for j, p in enumerate(positions) if c.value >> j & 1)
    return Cube(m, v)


def shrink(c: Cube, positions: list[int]) -> Cube:
    m = sum(1 << j for j, p in enumerate(positions) if c.mask >> p & 1)
    v = sum(1 << j for j, p in enumerate(positions) if c.value >> p & 1)
    return Cube(m, v)


@pytest.mark.parametrize("n", [64, 65, 117, 128, 130])
def test_multiword_cubes(n, leaf):
    """The same small functions placed on scattered positions of a 2- or 3-word space."""
    rng = np.random.default_rng(n)
    for _ in range(40):
        k = int(rng.integers(2, 9))
        positions = sorted(int(p) for p in rng.choice(n, size=k, replace=False))
        positions[-1] = n - 1  # always use the top word's last bit
        small = rand_cubes(rng, k, int(rng.integers(1, 12)), 0.5)
        wide = [spread(c, positions) for c in small]
        S = E.pack(wide, n)
        t = truth(small, k)
        assert E.tautology(S) == t.all()
        comp = [shrink(c, positions) for c in E.unpack(E.complement(S))]
        assert (truth(comp, k) == ~t).all()
        hole = E.find_uncovered(S)
        assert (hole is None) == t.all()
        assert [shrink(c, positions) for c in E.unpack(S)] == small  # pack/unpack round trip
