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


def _split_layout(rng: np.random.Generator, n_nets: int) -> list[Piece]:
    """Random nets drawn as the assembler gives them to the router: per net a vertical bar,
    an arm from the driver to it, and rods from the bar."""
    pieces = []
    for k in range(n_nets):
        net, w = f"n{k}", 6.0
        sweep = (10.4, 0.0) if rng.random() < 0.8 else (0.0, 0.0)
        x_bar, ty = rng.uniform(0, 400), rng.uniform(0, 400)
        ys = rng.uniform(0, 400, int(rng.integers(1, 4)))
        arm = (x_bar - rng.uniform(10, 120), ty - w / 2, x_bar + w / 2, ty + w / 2)
        bar = (x_bar - w / 2, min(ty, *ys) - w / 2, x_bar + w / 2, max(ty, *ys) + w / 2)
        for j, ly in enumerate(ys):
            lx = x_bar + rng.uniform(-300, 300)
            rod = (min(x_bar, lx) - w / 2, ly - w / 2, max(x_bar, lx) + w / 2, ly + w / 2)
            pieces.append(Piece(f"net.{net}.rod{j}", net, (rod,), sweep, True))
        pieces.append(Piece(f"net.{net}", net, (bar,), sweep, False))
        pieces.append(Piece(f"net.{net}.arm", net, (arm,), sweep, False, arm=True))
    return pieces


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("one_graph", [True, False])
def test_planes_keep_every_conflicting_pair_apart_and_no_more_than_one_graph(seed, one_graph,
                                                                              monkeypatch):
    """Whichever colouring assign_planes keeps, no two pieces that conflict (brute force over
    every pair, an arm judged as one plate with its bar when they share a plane) share a
    plane; and it never uses more planes than colouring the one graph of all pieces. Also
    with the one graph never tried (as for a big design): the split families alone."""
    from mechc.passes import route
    from mechc.passes.route import _merged, assign_planes

    if not one_graph:
        monkeypatch.setattr(route, "ONE_GRAPH_EDGES", -1)
    rng = np.random.default_rng(seed)
    pieces = _split_layout(rng, int(rng.integers(3, 60)))
    plane = assign_planes(pieces, CLEARANCE, 10)
    assert set(plane) == {p.key for p in pieces} and min(plane.values()) == 10
    for p, q in itertools.combinations(pieces, 2):
        arm_and_its_bar = p.net == q.net and {p.arm, q.arm} == {True, False} \
            and not (p.rod or q.rod)
        if plane[p.key] == plane[q.key] and not arm_and_its_bar:
            assert not conflict(p, q, CLEARANCE), (p.key, q.key)
    # an arm on its bar's plane is one plate with it: that plate against every other piece
    bars = {p.net: p for p in pieces if p.bar}
    for a in (p for p in pieces if p.arm):
        if plane[a.key] == plane[bars[a.net].key]:
            whole = _merged(bars[a.net], a)
            for q in pieces:
                if q.net != a.net and plane[q.key] == plane[a.key]:
                    assert not conflict(whole, q, CLEARANCE)
    # the one graph of all pieces, each arm with its bar, coloured alone
    whole = [p for p in pieces if p.rod] + [_merged(p, next(a for a in pieces if a.arm
                                                            and a.net == p.net))
                                            for p in pieces if p.bar]
    pairs = conflicting_pairs(whole, CLEARANCE)
    one = dsatur_indexed(len(whole), np.array([i for i, _ in pairs], dtype=np.int64),
                         np.array([k for _, k in pairs], dtype=np.int64))
    if one_graph:
        assert len(set(plane.values())) <= max(one) + 1
