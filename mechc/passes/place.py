"""Layout v0: cells in columns by logic depth, rows ordered by barycentre sweeps to cut crossings.

``Netlist -> Layout``. Coordinates are millimetres: x grows with logic depth (signals flow left to
right, as in the dissertation's figures), y with row. Pitches are a parameter so that cell
geometry can widen them.
"""

from __future__ import annotations

from mechc.ir.layout import Layout, Place
from mechc.ir.netlist import Netlist, in_node


def place(nl: Netlist, pitch: tuple[float, float] = (140.0, 90.0), sweeps: int = 8) -> Layout:
    depth = nl.depth()
    ncol = max(depth.values(), default=0) + 1
    columns: list[list[str]] = [[in_node(n) for n in nl.inputs]] + [[] for _ in range(ncol - 1)]
    for cell in nl.topo_cells():
        columns[depth[cell.id]].append(cell.id)
    preds: dict[str, list[str]] = {}
    succs: dict[str, list[str]] = {}
    for u, v in nl.graph.edges():
        if v.startswith("out:"):
            continue
        preds.setdefault(v, []).append(u)
        succs.setdefault(u, []).append(v)

    def positions(cols):
        return {node: i for col in cols for i, node in enumerate(col)}

    best = [list(c) for c in columns]
    best_x = _crossings(best, preds)
    cur = [list(c) for c in columns]
    for sweep in range(sweeps):
        rng = range(1, ncol) if sweep % 2 == 0 else range(ncol - 2, -1, -1)
        nbrs = preds if sweep % 2 == 0 else succs
        for ci in rng:
            pos = positions(cur)
            old = {node: i for i, node in enumerate(cur[ci])}

            def bary(node, pos=pos, old=old, nbrs=nbrs):
                ns = [pos[m] for m in nbrs.get(node, []) if m in pos]
                return (sum(ns) / len(ns) if ns else old[node], old[node])

            cur[ci].sort(key=bary)
        x = _crossings(cur, preds)
        if x < best_x:
            best, best_x = [list(c) for c in cur], x
    cells: dict[str, Place] = {}
    inputs: dict[str, Place] = {}
    for ci, col in enumerate(best):
        offset = (max(len(c) for c in best) - len(col)) / 2.0  # centre short columns
        for ri, node in enumerate(col):
            p = Place(ci * pitch[0], (ri + offset) * pitch[1], ci, ri)
            if node.startswith("in:"):
                inputs[node[3:]] = p
            else:
                cells[node] = p
    return Layout(cells, inputs, pitch, best_x)


def _crossings(cols: list[list[str]], preds: dict[str, list[str]]) -> int:
    """Pairs of edges between the same two columns whose straight segments cross."""
    pos = {node: (ci, ri) for ci, col in enumerate(cols) for ri, node in enumerate(col)}
    groups: dict[tuple[int, int], list[tuple[int, int]]] = {}
    for v, us in preds.items():
        if v not in pos:
            continue
        cv, rv = pos[v]
        for u in us:
            if u in pos:
                cu, ru = pos[u]
                groups.setdefault((cu, cv), []).append((ru, rv))
    return sum(_inversions(edges) for edges in groups.values())


def _inversions(edges: list[tuple[int, int]]) -> int:
    """Pairs of (row at one end, row at the other) that cross: one strictly above the other at
    the left end and strictly below at the right. Sorted by the left row (then the right),
    these are the strict inversions of the right rows, counted with a Fenwick tree in
    O(e log e) (comparing every pair, an e x e matrix per pair of columns, took gigabytes on
    a design whose inputs fan out to a thousand loads)."""
    right = [rv for _, rv in sorted(edges)]
    ranks = {v: k + 1 for k, v in enumerate(sorted(set(right)))}
    size = len(ranks)
    tree = [0] * (size + 1)
    count = 0
    for seen, v in enumerate(right):
        r = ranks[v]
        k, le = r, 0  # how many seen so far are <= v
        while k:
            le += tree[k]
            k -= k & -k
        count += seen - le
        k = r
        while k <= size:
            tree[k] += 1
            k += k & -k
    return count
