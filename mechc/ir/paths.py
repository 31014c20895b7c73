"""Path delays through a netlist's acyclic combinational graph: the one home of the longest
and shortest sums of cell delays (static timing), which the hold after each change
(:mod:`mechc.proofs.hold`), compile's ordering requirements (:mod:`mechc.passes.ordering`)
and the timing level's inequalities (:mod:`mechc.proofs.timing`) all read, each with its
own delays (stated, or characterised).

A sequential circuit's ordering requirements (001 Appendix B.2) are inequalities between such
sums: for an essential hazard the moving input must reach every SET/RESET generator (longest
path) before a switching memory's new state does and comes back (shortest path, after the
memory's throw); for SET and RESET moving together, the input's paths to the two pins may
differ by at most a margin. :func:`essential_hazard_times` and :func:`set_reset_skew` give the
two sides; the callers judge them against their margin.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable

import networkx as nx

from mechc.ir.netlist import Netlist


def path_sums(g: nx.MultiDiGraph, delay: dict[str, float], starts: Iterable[str],
              pick: Callable[[list[float]], float] = max
              ) -> tuple[dict[str, float], dict[str, str | None]]:
    """From the nodes ``starts`` (their own delay included) to every node they reach in the
    acyclic graph ``g``: the longest (``pick=max``) or shortest (``min``) sum of ``delay``,
    and the predecessor that sum came through (None at a start)."""
    starts = list(starts)
    first = set(starts)
    reach = set(starts)
    for v in starts:
        reach |= nx.descendants(g, v)
    best: dict[str, float] = {}
    came: dict[str, str | None] = {}
    for node in nx.topological_sort(g.subgraph(reach)):
        options = [(best[u], u) for u in g.predecessors(node) if u in best]
        if node in first:
            options.append((0.0, None))
        if options:
            value = pick(v for v, _u in options)
            best[node] = value + delay.get(node, 0.0)
            came[node] = next(u for v, u in options if v == value)
    return best, came


def latest(g: nx.MultiDiGraph, delay: dict[str, float]
           ) -> tuple[dict[str, float], dict[str, str | None]]:
    """Every node's latest arrival from any source of ``g`` (its own delay included) and the
    node the slowest chain came through."""
    return path_sums(g, delay, [n for n in g if g.in_degree(n) == 0], max)


def set_reset_drivers(nl: Netlist) -> dict[str, set[str]]:
    """MEMORY cell -> the nodes driving its SET and RESET pins."""
    out: dict[str, set[str]] = {}
    for u, v in nl.graph.edges():
        if v in nl.cells and nl.cells[v].type == "MEMORY":
            out.setdefault(v, set()).add(u)
    return out


def _from_input(nl: Netlist, delay: dict[str, float], moving: str
                ) -> tuple[nx.MultiDiGraph, dict[str, set[str]], dict[str, str],
                           dict[str, float], dict[str, float]]:
    """The combinational graph, each memory's SET/RESET drivers, memory net -> cell, and the
    longest and shortest sums from input ``moving`` to every node it reaches."""
    g = nl.combinational_graph()
    src = list(g.successors("in:" + moving))
    far, _ = path_sums(g, delay, src, max)
    near, _ = path_sums(g, delay, src, min)
    mem_of = {c.outputs[0]: c.id for c in nl.cells.values() if c.type == "MEMORY"}
    return g, set_reset_drivers(nl), mem_of, far, near


def essential_hazard_times(nl: Netlist, delay: dict[str, float], moving: str,
                           memories: Iterable[str], move_time: float, throw: float
                           ) -> tuple[float, float]:
    """(t_input, t_memory): when input ``moving`` (moved in ``move_time``, from its start)
    has reached every SET/RESET generator by its longest path, and the earliest that one of
    the ``memories`` (their nets) can have switched (mid-move by the input's shortest path to
    its pins, then ``throw``) and come back to a generator by the shortest path."""
    g, sr, mem_of, far, near = _from_input(nl, delay, moving)
    t_in = move_time + max((far[u] for d in sr.values() for u in d if u in far), default=0.0)
    t_mem = math.inf
    for net in memories:
        cid = mem_of.get(net)
        if cid is None:
            continue
        start = move_time / 2 + min((near[u] for u in sr.get(cid, ()) if u in near),
                                    default=0.0)
        back, _ = path_sums(g, delay, sorted(set(nl.graph.successors(cid))), min)
        fb = min((back[u] for d in sr.values() for u in d if u in back and u != cid),
                 default=0.0)
        t_mem = min(t_mem, start + throw + fb)
    if not math.isfinite(t_mem):
        t_mem = move_time / 2 + throw
    return t_in, t_mem


def set_reset_skew(nl: Netlist, delay: dict[str, float], moving: str,
                   memories: Iterable[str]) -> float:
    """The largest difference between input ``moving``'s longest path to one of a memory's
    two pins and its shortest to the other, over the ``memories`` (their nets)."""
    _g, sr, mem_of, far, near = _from_input(nl, delay, moving)
    skew = 0.0
    for net in memories:
        drivers = [u for u in sorted(sr.get(mem_of.get(net, ""), ())) if u in far]
        if len(drivers) == 2:
            a, b = drivers
            skew = max(skew, far[a] - near[b], far[b] - near[a])
    return skew
