"""Heuristic unate covering for problems too large for the integer program.

The multi-output covering problems of wide PLAs have thousands of rows and up to tens of
thousands of columns (ex1010: 1,471 x 25,203). There HiGHS spent 100 s on the LP relaxation
alone and its 30 s incumbent was far worse than a plain greedy cover. This module finds a
small cover by:

* greedy: the column covering the most uncovered rows, then the cheaper one (gains kept
  incrementally: picking a column lowers the gain of every column sharing a newly covered row);
* redundancy removal: a chosen column all of whose rows are covered twice is dropped;
* iterated greedy (local search): remove a chosen column with the chosen columns around it,
  cover the rows left open again greedily (ties broken at random), drop redundant columns, and
  keep the result when it has no more columns. The best cover (fewest columns, then least
  cost) seen is returned.

A starting cover (e.g. espresso's) can be given, so the result is never worse than it.
Nothing here is proven minimal.
"""

from __future__ import annotations

import time

import numpy as np
from scipy import sparse

from mechc.logic.clock import floors_hold


def _gather(indptr: np.ndarray, indices: np.ndarray, which: np.ndarray) -> np.ndarray:
    """The concatenated index lists of the rows (or columns) ``which``."""
    if len(which) <= 8:  # the common case in the local search: a few slices
        if len(which) == 1:
            w = int(which[0])
            return indices[indptr[w]:indptr[w + 1]]
        return np.concatenate([indices[indptr[w]:indptr[w + 1]] for w in which.tolist()]) \
            if len(which) else np.zeros(0, dtype=indices.dtype)
    starts = indptr[which]
    lens = indptr[which + 1] - starts
    total = int(lens.sum())
    if total == 0:
        return np.zeros(0, dtype=indices.dtype)
    shift = np.repeat(starts - np.concatenate([[0], np.cumsum(lens)[:-1]]), lens)
    return indices[shift + np.arange(total)]


class _Cover:
    """A cover under construction: chosen columns and how often each row is covered."""

    def __init__(self, A: sparse.csr_matrix, cost: np.ndarray):
        A = sparse.csr_matrix(A)
        A.sum_duplicates()
        self.rows_of = A.tocsc()  # column j -> its rows
        self.cols_of = A  # row r -> its columns
        self.nr, self.nc = A.shape
        self.cost = np.asarray(cost, dtype=np.float64)
        span = float(self.cost.max() - self.cost.min()) if self.nc else 0.0
        # gain first, then cost: the cost term stays below one row's gain
        self.tie = (self.cost - (self.cost.min() if self.nc else 0.0)) / (2.0 * span + 2.0)

    def col_rows(self, j: int) -> np.ndarray:
        c = self.rows_of
        return c.indices[c.indptr[j]:c.indptr[j + 1]]

    def repair(self, chosen: np.ndarray, cov: np.ndarray, rng: np.random.Generator | None):
        """Add columns greedily until every row is covered."""
        open_rows = np.flatnonzero(cov == 0)
        if not len(open_rows):
            return
        ptr, idx = self.cols_of.indptr, self.cols_of.indices
        cols = _gather(ptr, idx, open_rows)
        gain = np.bincount(cols, minlength=self.nc).astype(np.float64)
        cand = np.flatnonzero(gain)
        if not len(cand) and len(open_rows):
            raise ValueError("a row no column covers")
        remaining = len(open_rows)
        noise = rng.random(self.nc) * 1e-3 if rng is not None else None
        while remaining:
            score = gain[cand] - self.tie[cand]
            if noise is not None:
                score = score + noise[cand] * (gain[cand] > 0)
            j = int(cand[int(np.argmax(score))])
            if gain[j] <= 0:
                raise ValueError("a row no column covers")
            rows = self.col_rows(j)
            newly = rows[cov[rows] == 0]
            cov[rows] += 1
            chosen[j] = True
            remaining -= len(newly)
            np.subtract.at(gain, _gather(ptr, idx, newly), 1.0)
            cand = cand[gain[cand] > 0]

    def prune(self, chosen: np.ndarray, cov: np.ndarray, rng: np.random.Generator | None):
        """Drop chosen columns whose rows are all covered by others (costliest first)."""
        js = np.flatnonzero(chosen)
        if rng is not None:
            js = js[rng.permutation(len(js))]
        order = js[np.argsort(-self.cost[js], kind="stable")]
        for j in order.tolist():
            rows = self.col_rows(j)
            if (cov[rows] >= 2).all():
                cov[rows] -= 1
                chosen[j] = False

    def value(self, chosen: np.ndarray) -> tuple[int, float]:
        return int(chosen.sum()), float(self.cost[chosen].sum())


def heuristic_cover(A: sparse.csr_matrix, cost: np.ndarray, time_limit: float,
                    start: np.ndarray | None = None, seed: int = 0,
                    max_steps: int | None = None, min_steps: int = 0) -> np.ndarray:
    """Column indices of a cover of every row of ``A`` with few columns (then little
    ``cost``): greedy (or ``start``, column indices of a cover), redundancy removal, then row
    weighting local search until ``time_limit`` (or ``max_steps`` steps), but at least
    ``min_steps`` steps when the time limit is positive (a result that does not depend on
    how busy the machine is; the floor gives way near the minimisation's hard end,
    ``clock.floors_hold``)."""
    t_end = time.perf_counter() + time_limit
    S = _Cover(A, cost)
    if S.nr == 0:
        return np.zeros(0, dtype=np.int64)
    chosen = np.zeros(S.nc, dtype=bool)
    cov = np.zeros(S.nr, dtype=np.int32)
    if start is not None and len(start):
        chosen[np.asarray(start, dtype=np.int64)] = True
        cov += np.bincount(_gather(S.rows_of.indptr, S.rows_of.indices,
                                   np.flatnonzero(chosen)), minlength=S.nr).astype(np.int32)
    S.repair(chosen, cov, None)
    S.prune(chosen, cov, None)
    if time_limit <= 0 or chosen.sum() <= 1:
        return np.flatnonzero(chosen)
    return _row_weighting(S, chosen, cov, t_end, np.random.default_rng(seed), max_steps,
                          min_steps)


def _row_weighting(S: _Cover, chosen: np.ndarray, cov: np.ndarray, t_end: float,
                   rng: np.random.Generator, max_steps: int | None,
                   min_steps: int = 0) -> np.ndarray:
    """Row weighting local search for unate covering (after Gao et al., 2015): with k columns
    covering everything, drop one and look for a cover of k - 1 by swapping columns; rows left
    open gain weight, so the search is pushed towards covering the hard ones. A column's
    score is the weight it would newly cover (unchosen) or leave open (chosen, negated);
    a column just removed may come back only after a neighbour changed (configuration
    checking), the one just added is not removed next."""
    rp, ri = S.rows_of.indptr, S.rows_of.indices  # column -> rows
    cp, ci = S.cols_of.indptr, S.cols_of.indices  # row -> columns
    w = np.ones(S.nr, dtype=np.float64)
    score = np.zeros(S.nc, dtype=np.float64)
    # scores from scratch: chosen columns lose the rows only they cover
    once = np.flatnonzero(cov == 1)
    cols = _gather(cp, ci, once)
    rep = np.repeat(once, np.diff(cp)[once])  # each row once per column it has
    sel = chosen[cols]
    np.subtract.at(score, cols[sel], w[rep[sel]])
    stamp = np.zeros(S.nc, dtype=np.int64)
    can_add = np.ones(S.nc, dtype=bool)
    tie = S.tie
    best, best_val = chosen.copy(), S.value(chosen)
    n_open = 0
    step = 0

    rdeg = np.diff(cp)

    def rows_with_cols(rows: np.ndarray):
        c = _gather(cp, ci, rows)
        return c, np.repeat(rows, rdeg[rows])

    def add(j: int) -> int:
        rows = ri[rp[j]:rp[j + 1]]
        c = cov[rows]
        newly = rows[c == 0]
        if len(newly):
            k, r = rows_with_cols(newly)
            np.subtract.at(score, k, w[r])
        one = rows[c == 1]
        if len(one):
            k, r = rows_with_cols(one)
            sel = chosen[k]
            np.add.at(score, k[sel], w[r[sel]])
        cov[rows] += 1
        chosen[j] = True
        score[j] = -w[rows[cov[rows] == 1]].sum()
        can_add[_gather(cp, ci, rows)] = True
        return len(newly)

    def remove(j: int) -> int:
        rows = ri[rp[j]:rp[j + 1]]
        cov[rows] -= 1
        chosen[j] = False
        gone = rows[cov[rows] == 0]
        if len(gone):
            k, r = rows_with_cols(gone)
            np.add.at(score, k, w[r])
        one = rows[cov[rows] == 1]
        if len(one):
            k, r = rows_with_cols(one)
            sel = chosen[k]
            np.subtract.at(score, k[sel], w[r[sel]])
        score[j] = w[gone].sum()
        can_add[_gather(cp, ci, rows)] = True
        can_add[j] = False
        return len(gone)

    def worst_chosen(exclude: int) -> int:
        js = np.flatnonzero(chosen)
        if exclude >= 0 and len(js) > 1:
            js = js[js != exclude]
        key = score[js] + tie[js] * 0.0
        top = js[key == key.max()]
        return int(top[np.argmin(stamp[top])])

    last = -1
    while ((step < min_steps and floors_hold() or time.perf_counter() < t_end)
           and (max_steps is None or step < max_steps)):
        step += 1
        while n_open == 0:
            val = S.value(chosen)
            if val < best_val:
                best, best_val = chosen.copy(), val
            if val[0] <= 1:
                return np.flatnonzero(best)
            j = worst_chosen(-1)
            n_open += remove(j)
            stamp[j] = step
        j = worst_chosen(last)
        n_open += remove(j)
        stamp[j] = step
        open_rows = np.flatnonzero(cov == 0)
        r = int(open_rows[rng.integers(len(open_rows))])
        cand = ci[cp[r]:cp[r + 1]]
        ok = cand[can_add[cand]]
        if not len(ok):
            ok = cand
        key = score[ok] - tie[ok]
        top = ok[key == key.max()]
        k = int(top[np.argmin(stamp[top])])
        n_open -= add(k)
        stamp[k] = step
        last = k
        # rows still open weigh more
        open_rows = np.flatnonzero(cov == 0)
        if len(open_rows):
            w[open_rows] += 1.0
            kk, rr = rows_with_cols(open_rows)
            np.add.at(score, kk, 1.0)
    if n_open == 0:
        val = S.value(chosen)
        if val < best_val:
            best = chosen.copy()
    return np.flatnonzero(best)
