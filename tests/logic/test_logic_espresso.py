"""EXPAND, IRREDUNDANT, the whole espresso loop and the exact cube verifier, each checked
against truth tables of small random specs (n <= 9), and against the exact engine's proven
minimum (a heuristic can never use fewer terms than a proven minimum)."""

from __future__ import annotations

import time

import numpy as np
import pytest

from mechc.logic import espresso as E
from mechc.logic.cubes import DC, Cube
from mechc.passes.minimise import MinimiseOptions, _minimise_table
from tests.logic.bruteforce import rand_cubes, spec_table, truth


def random_spec(rng, rest=None):
    n = int(rng.integers(2, 10))
    on = rand_cubes(rng, n, int(rng.integers(0, 12)), 0.5)
    dc = rand_cubes(rng, n, int(rng.integers(0, 4)), 0.5)
    rest = int(rng.choice([0, DC, 1])) if rest is None else rest
    off = rand_cubes(rng, n, int(rng.integers(0, 9)), 0.5) if rest != 0 else []
    return n, on, dc, off, rest


def is_prime_in(cube: Cube, allowed: np.ndarray, n: int) -> bool:
    if not allowed[truth([cube], n)].all():
        return False
    for j in range(n):
        if cube.mask >> j & 1:
            bigger = Cube(cube.mask & ~(1 << j), cube.value & ~(1 << j))
            if allowed[truth([bigger], n)].all():
                return False
    return True


@pytest.mark.parametrize("with_offset", [True, False], ids=["offset", "oracle"])
def test_expand_gives_primes_containing_every_input_cube(with_offset):
    rng = np.random.default_rng(10)
    for _ in range(120):
        n, on, dc, off, rest = random_spec(rng)
        if rest == 1 or not on:
            continue
        t = spec_table(n, on, dc, off, rest)
        allowed = t != 0
        FD = E._cat(E.pack(on, n), E.pack(dc, n))
        space = E._Space(FD, E.pack(off, n), rest)
        if with_offset:
            space.R = E.complement(FD) if rest == 0 else E.sharp(E.pack(off, n), FD)
        F = E.scc(E.pack(on, n))
        out = E.unpack(E._expand(F, space, time.perf_counter() + 60))
        assert all(is_prime_in(c, allowed, n) for c in out)
        assert all(any(p.contains(c) for p in out) for c in E.unpack(F))


def test_irredundant_keeps_coverage_and_needs_every_cube():
    rng = np.random.default_rng(11)
    checked = 0
    for _ in range(150):
        n, on, dc, _off, _ = random_spec(rng, rest=0)
        if not on:
            continue
        t = spec_table(n, on, dc, [], 0)
        must = t == 1
        # a redundant starting cover: the on-cubes, their primes, and a few duplicates
        space = E._Space(E._cat(E.pack(on, n), E.pack(dc, n)), E.pack([], n), 0)
        primes = E._expand(E.scc(E.pack(on, n)), space, time.perf_counter() + 60)
        G = E._cat(E.pack(on, n), primes, E.pack(on[:2], n))
        kept = E.unpack(E._irredundant(G, E.pack(dc, n), None, time.perf_counter() + 60))
        cov = truth(kept, n)
        assert not (must & ~cov).any()
        for i in range(len(kept)):
            rest = truth(kept[:i] + kept[i + 1:], n)
            assert (must & ~rest).any(), "a cube the others already cover was kept"
        checked += 1
    assert checked > 100


@pytest.mark.parametrize("rest", [0, DC, 1])
def test_espresso_is_correct_prime_and_never_beats_a_proven_minimum(rest):
    rng = np.random.default_rng(12 + rest)
    worse = total = 0
    for _ in range(80):
        n, on, dc, off, _ = random_spec(rng, rest=rest)
        t = spec_table(n, on, dc, off, rest)
        res = E.espresso(n, on, dc, off, rest)
        got = truth(res.cubes, n)
        care = t != DC
        assert (got[care] == (t[care] == 1)).all()
        assert all(is_prime_in(c, t != 0, n) for c in res.cubes)
        assert E.check_cover(n, res.cubes, on, dc, off, rest) is None
        exact, _ = _minimise_table(t, n, MinimiseOptions())
        if exact.proven:
            ours = (len(res.cubes), sum(c.literals() for c in res.cubes))
            assert ours >= (exact.terms, exact.literals)
            worse += ours > (exact.terms, exact.literals)
            total += 1
    assert total > 60
    assert worse <= total // 4  # quality guard: most small functions reach the minimum


def test_time_limit_still_returns_a_valid_cover():
    rng = np.random.default_rng(13)
    n = 9
    on = rand_cubes(rng, n, 40, 0.3)
    res = E.espresso(n, on, time_limit=0.0)
    assert not res.complete
    assert E.check_cover(n, res.cubes, on) is None


def test_empty_and_full_functions():
    n = 5
    assert E.espresso(n, []).cubes == []
    assert E.espresso(n, [], off=[Cube(1, 1)], rest=DC).cubes == []
    # type r with no off-set: the function is 1 everywhere, one cube with no literal
    assert E.espresso(n, [], rest=1).cubes == [Cube(0, 0)]
    # on-set covering everything once don't-cares are added
    assert E.espresso(n, [Cube(1, 1)], dc=[Cube(1, 0)]).cubes == [Cube(0, 0)]


def test_check_cover_finds_real_faults_with_a_witness():
    rng = np.random.default_rng(14)
    faults = 0
    for _ in range(200):
        n, on, dc, off, rest = random_spec(rng)
        t = spec_table(n, on, dc, off, rest)
        care = t != DC
        good = E.espresso(n, on, dc, off, rest).cubes
        for cover in (good[1:], good + rand_cubes(rng, n, 1, 0.6), good[:-1] + good[:1]):
            got = truth(cover, n)
            wrong = care & (got != (t == 1))
            fault = E.check_cover(n, cover, on, dc, off, rest)
            assert (fault is None) == (not wrong.any())
            if fault is not None:
                faults += 1
                point = int(fault.point, 2)
                assert wrong[point]
                assert fault.kind == ("meets off-set" if got[point] else "misses on-set")
    assert faults > 50
