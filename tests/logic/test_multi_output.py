"""The multi-output minimiser against brute force: its primes, its covers on every vector and
the fewest distinct products found by exhaustive search; time limits that run out are listed."""

from __future__ import annotations

import itertools
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import OptimizeResult

from mechc.frontends.pla import parse_pla_file
from mechc.ir.spec import OutputSpec, Spec
from mechc.logic import hazards
from mechc.logic.cubes import DC, Cube
from mechc.logic.multi import multi_primes, output_sets
from mechc.passes.minimise import MinimiseOptions, minimise
from tests.helpers import random_table

PLAS = Path(__file__).parent / "pla"


def all_cubes(n: int):
    """Every cube over n inputs as (mask, value, boolean membership of the 2**n points)."""
    idx = np.arange(1 << n)
    for lits in itertools.product((0, 1, 2), repeat=n):  # 2 = input absent
        mask = sum(1 << (n - 1 - k) for k, v in enumerate(lits) if v != 2)
        val = sum(1 << (n - 1 - k) for k, v in enumerate(lits) if v == 1)
        yield mask, val, (idx & mask) == val


def brute_multi_primes(tables: list[np.ndarray], n: int) -> set[tuple[int, int, int]]:
    """(cube, outputs whose on ∪ dc holds it) with no larger cube holding the same outputs."""
    imp = {}
    for mask, val, pts in all_cubes(n):
        s = sum(1 << i for i, t in enumerate(tables) if (t[pts] != 0).all())
        if s:
            imp[(mask, val)] = s
    out = set()
    for (mask, val), s in imp.items():
        bigger = any(m2 != mask and (mask & m2) == m2 and (val & m2) == v2 and (s & ~s2) == 0
                     for (m2, v2), s2 in imp.items())
        if not bigger:
            out.add((mask, val, s))
    return out


def brute_min_products(tables: list[np.ndarray], n: int) -> int:
    """Fewest cubes such that every output's on-set is covered by those of them inside its
    on ∪ dc: exhaustive over sets of brute-force multi-output primes."""
    primes = sorted(brute_multi_primes(tables, n))
    idx = np.arange(1 << n)
    need = [frozenset(np.flatnonzero(t == 1).tolist()) for t in tables]
    cov = [[frozenset(idx[(idx & m) == v].tolist()) & need[i] if s >> i & 1 else frozenset()
            for i in range(len(tables))] for m, v, s in primes]
    for k in range(0, len(primes) + 1):
        for combo in itertools.combinations(range(len(primes)), k):
            if all(frozenset().union(*(cov[p][i] for p in combo)) >= need[i]
                   for i in range(len(tables))):
                return k
    raise AssertionError("no cover")


def spec_of(tables: list[np.ndarray], n: int) -> Spec:
    funcs = {}
    for i, t in enumerate(tables):
        funcs[f"f{i}"] = OutputSpec(
            f"f{i}", on=[Cube.minterm(int(x), n) for x in np.flatnonzero(t == 1)],
            dc=[Cube.minterm(int(x), n) for x in np.flatnonzero(t == DC)])
    return Spec("random", "bool", [f"x{k}" for k in range(n)], list(funcs), funcs)


def assert_covers_match(eq, tables: list[np.ndarray], n: int) -> None:
    """Every output's cover is 1 exactly on its on-set, on every care vector (own evaluation,
    not mechc's verifier)."""
    idx = np.arange(1 << n)
    for i, t in enumerate(tables):
        got = np.zeros(1 << n, dtype=bool)
        for c in eq.covers[f"f{i}"].cubes:
            got |= (idx & c.mask) == c.value
        care = t != DC
        assert np.array_equal(got[care], t[care] == 1)


@pytest.mark.parametrize("seed", range(30))
def test_multi_primes_match_brute_force(seed):
    rng = np.random.default_rng(500 + seed)
    n = int(rng.integers(1, 5))
    m = int(rng.integers(1, 4))
    tables = [random_table(rng, n, p_on=0.5, p_dc=0.15) for _ in range(m)]
    sets = output_sets(np.array([t != 0 for t in tables]))
    pm, pv, ps = multi_primes(sets)
    got = {(int(a), int(b), int(s)) for a, b, s in zip(pm, pv, ps)}
    assert got == brute_multi_primes(tables, n)


@pytest.mark.parametrize("seed", range(25))
def test_exact_cover_is_the_fewest_products(seed):
    rng = np.random.default_rng(900 + seed)
    n = int(rng.integers(2, 5))
    m = int(rng.integers(2, 4))
    tables = [random_table(rng, n, p_on=float(rng.uniform(0.2, 0.6)), p_dc=0.15)
              for _ in range(m)]
    eq = minimise(spec_of(tables, n))
    assert_covers_match(eq, tables, n)
    assert eq.proven
    assert eq.products == brute_min_products(tables, n)


@pytest.mark.parametrize("seed", range(8))
def test_heuristic_covers_are_right_and_no_worse_than_per_output(seed):
    """Forced onto the heuristic (a prime limit of 1): covers right on every vector, never
    more distinct products than the per-output covers (same options) shared afterwards."""
    rng = np.random.default_rng(40 + seed)
    n = int(rng.integers(5, 8))
    m = int(rng.integers(2, 5))
    tables = [random_table(rng, n, p_on=float(rng.uniform(0.2, 0.5)), p_dc=0.1)
              for _ in range(m)]
    spec = spec_of(tables, n)
    eq = minimise(spec, MinimiseOptions(prime_limit=1, time_limit=5, complements=False,
                                        hazard_free=False))
    assert_covers_match(eq, tables, n)
    assert not eq.proven
    per_output = minimise(spec, MinimiseOptions(prime_limit=1, multi_output=False,
                                                complements=False, hazard_free=False))
    assert eq.products <= per_output.products


@pytest.mark.parametrize("name,reference", [("count5", 31), ("square5", None), ("add2", None)])
def test_small_plas_no_more_products_than_reference(name, reference):
    """rd53's function (the 5-input count) needs 31 products (espresso's count on MCNC rd53);
    the others are held against the per-output covers shared afterwards."""
    spec = parse_pla_file(PLAS / f"{name}.pla")
    eq = minimise(spec)
    per_output = minimise(spec, MinimiseOptions(multi_output=False))
    assert eq.products <= per_output.products
    if reference is not None:
        assert eq.products <= reference
    tables = [spec.table(o) for o in spec.outputs]
    idx = np.arange(1 << spec.n)
    for o, t in zip(spec.outputs, tables):
        got = np.zeros(1 << spec.n, dtype=bool)
        for c in eq.covers[o].cubes:
            got |= (idx & c.mask) == c.value
        assert np.array_equal(got, t == 1)


def test_square5_shares_products():
    """The square of a 5-bit number: the multi-output cover has strictly fewer products than
    per-output minimum covers shared afterwards (the case the multi-output step exists for)."""
    spec = parse_pla_file(PLAS / "square5.pla")
    eq = minimise(spec)
    per_output = minimise(spec, MinimiseOptions(multi_output=False))
    assert eq.proven
    assert eq.products < per_output.products


def test_tiny_time_limit_is_reported():
    """A time limit far too short: the covers are still right, every step that ran out is
    listed, and nothing claims a proven minimum."""
    rng = np.random.default_rng(11)
    n, m = 10, 3
    tables = [random_table(rng, n, p_on=0.45, p_dc=0.1) for _ in range(m)]
    eq = minimise(spec_of(tables, n), MinimiseOptions(time_limit=0.01, alt_time_limit=0.01))
    assert_covers_match(eq, tables, n)
    assert not eq.proven
    assert eq.time_limited
    assert any("multi-output" in s for s in eq.time_limited)


def test_hazard_step_time_limit_is_reported(monkeypatch):
    """The consensus-term program stopped by its time limit: the cover is named, and the
    greedy answer used instead still closes every hazard. The solver's stop is forced (a
    real 0.05 s limit is met or not by the machine's load: on a loaded one the cover step
    ran out first, left another cover, and the program then finished in time)."""
    calls = []

    def out_of_time(c, **kw):
        calls.append(len(c))
        return OptimizeResult(x=None, status=1, message="time limit reached")

    monkeypatch.setattr(hazards, "milp", out_of_time)
    rng = np.random.default_rng(5)
    n = 8
    t = random_table(rng, n, p_on=0.6, p_dc=0.0)
    eq = minimise(spec_of([t], n), MinimiseOptions(complements=False))
    assert calls, "the consensus-term program was never asked"
    assert "hazard-free cover of f0" in eq.time_limited, eq.time_limited
    assert hazards.uncovered_pairs(eq.hazard_free["f0"].cubes, t, n) == []


def test_hazard_step_given_almost_no_time_never_leaves_a_hazard_unreported():
    """The program given almost no time on a function with many hazards, for real: whether
    it stops early depends on the machine, but a cover with a hazard left is never handed on
    without the cover named."""
    rng = np.random.default_rng(5)
    n = 11
    t = random_table(rng, n, p_on=0.6, p_dc=0.0)
    eq = minimise(spec_of([t], n), MinimiseOptions(hazard_time_limit=0.001, complements=False,
                                                   time_limit=2))
    named = any(s.startswith(("hazard-free cover of", "hazard-free covers of"))
                for s in eq.time_limited)
    left = hazards.uncovered_pairs(eq.hazard_free["f0"].cubes, t, n) if "f0" in eq.hazard_free \
        else None
    assert named or left == [], (eq.time_limited, left)
