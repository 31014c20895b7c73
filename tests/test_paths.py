"""Path sums through an acyclic graph (``mechc.ir.paths``), against every path enumerated."""

from __future__ import annotations

import networkx as nx
import numpy as np
import pytest

from mechc.ir.paths import latest, path_sums


def _random_dag(seed: int, n: int = 14) -> tuple[nx.MultiDiGraph, dict[str, float]]:
    rng = np.random.default_rng(seed)
    g = nx.MultiDiGraph()
    names = [f"v{k}" for k in range(n)]
    g.add_nodes_from(names)
    for j in range(1, n):
        for i in range(j):
            if rng.random() < 0.25:
                g.add_edge(names[i], names[j])
                if rng.random() < 0.2:  # a second edge between the same nodes (two pins)
                    g.add_edge(names[i], names[j])
    return g, {v: float(rng.uniform(0.0, 0.05)) for v in names}


def _brute(g, delay, starts, pick) -> dict[str, float]:
    """Every simple path from a start, its nodes' delays summed; the longest or shortest."""
    out: dict[str, list[float]] = {}
    for s in starts:
        out.setdefault(s, []).append(delay[s])
        for t in nx.descendants(g, s):
            for p in nx.all_simple_paths(g, s, t):
                out.setdefault(t, []).append(sum(delay[v] for v in p))
    return {v: pick(x) for v, x in out.items()}


@pytest.mark.parametrize("seed", range(6))
def test_longest_and_shortest_sums_are_those_of_every_path(seed):
    g, delay = _random_dag(seed)
    starts = [v for v in g if g.in_degree(v) == 0][:2] + ["v5"]
    for pick in (max, min):
        best, came = path_sums(g, delay, starts, pick)
        want = _brute(g, delay, starts, pick)
        assert best.keys() == want.keys()
        for v in best:
            assert best[v] == pytest.approx(want[v], abs=1e-12)
            u = came[v]  # the chain it came through gives the same sum
            assert (u is None and v in starts) or best[v] == pytest.approx(best[u] + delay[v])
    arrive, came = latest(g, delay)
    sources = [v for v in g if g.in_degree(v) == 0]
    assert arrive == pytest.approx(_brute(g, delay, sources, max))
    end = max(arrive, key=arrive.get)  # walking back along ``came`` is a real path
    path = [end]
    while came[path[-1]] is not None:
        path.append(came[path[-1]])
    assert sum(delay[v] for v in path) == pytest.approx(arrive[end])
    assert all(g.has_edge(a, b) for b, a in zip(path, path[1:]))
