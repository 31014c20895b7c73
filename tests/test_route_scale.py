"""The router's bulk conflict search and colouring against brute force on small random layouts,
and the placer's crossing count against comparing every pair of edges."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from mechc.passes.place import _inversions
from mechc.passes.route import Piece, conflict, conflicting_pairs, dsatur, dsatur_indexed

CLEARANCE = 1.0


def _random_pieces(rng: np.random.Generator, n_nets: int) -> list[Piece]:
    """Nets as the assembler draws them: an L of arm and vertical bar, and horizontal rods
    from the bar; a few nets move vertically, some not at all."""
    pieces = []
    for k in range(n_nets):
        net = f"n{k}"
        sweep = [(10.4, 0.0), (0.0, 7.0), (0.0, 0.0)][int(rng.integers(0, 3))]
        x_bar, ty = rng.uniform(0, 300), rng.uniform(0, 300)
        ys = rng.uniform(0, 300, int(rng.integers(1, 4)))
        w = 6.0
        arm = (x_bar - rng.uniform(10, 80), ty - w / 2, x_bar + w / 2, ty + w / 2)
        bar = (x_bar - w / 2, min(ty, *ys) - w / 2, x_bar + w / 2, max(ty, *ys) + w / 2)
        pieces.append(Piece(f"net.{net}", net, (arm, bar), sweep, False))
        for j, ly in enumerate(ys):
            lx = x_bar + rng.uniform(-250, 250)
            rod = (min(x_bar, lx) - w / 2, ly - w / 2, max(x_bar, lx) + w / 2, ly + w / 2)
            pieces.append(Piece(f"net.{net}.rod{j}", net, (rod,), sweep, True))
    order = rng.permutation(len(pieces))
    return [pieces[i] for i in order]


@pytest.mark.parametrize("seed", range(6))
def test_conflicting_pairs_are_every_pair_conflict_names(seed):
    """The spatial-index search finds exactly the pairs the pairwise test says conflict."""
    rng = np.random.default_rng(seed)
    pieces = _random_pieces(rng, int(rng.integers(2, 40)))
    brute = [(i, k) for i, k in itertools.combinations(range(len(pieces)), 2)
             if conflict(pieces[i], pieces[k], CLEARANCE)]
    assert conflicting_pairs(pieces, CLEARANCE) == brute
    assert brute  # the layouts are dense enough to test something


def test_a_rod_and_its_own_bar_always_conflict():
    """Pinned together, a rod and its fan-out bar are never on one plane (the pin stacks the
    two plates), whatever their outlines."""
    bar = Piece("net.a", "a", ((0.0, 0.0, 6.0, 100.0),), (10.0, 0.0), False)
    rod = Piece("net.a.rod1", "a", ((3.0, 50.0, 200.0, 56.0),), (10.0, 0.0), True)
    assert conflicting_pairs([bar, rod], CLEARANCE) == [(0, 1)]


@pytest.mark.parametrize("seed", range(4))
def test_indexed_dsatur_equals_the_named_one_and_colours_properly(seed):
    """The array DSATUR colours every edge's ends differently, and the named wrapper gives
    the same colours for the same order (the tie-break)."""
    rng = np.random.default_rng(seed)
    n = 80
    edges = {(int(a), int(b)) for a, b in rng.integers(0, n, (300, 2)) if a < b}
    a = np.array([e[0] for e in edges], dtype=np.int64)
    b = np.array([e[1] for e in edges], dtype=np.int64)
    col = dsatur_indexed(n, a, b)
    assert all(col[i] != col[k] for i, k in edges)
    adj = {str(v): set() for v in range(n)}
    for i, k in edges:
        adj[str(i)].add(str(k))
        adj[str(k)].add(str(i))
    named = dsatur(adj, [str(v) for v in range(n)])
    assert [named[str(v)] for v in range(n)] == col


@pytest.mark.parametrize("seed", range(5))
def test_crossings_by_inversions_equal_every_pair_compared(seed):
    """Crossing edges between two columns, counted in O(e log e), against every pair."""
    rng = np.random.default_rng(seed)
    for _ in range(40):
        m = int(rng.integers(1, 12))
        edges = [(int(u), int(v)) for u, v in rng.integers(0, m, (int(rng.integers(1, 50)), 2))]
        brute = sum(1 for (u1, v1), (u2, v2) in itertools.combinations(edges, 2)
                    if (u1 - u2) * (v1 - v2) < 0)
        assert _inversions(edges) == brute
