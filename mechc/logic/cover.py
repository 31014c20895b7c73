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

from mechc.logic.setcover import heuristic_cover

DC_TIEBREAK_MAX_NNZ = 200_000
#: Dominance between rows (columns) needs their pairwise product; past this many pairs the
#: reduction stops at the essential columns (the product alone would take gigabytes).
DOMINANCE_MAX_PAIRS = 30_000_000
#: Covering problems up to this size are reduced on dense bit sets (``reduce_dense``).
DENSE_MIN_ROWS = 5_000
DENSE_MAX_COLUMNS = 20_000
DENSE_MAX_CELLS = 400_000_000
#: The share of ``solve_cover``'s time limit the dense reductions may take.
DENSE_TIME_SHARE = 0.4
#: The don't-care tie-break is a nicety for hand-sized specs; past this many candidates it is
#: skipped (it can take longer than the cover itself).
DC_TIEBREAK_MAX_CANDIDATES = 300


#: Row weighting local search steps when the program runs out of time (on ex1010's outputs
#: 1,500 steps, 0.2 s each, came within 1.5 % of the minimum terms; the greedy cover, 45 %).
FALLBACK_STEPS = 1_500


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
        # row dominance: if row i's columns are a subset of row j's, row j is implied (the
        # pairwise product is skipped when it would be too large to hold)
        col_deg = np.bincount(sub.indices, minlength=sub.shape[1]).astype(np.int64)
        if int((col_deg * col_deg).sum()) > DOMINANCE_MAX_PAIRS:
            break
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
        row_deg = np.diff(sub.tocsr().indptr).astype(np.int64)
        if int((row_deg * row_deg).sum()) > DOMINANCE_MAX_PAIRS:
            break
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
    covers, one switching on the fewest don't-care rows (a second, time-capped program).
    ``time_limit`` <= 0: the greedy cover only (method ``greedy``)."""
    t0 = time.perf_counter()
    P = len(masks)
    if len(on_rows) == 0:
        return CoverResult(np.zeros(0, dtype=np.int64), True, "exact", 0.0)
    A = coverage(masks, values, on_rows)
    lits = _lits(masks)
    g = greedy_cover(A, 1.0 + lits / (n + 1.0))
    if time_limit <= 0:  # no time for a program (the caller's clock is out): greedy
        return CoverResult(np.sort(g), False, "greedy", time.perf_counter() - t0)
    w_term = n * len(g) + 1  # more than any literal difference between covers of equal size
    c = (w_term + lits).astype(float)
    forced, rows, cols = reduce_problem(A, c)
    if len(rows) == 0:
        chosen, proven = forced, True
    else:
        picked, proven = _terms_then_cost(A[rows][:, cols], lits[cols].astype(float),
                                          lambda: max(0.1, time_limit - (time.perf_counter()
                                                                         - t0)))
        if picked is None or not proven:  # out of time: local search, if it does better
            got = heuristic_cover(A[rows][:, cols], lits[cols], time_limit,
                                  max_steps=FALLBACK_STEPS, min_steps=FALLBACK_STEPS)
            alt = np.sort(np.concatenate([forced, cols[got]]))
            if picked is None or (len(alt), lits[alt].sum()) < (
                    len(forced) + picked.sum(), lits[forced].sum() + lits[cols[picked]].sum()):
                return CoverResult(alt, False, "local search", time.perf_counter() - t0)
        chosen = np.sort(np.concatenate([forced, cols[picked]]))
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


def solve_cover(A: sparse.csr_matrix, lits: np.ndarray, n: int,
                time_limit: float) -> tuple[np.ndarray, bool]:
    """Fewest columns covering every row of ``A``, then the least total ``lits`` (a cost per
    column: literals, or parts) with that count.

    Returns (chosen column indices, proven). When the time limit runs out the better of the
    solver's incumbent and the greedy cover is returned, unproven."""
    t0 = time.perf_counter()
    if A.shape[0] == 0:
        return np.zeros(0, dtype=np.int64), True
    lits = np.asarray(lits, dtype=np.int64)
    A = unique_rows(A)
    g = greedy_cover(A, 1.0 + lits / (n + 1.0))
    c = (n * len(g) + 1 + lits).astype(float)
    forced, rows, cols = reduce_problem(A, c)
    # the sparse reduction stops where its pairwise products grow too large: many rows left
    # are then reduced on bit sets
    if (len(rows) > DENSE_MIN_ROWS and len(cols) <= DENSE_MAX_COLUMNS
            and len(rows) * len(cols) <= DENSE_MAX_CELLS):
        f2, r2, c2 = reduce_dense(A[rows][:, cols], c[cols],
                                  t0 + DENSE_TIME_SHARE * time_limit)
        forced = np.union1d(forced, cols[f2]).astype(np.int64)
        rows, cols = rows[r2], cols[c2]
    if len(rows) == 0:
        return forced, True
    picked, proven = _terms_then_cost(
        A[rows][:, cols], lits[cols].astype(float),
        lambda: max(0.05, time_limit - (time.perf_counter() - t0)), len(g) - len(forced))
    if picked is None:
        return g, False
    return np.sort(np.concatenate([forced, cols[picked]])), proven


def _terms_then_cost(sub: sparse.csr_matrix, cost: np.ndarray, remaining,
                     max_terms: int | None = None) -> tuple[np.ndarray | None, bool]:
    """The columns of a cover of every row of ``sub``: fewest columns, then the least ``cost``
    with that count fixed — two programs, several times faster on cyclic random problems than
    one lexicographic objective. ``remaining()`` gives each program's time limit. Returns (a
    mask over the columns, proven), or (None, False) when no cover was found or the fewest
    exceed ``max_terms`` (the caller has a cover that good already)."""
    cover_rows = LinearConstraint(sub, 1, np.inf)
    ones = np.ones(sub.shape[1])
    res = milp(ones, integrality=ones, bounds=Bounds(0, 1), constraints=[cover_rows],
               options={"time_limit": remaining()})
    if res.x is None:
        return None, False
    terms = int(round(res.x.sum()))
    if max_terms is not None and terms > max_terms:
        return None, False
    res2 = milp(cost, integrality=ones, bounds=Bounds(0, 1),
                constraints=[cover_rows, LinearConstraint(ones[None, :], terms, terms)],
                options={"time_limit": remaining(), "mip_rel_gap": 0.0})
    x = res2.x if res2.x is not None else res.x
    return x > 0.5, res.status == 0 and res2.status == 0


def unique_rows(A: sparse.csr_matrix) -> sparse.csr_matrix:
    """One row per distinct column set (on-minterms inside the same cubes are one constraint);
    rows are told apart by two random 64-bit signatures of their column sets."""
    A = sparse.csr_matrix(A)
    A.sum_duplicates()
    A.sort_indices()
    rng = np.random.default_rng(0)
    sig = []
    for _ in range(2):
        w = rng.integers(1, 2**63 - 1, size=A.shape[1], dtype=np.int64).astype(np.uint64)
        vals = np.concatenate([w[A.indices], np.zeros(1, dtype=np.uint64)])
        starts = A.indptr[:-1]
        s = np.add.reduceat(vals, np.minimum(starts, len(vals) - 1))
        s[np.diff(A.indptr) == 0] = 0
        sig.append(s)
    _, first = np.unique(np.stack(sig, axis=1), axis=0, return_index=True)
    return A[np.sort(first)]


def _packed(D: np.ndarray) -> np.ndarray:
    """Boolean (k, c) -> (k, ceil(c/64)) uint64 words."""
    pad = (-D.shape[1]) % 64
    if pad:
        D = np.concatenate([D, np.zeros((D.shape[0], pad), dtype=bool)], axis=1)
    return np.packbits(D, axis=1, bitorder="little").view(np.uint64)


def _minimal_sets(B: np.ndarray, deg: np.ndarray, cost: np.ndarray | None = None,
                  block_words: int = 20_000_000, deadline: float | None = None) -> np.ndarray:
    """Which bit sets (rows of packed B) contain no other set of the list: with ``cost``
    None, a set is dropped if a strictly smaller one lies inside it (row dominance: the
    larger constraint is implied); with ``cost``, sets are columns and one is dropped if it
    lies inside another that costs no more (column dominance; ties keep the lower index).
    Past ``deadline`` (``time.perf_counter``) the sets not yet looked at are kept."""
    k, W = B.shape
    keep = np.ones(k, dtype=bool)
    if cost is None:
        order = np.argsort(deg, kind="stable")
        kept: list[int] = []
        s = 0
        while s < k:
            if deadline is not None and time.perf_counter() > deadline:
                break
            d = deg[order[s]]
            e = s
            while e < k and deg[order[e]] == d:
                e += 1
            grp = order[s:e]
            if kept:
                K = B[np.array(kept)]
                step = max(1, block_words // max(1, len(K) * W))
                for a in range(0, len(grp), step):
                    g = grp[a:a + step]
                    inside = ((K[None, :, :] & ~B[g][:, None, :]) == 0).all(axis=2)
                    keep[g[inside.any(axis=1)]] = False
            kept.extend(int(x) for x in grp if keep[x])
            s = e
        return keep
    step = max(1, block_words // max(1, k * W))
    for a in range(0, k, step):
        if deadline is not None and time.perf_counter() > deadline:
            break
        P = B[a:a + step]
        # q contains p: p & ~q == 0
        inside = ((P[:, None, :] & ~B[None, :, :]) == 0).all(axis=2)
        idx = np.arange(a, min(k, a + step))
        better = (cost[None, :] < cost[idx][:, None]) | (
            (cost[None, :] == cost[idx][:, None])
            & ((deg[None, :] > deg[idx][:, None]) | ((deg[None, :] == deg[idx][:, None])
                                                     & (np.arange(k)[None, :] < idx[:, None]))))
        inside &= better
        inside[np.arange(len(idx)), idx] = False
        keep[idx] = ~inside.any(axis=1)
    return keep


def reduce_dense(A: sparse.csr_matrix, cost: np.ndarray, deadline: float | None = None):
    """``reduce_problem`` on bit sets (rows and columns as packed words), for covering
    problems with many rows and a few thousand columns at most. Past ``deadline`` it stops
    where it is (what it returns is still the same problem, only less reduced): on a random
    18-output PLA the dominance checks alone took 7 s of CPU."""
    D = A.toarray().astype(bool)
    rows = np.arange(D.shape[0])
    cols = np.arange(D.shape[1])
    forced: list[int] = []
    while True:
        S = D[np.ix_(rows, cols)]
        if S.shape[0] == 0:
            break
        deg = S.sum(axis=1)
        if (deg == 0).any():
            raise ValueError("a row no candidate covers")
        ess = np.unique(np.argmax(S[deg == 1], axis=1))
        if len(ess):
            forced.extend(cols[ess].tolist())
            rows = rows[~S[:, ess].any(axis=1)]
            keep = np.ones(len(cols), dtype=bool)
            keep[ess] = False
            cols = cols[keep]
            continue
        if deadline is not None and time.perf_counter() > deadline:
            break
        keep_r = _minimal_sets(_packed(S), deg, deadline=deadline)
        rows = rows[keep_r]
        S = S[keep_r]
        csize = S.sum(axis=0)
        keep_c = _minimal_sets(_packed(S.T), csize, cost[cols], deadline=deadline) & (csize > 0)
        cols = cols[keep_c]
        if keep_r.all() and keep_c.all():
            break
    return np.array(sorted(set(forced)), dtype=np.int64), rows, cols
