"""Minimum covers by integer programming (scipy.optimize.milp / HiGHS).

Single output: choose primes covering every on-minterm, minimising (terms, literals, don't-care
minterms switched on) lexicographically: the last criterion makes the choice among equal-cost
covers deterministic and conservative (an unspecified input state is left off where possible).
Several outputs: after each output's minimum is known, a second program keeps every output at its
minimum and minimises the number of distinct product terms, so shared terms cost one cell.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
from scipy import sparse
from scipy.optimize import Bounds, LinearConstraint, milp

DC_TIEBREAK_MAX_NNZ = 200_000
#: The don't-care tie-break is a nicety for hand-sized specs; past this many candidates it is
#: skipped (it can take longer than the cover itself).
DC_TIEBREAK_MAX_CANDIDATES = 300


@dataclass
class CoverResult:
    chosen: np.ndarray  # indices into the candidate arrays
    proven: bool
    method: str  # "exact" | "greedy"
    seconds: float


def _lits(masks: np.ndarray) -> np.ndarray:
    return np.array([int(m).bit_count() for m in masks], dtype=np.int64)


def coverage(masks: np.ndarray, values: np.ndarray, rows: np.ndarray,
             budget: int = 8_000_000) -> sparse.csr_matrix:
    """Sparse (len(rows) x len(masks)) matrix: row r is covered by cube p."""
    if len(rows) == 0 or len(masks) == 0:
        return sparse.csr_matrix((len(rows), len(masks)), dtype=np.int8)
    step = max(1, budget // len(masks))
    ri, ci = [], []
    for s in range(0, len(rows), step):
        blk = rows[s:s + step, None]
        r, c = np.nonzero((blk & masks[None, :]) == values[None, :])
        ri.append(r + s)
        ci.append(c)
    r = np.concatenate(ri)
    c = np.concatenate(ci)
    return sparse.csr_matrix((np.ones(len(r), dtype=np.int8), (r, c)),
                             shape=(len(rows), len(masks)))


def greedy_cover(A: sparse.csr_matrix, cost: np.ndarray) -> np.ndarray:
    """Classic greedy set cover (best ratio of newly covered rows to cost)."""
    A = A.tocsc()
    uncovered = np.ones(A.shape[0], dtype=bool)
    chosen: list[int] = []
    while uncovered.any():
        gain = A.T @ uncovered.astype(np.int64)
        ratio = np.where(gain > 0, gain / cost, -1.0)
        p = int(np.argmax(ratio))
        if ratio[p] <= 0:
            raise ValueError("rows that no candidate covers")
        chosen.append(p)
        col = A[:, p].toarray().ravel().astype(bool)
        uncovered &= ~col
    return np.array(sorted(chosen), dtype=np.int64)


def reduce_problem(A: sparse.csr_matrix, cost: np.ndarray):
    """Shrink a unate covering problem without losing an optimum: select essential columns,
    drop dominating rows and dominated columns, repeat until nothing changes.

    Returns (forced column indices, remaining row indices, remaining column indices)."""
    A = sparse.csr_matrix(A, dtype=np.int32)
    rows = np.arange(A.shape[0])
    cols = np.arange(A.shape[1])
    forced: list[int] = []
    while True:
        sub = A[rows][:, cols].tocsr()
        if sub.shape[0] == 0:
            break
        changed = False
        # essential columns: a row only one column covers
        deg = np.diff(sub.indptr)
        if (deg == 0).any():
            raise ValueError("a row no candidate covers")
        ess = np.unique(sub.indices[sub.indptr[:-1][deg == 1]])
        if len(ess):
            forced.extend(cols[ess].tolist())
            covered = np.asarray(sub[:, ess].sum(axis=1)).ravel() > 0
            rows = rows[~covered]
            keep = np.ones(len(cols), dtype=bool)
            keep[ess] = False
            cols = cols[keep]
            continue
        # row dominance: if row i's columns are a subset of row j's, row j is implied
        inter = (sub @ sub.T).tocoo()
        size = deg
        sub_of = (inter.data == size[inter.row]) & (inter.row != inter.col)
        i, j = inter.row[sub_of], inter.col[sub_of]
        # equal rows: drop the later one only
        drop_rows = set(j[(size[i] < size[j]) | ((size[i] == size[j]) & (i < j))].tolist())
        if drop_rows:
            keep = np.array([r not in drop_rows for r in range(len(rows))])
            rows = rows[keep]
            changed = True
        sub = A[rows][:, cols].tocsc()
        # column dominance: p dominated by q if rows(p) ⊆ rows(q) and cost(q) <= cost(p)
        csize = np.diff(sub.indptr)
        empty = csize == 0
        inter = (sub.T @ sub).tocoo()
        c = cost[cols]
        dom = ((inter.data == csize[inter.row]) & (inter.row != inter.col)
               & (c[inter.col] <= c[inter.row]))
        p, q = inter.row[dom], inter.col[dom]
        strict = (csize[p] < csize[q]) | (c[q] < c[p]) | (p > q)
        drop_cols = set(p[strict].tolist()) | set(np.flatnonzero(empty).tolist())
        if drop_cols:
            keep = np.array([k not in drop_cols for k in range(len(cols))])
            cols = cols[keep]
            changed = True
        if not changed:
            break
    return np.array(sorted(set(forced)), dtype=np.int64), rows, cols


def min_cover(masks: np.ndarray, values: np.ndarray, on_rows: np.ndarray, dc_rows: np.ndarray,
              n: int, time_limit: float, dc_time: float = 2.0) -> CoverResult:
    """Minimum (terms, literals) cover of ``on_rows`` by the candidate cubes; among minimum
    covers, one switching on the fewest don't-care rows (a second, time-capped program)."""
    t0 = time.perf_counter()
    P = len(masks)
    if len(on_rows) == 0:
        return CoverResult(np.zeros(0, dtype=np.int64), True, "exact", 0.0)
    A = coverage(masks, values, on_rows)
    lits = _lits(masks)
    g = greedy_cover(A, 1.0 + lits / (n + 1.0))
    w_term = n * len(g) + 1  # more than any literal difference between covers of equal size
    c = (w_term + lits).astype(float)
    forced, rows, cols = reduce_problem(A, c)
    if len(rows) == 0:
        chosen, proven = forced, True
    else:
        # two stages (fewest terms, then fewest literals with the term count fixed): several
        # times faster on cyclic random problems than one lexicographic objective
        sub = A[rows][:, cols]
        cover_rows = LinearConstraint(sub, 1, np.inf)
        k = len(cols)
        ones = np.ones(k)

        def remaining():
            return max(0.1, time_limit - (time.perf_counter() - t0))

        res = milp(ones, integrality=ones, bounds=Bounds(0, 1), constraints=[cover_rows],
                   options={"time_limit": remaining()})
        if res.x is None:
            return CoverResult(g, False, "greedy", time.perf_counter() - t0)
        terms = int(round(res.x.sum()))
        proven = res.status == 0
        res2 = milp(lits[cols].astype(float), integrality=ones, bounds=Bounds(0, 1),
                    constraints=[cover_rows, LinearConstraint(ones[None, :], terms, terms)],
                    options={"time_limit": remaining(), "mip_rel_gap": 0.0})
        x = res2.x if res2.x is not None else res.x
        proven = proven and res2.status == 0
        chosen = np.sort(np.concatenate([forced, cols[x > 0.5]]))
    if proven and len(dc_rows) and P <= DC_TIEBREAK_MAX_CANDIDATES:
        better = _fewest_dc(A, c, float(c[chosen].sum()), masks, values, dc_rows, dc_time)
        if better is not None:
            chosen = better
    return CoverResult(chosen, proven, "exact", time.perf_counter() - t0)


def _fewest_dc(A, c, best, masks, values, dc_rows, time_limit) -> np.ndarray | None:
    """Among covers of cost <= best, one covering the fewest don't-care rows (or None)."""
    B = coverage(masks, values, dc_rows)
    if B.nnz == 0 or B.nnz > DC_TIEBREAK_MAX_NNZ:
        return None
    B = B[np.flatnonzero(np.asarray(B.sum(axis=1)).ravel() > 0)].tocoo()
    P, D, k = A.shape[1], B.shape[0], B.nnz
    # d_j >= x_p for every candidate p covering don't-care row j
    link = sparse.csr_matrix((np.tile([1.0, -1.0], k),
                              (np.repeat(np.arange(k), 2),
                               np.stack([P + B.row, B.col], axis=1).ravel())), shape=(k, P + D))
    cons = [LinearConstraint(sparse.hstack([A, sparse.csr_matrix((A.shape[0], D))]), 1, np.inf),
            LinearConstraint(np.concatenate([c, np.zeros(D)])[None, :], -np.inf, best + 0.5),
            LinearConstraint(link, 0, np.inf)]
    obj = np.concatenate([np.zeros(P), np.ones(D)])
    res = milp(obj, integrality=np.ones(P + D), bounds=Bounds(0, 1), constraints=cons,
               options={"time_limit": time_limit})
    if res.x is None:
        return None
    return np.flatnonzero(res.x[:P] > 0.5)


def share_covers(cands: list[tuple[np.ndarray, np.ndarray]], on_rows: list[np.ndarray],
                 dc_rows: list[np.ndarray], costs: list[tuple[int, int]], n: int,
                 time_limit: float) -> list[np.ndarray] | None:
    """Fewest distinct cubes over all outputs, every output kept at its (terms, literals) cost.

    ``cands[i]`` are output i's candidate cubes (masks, values). Returns the chosen indices per
    output, or None when the solver found nothing in time.
    """
    keys: dict[tuple[int, int], int] = {}
    ymap, offsets, nvar = [], [], 0
    for masks, values in cands:
        offsets.append(nvar)
        ymap.append([keys.setdefault((m, v), len(keys))
                     for m, v in zip(masks.tolist(), values.tolist())])
        nvar += len(masks)
    T = len(keys)
    x0 = nvar
    nvar += T
    lits_all = _lits(np.array([k[0] for k in keys], dtype=np.int64))
    cons = []
    c = np.zeros(nvar)
    for i, (masks, values) in enumerate(cands):
        k = len(masks)
        A = coverage(masks, values, on_rows[i]).tocoo()
        cons.append(LinearConstraint(
            sparse.csr_matrix((A.data.astype(float), (A.row, A.col + offsets[i])),
                              shape=(A.shape[0], nvar)), 1, np.inf))
        terms_i, lits_i = costs[i]
        w = n * (terms_i + 1) + 1  # more terms than terms_i can never fit under the bound
        row = np.zeros(nvar)
        row[offsets[i]:offsets[i] + k] = w + _lits(masks)
        cons.append(LinearConstraint(row[None, :], -np.inf, w * terms_i + lits_i))
        # y <= x: a cube used by any output is built once
        link = sparse.csr_matrix(
            (np.tile([1.0, -1.0], k),
             (np.repeat(np.arange(k), 2),
              np.stack([x0 + np.array(ymap[i]), offsets[i] + np.arange(k)], 1).ravel())),
            shape=(k, nvar))
        cons.append(LinearConstraint(link, 0, np.inf))
        # faint preference for switching on fewer don't-care minterms
        if len(dc_rows[i]):
            dcount = np.asarray(coverage(masks, values, dc_rows[i]).sum(axis=0)).ravel()
            c[offsets[i]:offsets[i] + k] = dcount / (1e3 * (1 + len(dc_rows[i])) * (T + 1))
    c[x0:] = 1.0 + lits_all / (n * T + 1.0)
    res = milp(c, integrality=np.ones(nvar), bounds=Bounds(0, 1), constraints=cons,
               options={"time_limit": max(0.1, time_limit), "mip_rel_gap": 0.0})
    if res.x is None:
        return None
    return [np.flatnonzero(res.x[offsets[i]:offsets[i] + len(m)] > 0.5)
            for i, (m, _v) in enumerate(cands)]
