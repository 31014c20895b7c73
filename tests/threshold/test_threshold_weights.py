"""Minimum multithreshold realisations: exhaustive search vs integer programming, counts."""

from __future__ import annotations

from collections import Counter

import numpy as np
import pytest

from mechc.threshold.functions import (
    function_value,
    input_matrix,
    is_unate,
    npn_class_ids,
    truth_table_from_fv,
)
from mechc.threshold.weights import (
    Realisation,
    is_linearly_separable_lp,
    realise,
    realise_milp,
    realise_search,
    separable_functions,
    static_hazards,
    threshold_counts,
    thresholds_for,
)

# Mow and Fu's table as repeated in 001 Table II (scan lines 1472-1505): one W;T per NPN class,
# thresholds in Haring's form T1 > T2 > ... with None for "-" (T1 absent).
TABLE_II = {
    1: ((1, 0, 0), (0.5,)), 4: ((2, 1, 1), (1.5,)), 7: ((1, 1, 1), (1.5,)),
    9: ((1, 1, 0), (0.5,)), 13: ((1, 1, 1), (0.5,)),
    26: ((2, 1, -1), (0.5, -0.5)), 27: ((-2, 1, 1), (1.5, -0.5)), 45: ((1, 1, 1), (1.5, 0.5)),
    46: ((2, 2, -1), (None, 3.5, 0.5)), 73: ((1, 1, 1), (None, 2.5, 0.5)),
    78: ((1, 1, 0), (None, 1.5, 0.5)),
    93: ((3, 1, -2), (1.5, -0.5, -1.5)), 163: ((-1, 1, 1), (None, 1.5, 0.5, -0.5)),
}


def haring(weights, thresholds) -> tuple[int, ...]:
    """Haring's element (001 Eq. 3.7): 1 at or above T1, alternating downwards."""
    s = input_matrix(3) @ np.array(weights)
    ts = [np.inf if t is None else t for t in thresholds]
    return tuple(int(sum(t > v for t in ts) % 2 == 0) for v in s)


def test_threshold_counts_match_table_ii_classes():
    # Independent of the search: each Table II vector's function, times its NPN class size.
    ids = npn_class_ids(3)
    sizes = Counter(ids.tolist())
    expected = Counter({0: 2})
    for w, t in TABLE_II.values():
        k = sum(v is not None for v in t)
        expected[k] += sizes[ids[function_value(haring(w, t))]]
    assert sum(expected.values()) == 256
    assert threshold_counts(3) == dict(expected)
    assert dict(expected) == {0: 2, 1: 102, 2: 126, 3: 26}


def test_linearly_separable_counts():
    # 104 threshold functions of 3 inputs and 1882 of 4 (constants included; literature).
    lp3 = sum(is_linearly_separable_lp(truth_table_from_fv(fv)) for fv in range(256))
    assert lp3 == 104
    assert len(separable_functions(3, 3)) == 104
    gen4 = separable_functions(4, 3)
    assert len(gen4) == 1882
    # LP (real weights) on one representative per NPN class, weighted by class size.
    ids = npn_class_ids(4)
    sizes = Counter(ids.tolist())
    total = 0
    for rep, size in sizes.items():
        tt = truth_table_from_fv(int(rep), 4)
        if is_unate(tt) and is_linearly_separable_lp(tt):
            total += size
    assert total == 1882
    assert all(is_linearly_separable_lp(truth_table_from_fv(fv, 4)) for fv in list(gen4)[:200])


def test_search_and_milp_agree_on_every_function():
    # The integer program tries both values of `below`, so f and its complement pose the same
    # problems: solving FV 0..127 covers all 256; the search runs on all 256.
    for fv in range(128):
        b = realise_milp(fv)
        for g in (fv, 255 - fv):
            a = realise_search(g)
            tt = truth_table_from_fv(g)
            assert a.truth_table() == tt, g
            assert (a.k, a.size) == (b.k, b.size), (g, a, b)
        assert b.truth_table() == truth_table_from_fv(fv)


def test_larger_weight_bound_changes_nothing():
    for fv in range(0, 256, 3):
        a, b = realise_search(fv, bound=4), realise_search(fv, bound=6)
        assert (a.k, a.size) == (b.k, b.size)


def test_realisation_conventions():
    assert realise(0) == Realisation((0, 0, 0), (), 0)
    assert realise(255) == Realisation((0, 0, 0), (), 1)
    r = realise(15)  # x1 alone: a single literal
    assert r.k == 1 and sorted(map(abs, r.weights)) == [0, 0, 1]
    for fv in range(256):
        r = realise(fv)
        assert list(r.thresholds) == sorted(r.thresholds)
        assert r.evaluate(input_matrix(3)).tolist() == list(truth_table_from_fv(fv))
        # thresholds sit halfway between integer sums
        assert all(abs(t * 2 - round(t * 2)) < 1e-12 and t != round(t) for t in r.thresholds)


def test_full_adder_sum_vector_from_design_notes():
    # 001 §3.8.2: W;T = (-1, 1, 1; 1.5, 0.5, -0.5) realises FV 105, and no
    # realisation needs fewer thresholds or a smaller sum of |w|.
    tt = truth_table_from_fv(105)
    th, below = thresholds_for((-1, 1, 1), tt)
    assert sorted(th) == [-0.5, 0.5, 1.5] and below == 1
    r = realise(105)
    assert (r.k, r.size) == (3, 3)


@pytest.mark.parametrize("fv", [6, 27, 105, 157])
def test_static_hazard_definition_by_brute_force(fv):
    # A hazard is a single-input change with equal outputs at its ends whose sum range holds a
    # minterm with the other output; checked here directly from the sums.
    tt = truth_table_from_fv(fv)
    r = realise(fv)
    x = input_matrix(3)
    s = x @ np.array(r.weights)
    found = set()
    for a in range(8):
        for j in range(3):
            b = a | (4 >> j)
            if b == a or tt[a] != tt[b]:
                continue
            lo, hi = sorted((s[a], s[b]))
            if any(tt[m] != tt[a] for m in range(8) if lo <= s[m] <= hi):
                found.add((a, j))
    assert set(static_hazards(r.weights, tt)) == found


def test_no_weights_avoid_the_48_hazards():
    # Exhaustive over weights in [-4, 4]^3 (any number of thresholds): 48 functions have a
    # hazard on every realisation, and realise() reaches the fewest hazards possible.
    grid = [np.array(w) for w in np.ndindex(9, 9, 9)]
    unavoidable = []
    for fv in range(256):
        tt = truth_table_from_fv(fv)
        best = None
        for w in grid:
            w = tuple(int(v) - 4 for v in w)
            if thresholds_for(w, tt) is None:
                continue
            h = len(static_hazards(w, tt))
            best = h if best is None else min(best, h)
            if best == 0:
                break
        if best:
            unavoidable.append(fv)
        assert len(static_hazards(realise(fv).weights, tt)) <= best or best is None, fv
    assert len(unavoidable) == 48
    assert {fv for fv in range(256) if static_hazards(realise(fv).weights,
                                                      truth_table_from_fv(fv))} == set(unavoidable)
