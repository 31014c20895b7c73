"""Steps 1-2: which rows may share a state (the implication table), and the fewest merged rows
that still close under the transitions (a minimum closed cover of compatibles)."""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import networkx as nx
import numpy as np
from scipy import sparse
from scipy.optimize import Bounds, LinearConstraint, milp

from mechc.errors import DesignError
from mechc.ir.seqspec import FlowTable

#: Enumerate every compatible (for prime compatibles) up to this many; beyond, maximal only.
MAX_COMPATIBLES = 5_000


# ---- 1. compatibility ------------------------------------------------------------------------
def stable_outputs(ft: FlowTable, r: int, k: int) -> list[int | None] | None:
    """Outputs of row r at column k if it is stable there (Mealy view), else None."""
    return ft.out[r] if ft.stable(r, k) else None


def compatibility(ft: FlowTable) -> np.ndarray:
    """Boolean N×N matrix: rows i, j may share a state (implication table to a fixed point).

    Outputs belong to stable total states: two rows conflict when both are stable in a column
    with different specified outputs; they imply the pair of their destinations per column."""
    N, K = len(ft.rows), len(ft.columns)
    comp = np.ones((N, N), dtype=bool)
    implied: dict[tuple[int, int], set[tuple[int, int]]] = {}
    for i in range(N):
        for j in range(i + 1, N):
            ok = True
            imp: set[tuple[int, int]] = set()
            for k in range(K):
                oi, oj = stable_outputs(ft, i, k), stable_outputs(ft, j, k)
                if oi is not None and oj is not None and any(
                        a is not None and b is not None and a != b for a, b in zip(oi, oj)):
                    ok = False
                    break
                di, dj = ft.dest(i, k), ft.dest(j, k)
                if di is not None and dj is not None and di != dj:
                    imp.add((min(di, dj), max(di, dj)))
            if not ok:
                comp[i, j] = comp[j, i] = False
            else:
                implied[(i, j)] = imp - {(i, j)}
    changed = True
    while changed:
        changed = False
        for (i, j), imp in implied.items():
            if comp[i, j] and any(not comp[a, b] for a, b in imp):
                comp[i, j] = comp[j, i] = False
                changed = True
    return comp


def implied_set(ft: FlowTable, cls: frozenset[int], k: int) -> frozenset[int]:
    return frozenset(d for r in cls if (d := ft.dest(r, k)) is not None)


def class_set(ft: FlowTable, cls: frozenset[int]) -> set[frozenset[int]]:
    """Implied classes a compatible needs elsewhere in a closed cover."""
    out = set()
    for k in range(len(ft.columns)):
        s = implied_set(ft, cls, k)
        if len(s) >= 2 and not s <= cls:
            out.add(s)
    return out


# ---- 2. closed cover ------------------------------------------------------------------------
@dataclass
class CoverResult:
    classes: list[frozenset[int]]
    proven: bool  # proven minimum number of merged rows
    candidates: int
    method: str  # "prime compatibles" | "maximal compatibles"


def maximal_compatibles(comp: np.ndarray) -> list[frozenset[int]]:
    g = _compat_graph(comp)
    return sorted((frozenset(c) for c in nx.find_cliques(g)), key=lambda c: (-len(c), sorted(c)))


def _compat_graph(comp: np.ndarray) -> nx.Graph:
    N = len(comp)
    g = nx.Graph()
    g.add_nodes_from(range(N))
    g.add_edges_from((i, j) for i in range(N) for j in range(i + 1, N) if comp[i, j])
    return g


def all_compatibles(comp: np.ndarray, limit: int = MAX_COMPATIBLES) -> list[frozenset[int]] | None:
    """Every compatible (clique of the compatibility graph), or None past ``limit``."""
    out = []
    for c in nx.enumerate_all_cliques(_compat_graph(comp)):
        out.append(frozenset(c))
        if len(out) > limit:
            return None
    return out


def prime_compatibles(ft: FlowTable, comps: list[frozenset[int]]) -> list[frozenset[int]]:
    """Compatibles not excluded by a larger one whose class set is no harder to close
    (Grasselli–Luccio): some minimum closed cover uses prime compatibles only."""
    cs = {c: class_set(ft, c) for c in comps}
    as_int = np.array([sum(1 << r for r in c) for c in comps], dtype=np.uint64) \
        if len(ft.rows) <= 64 else None
    primes = []
    for i, c in enumerate(comps):
        pc = cs[c]
        if as_int is not None:  # the strict supersets of c, vectorised
            cm = as_int[i]
            sup = np.flatnonzero(((as_int & cm) == cm) & (as_int != cm))
        else:
            sup = [j for j, d in enumerate(comps) if c < d]
        if not any(all(any(kd <= kc for kc in pc) for kd in cs[comps[j]]) for j in sup):
            primes.append(c)
    return primes


def is_closed_cover(ft: FlowTable, classes: list[frozenset[int]]) -> bool:
    N = len(ft.rows)
    if not classes or set().union(*classes) != set(range(N)):
        return False
    for c in classes:
        for k in class_set(ft, c):
            if not any(k <= d for d in classes):
                return False
    return True


def closed_cover(ft: FlowTable, comp: np.ndarray | None = None,
                 time_limit: float = 20.0) -> CoverResult:
    """Minimum closed cover: binary x_C per candidate; every row covered; a chosen C forces
    some chosen D ⊇ K for each class K it implies. Exact over prime compatibles."""
    comp = compatibility(ft) if comp is None else comp
    N = len(ft.rows)
    comps = all_compatibles(comp)
    if comps is not None:
        cands = prime_compatibles(ft, comps)
        method, exact = "prime compatibles", True
    else:
        cands = maximal_compatibles(comp)
        method, exact = "maximal compatibles", False
    cands = sorted(set(cands), key=lambda c: (-len(c), sorted(c)))
    index = {c: i for i, c in enumerate(cands)}
    P = len(cands)
    rows, cols, vals = [], [], []
    r = 0
    for s in range(N):  # cover
        for c, i in index.items():
            if s in c:
                rows.append(r)
                cols.append(i)
                vals.append(1.0)
        r += 1
    n_cover = r
    for c, i in index.items():  # closure: sum_{D ⊇ K} x_D - x_C >= 0
        for k in class_set(ft, c):
            sup = [index[d] for d in cands if k <= d]
            if not sup:
                raise DesignError(f"internal error: no candidate compatible contains the "
                                  f"implied class {{{', '.join(ft.rows[s] for s in sorted(k))}}}")
            for j in sup:
                rows.append(r)
                cols.append(j)
                vals.append(1.0)
            if i not in sup:
                rows.append(r)
                cols.append(i)
                vals.append(-1.0)
            r += 1
    A = sparse.csr_matrix((vals, (rows, cols)), shape=(r, P))
    lo = np.concatenate([np.ones(n_cover), np.zeros(r - n_cover)])
    # fewest classes; among equals the fewest members in all (a row in two classes adds
    # specified entries, so overlapping covers leave fewer don't-cares to the equations)
    cost = np.array([1.0 + 0.5 * len(c) / (N * N + 1) for c in cands])
    res = milp(cost, integrality=np.ones(P), bounds=Bounds(0, 1),
               constraints=[LinearConstraint(A, lo, np.inf)],
               options={"time_limit": time_limit})
    if res.x is None:
        # the maximal compatibles always form a closed cover: fall back to it
        chosen = maximal_compatibles(comp)
        return CoverResult(chosen, False, P, method + " (solver gave no answer)")
    chosen = [cands[i] for i in np.flatnonzero(res.x > 0.5)]
    proven = exact and res.status == 0
    chosen = _shrink(ft, _drop_redundant(ft, chosen))
    return CoverResult(sorted(chosen, key=lambda c: min(c)), proven, P, method)


def _drop_redundant(ft: FlowTable, classes: list[frozenset[int]]) -> list[frozenset[int]]:
    out = list(classes)
    for c in sorted(classes, key=len):
        rest = [d for d in out if d != c]
        if rest and is_closed_cover(ft, rest):
            out = rest
    return out


def _shrink(ft: FlowTable, classes: list[frozenset[int]]) -> list[frozenset[int]]:
    """Take each row out of all but one of the classes that hold it, where the cover stays
    closed: prime compatibles are as large as possible, but a row held twice only adds
    specified entries (fewer don't-cares for the equations)."""
    out = list(classes)
    for r in range(len(ft.rows)):
        holders = [i for i, c in enumerate(out) if r in c]
        for i in sorted(holders, key=lambda i: -len(out[i]))[:-1]:
            trial = list(out)
            trial[i] = out[i] - {r}
            if trial[i] and is_closed_cover(ft, trial):
                out = trial
    return out


def brute_force_min_cover(ft: FlowTable, comp: np.ndarray | None = None) -> int:
    """Size of a minimum closed cover by trying every set of compatibles (tests only)."""
    comp = compatibility(ft) if comp is None else comp
    comps = all_compatibles(comp, 1 << 20)
    for size in range(1, len(ft.rows) + 1):
        for combo in itertools.combinations(comps, size):
            if is_closed_cover(ft, list(combo)):
                return size
    return len(ft.rows)
