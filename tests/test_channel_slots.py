"""Where the cells and the fan-out bars go (``mechc.passes.assemble``): bars one above the
other share a channel slot, and cells move up or down towards what they are joined to.

References: brute force (every partition of a short sequence into blocks for the least-squares
non-increasing fit; every height for the most bars crossing one), and the compiled designs'
own geometry."""

from __future__ import annotations

import functools
import itertools

import numpy as np
import pytest

from mechc.frontends import load_spec
from mechc.passes import assemble
from mechc.passes.assemble import _channel_slots, _decreasing
from mechc.pipeline import compile_spec
from tests.helpers import EXAMPLES


def _brute_decreasing(values: list[float], weights: list[float]) -> float:
    """The least weighted squared error of any non-increasing fit: the optimum is constant on
    blocks of consecutive values (each at its block's weighted mean), so try every split."""
    n = len(values)
    v, w = np.array(values), np.array(weights)
    best = np.inf
    for cuts in itertools.product([0, 1], repeat=n - 1):
        edges = [0] + [i + 1 for i, c in enumerate(cuts) if c] + [n]
        means = [float(np.average(v[a:b], weights=w[a:b])) for a, b in zip(edges, edges[1:])]
        if any(m2 > m1 + 1e-12 for m1, m2 in zip(means, means[1:])):
            continue
        fit = np.concatenate([np.full(b - a, m) for (a, b), m in
                              zip(zip(edges, edges[1:]), means)])
        best = min(best, float(np.sum(w * (v - fit) ** 2)))
    return best


@pytest.mark.parametrize("seed", range(12))
def test_pool_adjacent_violators_is_the_least_squares_decreasing_fit(seed):
    rng = np.random.default_rng(seed)
    n = int(rng.integers(1, 9))
    values = list(rng.normal(0, 10, n))
    weights = list(rng.uniform(0.1, 3.0, n))
    fit = np.array(_decreasing(values, weights))
    assert len(fit) == n and np.all(np.diff(fit) <= 1e-9)
    sse = float(np.sum(np.array(weights) * (np.array(values) - fit) ** 2))
    assert sse == pytest.approx(_brute_decreasing(values, weights), rel=1e-9, abs=1e-9)


@pytest.mark.parametrize("seed", range(8))
def test_bars_in_one_slot_keep_the_clearance_and_no_packing_uses_fewer_slots(seed):
    rng = np.random.default_rng(seed)
    clearance = 1.0
    nets = [f"n{i}" for i in range(int(rng.integers(1, 30)))]
    spans = {}
    for n in nets:
        lo = float(rng.uniform(-500, 0))
        spans[n] = (lo, lo + float(rng.uniform(5, 200)))
    rightward = {n: int(rng.integers(-2, 4)) for n in nets}
    slots, count = _channel_slots({3: nets}, spans, rightward, clearance)
    assert set(slots) == set(nets) and sorted(set(slots.values())) == list(range(count[3]))
    for a, b in itertools.combinations(nets, 2):
        if slots[a] == slots[b]:
            (lo1, hi1), (lo2, hi2) = sorted([spans[a], spans[b]])
            assert lo2 - hi1 >= clearance - 1e-9, (a, b)
    # the least any packing can use: the most bars (each grown by half the clearance) that
    # cross one height; a bar starts at one of the lower ends, so those heights suffice
    most = max(sum(lo - clearance / 2 <= y + 1e-9 and y < hi + clearance / 2 - 1e-9
                   for lo, hi in spans.values())
               for y in (lo - clearance / 2 for lo, _ in spans.values()))
    assert count[3] == most
    # slots whose nets run right on average sit further right
    mean = [np.mean([rightward[n] for n in nets if slots[n] == k]) for k in range(count[3])]
    assert mean == sorted(mean)


@pytest.fixture(scope="module")
def comparator():
    return compile_spec(load_spec(EXAMPLES / "comparator2.bool"))


def _bars(design) -> dict[int, list[tuple[float, float, float]]]:
    """Per channel (the driver's column), every net's fan-out bar: (x, lowest, highest y)."""
    mech, nl = design.mechanism, design.netlist
    depth = nl.depth()
    out: dict[int, list[tuple[float, float, float]]] = {}
    for net, part in mech.nets.items():
        if net in nl.inputs:
            col, owner, pin = 0, mech.inputs[net], net
        else:
            cid, pin = nl.driver[net]
            col, owner = depth[cid], mech.cells[cid]
        body = owner.body(owner.terminals[pin].body)
        ys = [p[1] for p in body.outline[-1]]  # the vertical bar, drawn last onto the driver
        out.setdefault(col, []).append((part.data["fanout_bar_x"], min(ys), max(ys)))
    return out


def test_a_channel_has_as_many_slots_as_bars_crossing_one_height(comparator):
    """On a compiled design: bars sharing a slot keep the clearance, and each channel has as
    many slots as the most bars (grown by half the clearance) crossing one height."""
    c = comparator.mechanism.ctx.clearance
    shared = 0
    for bars in _bars(comparator).values():
        xs = sorted({x for x, _, _ in bars})
        for x in xs:
            here = sorted((lo, hi) for bx, lo, hi in bars if bx == x)
            shared += len(here) - 1
            for (_, hi1), (lo2, _) in zip(here, here[1:]):
                assert lo2 - hi1 >= c - 1e-6
        most = max(sum(lo - c / 2 <= y + 1e-9 and y < hi + c / 2 - 1e-9 for _, lo, hi in bars)
                   for y in (lo - c / 2 for _, lo, _ in bars))
        assert len(xs) == most
    assert shared > 0  # the design has bars that share a slot


def test_cells_move_towards_what_they_are_joined_to(comparator, monkeypatch):
    """Each column keeps the layout's order without overlapping, and the fan-out bars are
    shorter in all than with every column stacked from the top (the placement before)."""
    mech, nl, layout = comparator.mechanism, comparator.netlist, comparator.layout
    nets = [pl for p in mech.nets.values() for pl in [p.data["fanout_plane"]]]
    base = min(nets)  # the nets' planes lie above every cell's
    depth = nl.depth()
    cols: dict[int, list[str]] = {}
    for cid in nl.cells:
        cols.setdefault(depth[cid], []).append(cid)
    for col in cols.values():
        col.sort(key=lambda cid: layout.cells[cid].row)
        boxes = []
        for cid in col:
            ys = [p[1] for b in mech.cells[cid].bodies for i, poly in enumerate(b.outline)
                  if b.layer_of(i) < base for p in poly]
            boxes.append((min(ys), max(ys)))
        for (lo1, _), (_, hi2) in zip(boxes, boxes[1:]):
            assert hi2 < lo1  # the next row lies wholly below

    def bar_length(design) -> float:
        return sum(hi - lo for bars in _bars(design).values() for _, lo, hi in bars)

    stacked = functools.partial(assemble._rows, sweeps=0)
    monkeypatch.setattr(assemble, "_rows", stacked)
    before = compile_spec(load_spec(EXAMPLES / "comparator2.bool"))
    assert bar_length(comparator) < bar_length(before)
