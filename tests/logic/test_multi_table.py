"""The ternary implicant table and the heuristic covering against brute force: primes, cube
points, cover matrices, primes raised from implicants, and covers that cover every row."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from scipy import sparse

from mechc.logic.cubes import Cube
from mechc.logic.implicants import (
    cover_matrix,
    cube_points,
    decode,
    encode,
    multi_output_primes,
    raise_to_primes,
    ternary_table,
)
from mechc.logic.multi import minimise_multi
from mechc.logic.setcover import heuristic_cover
from tests.helpers import random_table
from tests.logic.test_multi_output import brute_multi_primes


def _regions(rng, n: int, m: int):
    tables = [random_table(rng, n, p_on=float(rng.uniform(0.2, 0.6)), p_dc=0.15)
              for _ in range(m)]
    arr = np.array(tables)
    return tables, arr == 1, arr != 0


@pytest.mark.parametrize("seed", range(25))
def test_table_primes_match_brute_force(seed):
    rng = np.random.default_rng(7000 + seed)
    n = int(rng.integers(1, 6))
    m = int(rng.integers(1, 4))
    tables, _on, region = _regions(rng, n, m)
    pm, pv, ps, _T = multi_output_primes(region, n)
    got = {(int(a), int(b), int(s)) for a, b, s in zip(pm, pv, ps)}
    assert got == brute_multi_primes(tables, n)


@pytest.mark.parametrize("n", [1, 3, 5])
def test_table_entries_are_the_and_over_each_cube(n):
    """Every one of the 3**n entries against the AND over the cube's points, by hand."""
    rng = np.random.default_rng(n)
    sets = rng.integers(0, 8, size=1 << n)
    T = ternary_table(sets, n, 3)
    idx = np.arange(1 << n)
    for k, digits in enumerate(itertools.product((0, 1, 2), repeat=n)):
        mask = sum(1 << (n - 1 - j) for j, d in enumerate(digits) if d != 2)
        value = sum(1 << (n - 1 - j) for j, d in enumerate(digits) if d == 1)
        assert T[k] == np.bitwise_and.reduce(sets[(idx & mask) == value])
        assert decode(np.array([k]), n) == (mask, value)
        assert encode(np.array([mask]), np.array([value]), n)[0] == k


def test_cube_points_and_cover_matrix_by_brute_force():
    rng = np.random.default_rng(3)
    n, m = 5, 3
    _tables, on, region = _regions(rng, n, m)
    pm, pv, ps, _T = multi_output_primes(region, n)
    cid, pts = cube_points(pm, pv, n)
    idx = np.arange(1 << n)
    for j in range(len(pm)):
        assert sorted(pts[cid == j].tolist()) == idx[(idx & pm[j]) == pv[j]].tolist()
    A = cover_matrix(pm, pv, ps, on, n).toarray()
    rows = [(i, x) for i in range(m) for x in np.flatnonzero(on[i])]
    assert A.shape == (len(rows), len(pm))
    for r, (i, x) in enumerate(rows):
        for j in range(len(pm)):
            want = (ps[j] >> i) & 1 and (x & pm[j]) == pv[j]
            assert bool(A[r, j]) == bool(want)


def test_raised_cubes_are_primes_holding_them():
    rng = np.random.default_rng(11)
    n, m = 5, 3
    _tables, on, region = _regions(rng, n, m)
    pm, pv, ps, T = multi_output_primes(region, n)
    primes = set(encode(pm, pv, n).tolist())
    idx = np.arange(1 << n)
    # minterms with the outputs whose region holds them are implicants
    sets = (region * (1 << np.arange(m))[:, None]).sum(axis=0)
    pts = np.flatnonzero(sets)
    got = raise_to_primes(np.full(len(pts), (1 << n) - 1), pts, sets[pts], T, n)
    gm, gv = decode(got, n)
    for x, s, k, mm, vv in zip(pts, sets[pts], got, gm, gv):
        assert int(k) in primes
        assert (x & mm) == vv  # holds the minterm
        inside = (idx & mm) == vv
        for i in range(m):
            if (s >> i) & 1:
                assert region[i][inside].all()


def _brute_min_cover(D: np.ndarray) -> int:
    for k in range(D.shape[1] + 1):
        for combo in itertools.combinations(range(D.shape[1]), k):
            if D[:, list(combo)].any(axis=1).all():
                return k
    raise AssertionError("no cover")


@pytest.mark.parametrize("seed", range(20))
def test_heuristic_cover_covers_every_row(seed):
    """A cover (every row hit) never below the brute-force minimum, and on these small
    problems the local search reaches it."""
    rng = np.random.default_rng(100 + seed)
    rows, cols = int(rng.integers(3, 14)), int(rng.integers(3, 12))
    D = rng.random((rows, cols)) < 0.3
    D[np.arange(rows), rng.integers(0, cols, rows)] = True  # every row coverable
    cost = rng.integers(0, 10, cols)
    got = heuristic_cover(sparse.csr_matrix(D.astype(np.int8)), cost, 0.2, seed=seed)
    assert D[:, got].any(axis=1).all()
    assert len(got) == _brute_min_cover(D)


def test_heuristic_cover_keeps_a_good_start():
    """Started from a minimum cover it returns one no larger."""
    rng = np.random.default_rng(5)
    D = rng.random((40, 30)) < 0.15
    D[np.arange(40), rng.integers(0, 30, 40)] = True
    A = sparse.csr_matrix(D.astype(np.int8))
    g = heuristic_cover(A, np.ones(30), 0.0)
    got = heuristic_cover(A, np.ones(30), 0.0, start=g)
    assert D[:, got].any(axis=1).all() and len(got) <= len(g)


def _assert_right_on_care_vectors(res, n: int, m: int, on, region) -> None:
    """Every cube of every output's cover lies inside that output's region (on-set or
    don't-care) and the cover holds every on-set vector: checked by enumeration."""
    idx = np.arange(1 << n)
    for i in range(m):
        got = np.zeros(1 << n, dtype=bool)
        for c in res.output_cubes(i):
            inside = (idx & c.mask) == c.value
            assert region[i][inside].all()
            got |= inside
        assert (got | ~on[i]).all()


@pytest.mark.parametrize("seed", range(10))
def test_table_engine_heuristic_route_is_right_on_every_vector(seed):
    """With a prime limit of 1 the table engine skips the exact program (local search and
    the program over its covers' columns); the covers are right on every care vector."""
    rng = np.random.default_rng(300 + seed)
    n = int(rng.integers(4, 8))
    m = int(rng.integers(2, 5))
    tables, on, region = _regions(rng, n, m)
    res = minimise_multi(n, on, region, [[] for _ in range(m)], time_limit=2.0, prime_limit=1)
    assert not res.proven
    _assert_right_on_care_vectors(res, n, m, on, region)


@pytest.mark.parametrize("seed", range(6))
def test_table_engine_never_more_products_than_its_start(seed):
    """Started from per-output covers (each output's minterms), the heuristic route keeps at
    most as many distinct products as the start has (the start, raised to primes and made
    irredundant, is one of the covers it compares)."""
    rng = np.random.default_rng(600 + seed)
    n, m = 6, 3
    _tables, on, region = _regions(rng, n, m)
    full = (1 << n) - 1
    start = [[Cube(full, int(x)) for x in np.flatnonzero(on[i])] for i in range(m)]
    distinct = len({c for cover in start for c in cover})
    res = minimise_multi(n, on, region, start, time_limit=0.5, prime_limit=1)
    assert res.products <= distinct
    assert sum(len(u) for u in res.use) >= res.products  # every product feeds an output


@pytest.mark.parametrize("seed", range(4))
def test_wide_fallback_without_the_table_is_right_on_every_vector(seed, monkeypatch):
    """Where the table would be too large the minimiser falls back to the Shannon primes and
    espresso's loop; that route too gives covers right on every care vector."""
    import mechc.logic.multi as multi

    monkeypatch.setattr(multi, "table_fits", lambda n, m: False)
    rng = np.random.default_rng(800 + seed)
    n, m = 6, 3
    _tables, on, region = _regions(rng, n, m)
    full = (1 << n) - 1
    start = [[Cube(full, int(x)) for x in np.flatnonzero(on[i])] for i in range(m)]
    res = minimise_multi(n, on, region, start, time_limit=2.0, prime_limit=1)
    _assert_right_on_care_vectors(res, n, m, on, region)


def _brute_primes(region: np.ndarray, n: int) -> set[tuple[int, int]]:
    """Every maximal cube inside ``region`` by enumeration of all 3**n cubes."""
    inside = set()
    for digits in itertools.product((0, 1, 2), repeat=n):
        mask = sum(1 << (n - 1 - k) for k, d in enumerate(digits) if d != 2)
        value = sum(1 << (n - 1 - k) for k, d in enumerate(digits) if d == 1)
        pts = [x for x in range(1 << n) if x & mask == value]
        if all(region[x] for x in pts):
            inside.add((mask, value))
    primes = set()
    for mask, value in inside:
        parents = [(mask & ~(1 << b), value & ~(1 << b)) for b in range(n) if mask >> b & 1]
        if not any(p in inside for p in parents):
            primes.add((mask, value))
    return primes


@pytest.mark.parametrize("seed", range(20))
def test_own_primes_match_brute_force_and_recursion(seed):
    """Every output's own primes read off one ternary table are exactly the maximal cubes
    of its region (enumeration) and what the Shannon recursion gives, in the same order."""
    from mechc.logic.implicants import own_primes, region_sets
    from mechc.logic.primes import prime_implicants
    rng = np.random.default_rng(9100 + seed)
    n = int(rng.integers(1, 6))
    m = int(rng.integers(1, 5))
    _tables, _on, region = _regions(rng, n, m)
    got = own_primes(ternary_table(region_sets(region), n, m), n, m)
    assert len(got) == m
    for i in range(m):
        masks, values = got[i]
        assert set(zip(masks.tolist(), values.tolist())) == _brute_primes(region[i], n)
        rm, rv = prime_implicants(region[i])
        assert np.array_equal(masks, rm) and np.array_equal(values, rv)


@pytest.mark.parametrize("seed", range(3))
def test_cover_out_of_time_is_no_worse_than_greedy(seed):
    """When the covering program has (almost) no time, min_cover falls back to local search:
    a cover of every on-minterm (checked here row by row) with no more terms than the
    classic greedy cover of the same candidates."""
    from mechc.logic.cover import coverage, greedy_cover, min_cover
    from mechc.logic.primes import prime_implicants
    rng = np.random.default_rng(880 + seed)
    n = 11
    t = random_table(rng, n, p_on=0.45, p_dc=0.1)
    on = np.flatnonzero(t == 1).astype(np.int64)
    dc = np.flatnonzero(t == 2).astype(np.int64)
    masks, values = prime_implicants(t != 0)
    res = min_cover(masks, values, on, dc, n, time_limit=1e-3)
    got = np.zeros(len(on), dtype=bool)
    for k in res.chosen:
        got |= (on & masks[k]) == values[k]
    assert got.all()
    A = coverage(masks, values, on)
    lits = np.array([int(x).bit_count() for x in masks])
    g = greedy_cover(A, 1.0 + lits / (n + 1.0))
    assert len(res.chosen) <= len(g)
