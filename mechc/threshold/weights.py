"""Integer weights and thresholds of a multithreshold realisation (001 §3.1, Haring's element).

A realisation of f is integer weights w, ascending thresholds T_1 < ... < T_k and the value
``below`` taken when the weighted sum s = w.x is below T_1; the output flips each time s crosses a
threshold: f(x) = below XOR (number of T_i < s(x)) mod 2. With integer weights every sum is an
integer, so thresholds sit halfway between adjacent occupied sums (0.5 clear of each).

Cost order, lowest first:

1. k, the number of thresholds (the cam's rises and returns);
2. the separator size sum |w_j|. This is the dissertation's k of Eq. (3.12): the span of s in
   unit steps, hence the number of separation angles the cam turns through (Fig. 29), so the
   smaller it is the larger each angle can be;
3. the number of static hazards (:func:`static_hazards`), which a threshold generator cannot
   avoid once the weights are chosen; over all 256 functions of 3 inputs ranking them third never
   costs a larger size (checked in tests), so 1-2-3 is also optimal for hazards;
4. max |w|, then fewer negative weights, then the lexicographically largest w (determinism).

Two independent exact methods: exhaustive search over integer weights in [-B, B]^n
(:func:`realise_search`) and a mixed-integer program solved by HiGHS (:func:`realise_milp`).
Both are exact within the same weight bound; the tests check they agree on every function of
three inputs and that raising the bound changes nothing.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence
from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from scipy.optimize import Bounds, LinearConstraint, linprog, milp

from mechc.threshold.functions import as_truth_table, input_matrix, n_inputs


@dataclass(frozen=True)
class Realisation:
    weights: tuple[int, ...]
    thresholds: tuple[float, ...]  # ascending
    below: int

    @property
    def k(self) -> int:
        return len(self.thresholds)

    @property
    def size(self) -> int:
        return int(sum(abs(w) for w in self.weights))

    @property
    def s_min(self) -> int:
        return int(sum(min(w, 0) for w in self.weights))

    def evaluate(self, x: np.ndarray) -> np.ndarray:
        """Output for input rows ``x`` (N, n) of 0/1."""
        s = np.asarray(x) @ np.asarray(self.weights)
        return (self.below + (s[:, None] > np.asarray(self.thresholds)[None, :]).sum(1)) % 2

    def truth_table(self) -> tuple[int, ...]:
        return tuple(int(v) for v in self.evaluate(input_matrix(len(self.weights))))

    def gaps(self) -> tuple[int, ...]:
        """Separation-angle index of each threshold: 0 for the step s_min -> s_min + 1 (the
        dissertation's tau_a), 1 for tau_b, ... (Fig. 29, Table IV's tau vector)."""
        return tuple(int(np.floor(t - self.s_min)) for t in self.thresholds)


def thresholds_for(weights: Sequence[int], tt: Sequence[int]
                   ) -> tuple[tuple[float, ...], int] | None:
    """The fewest thresholds that realise ``tt`` with these weights, or None if two minterms
    with equal sums need different outputs."""
    x = input_matrix(n_inputs(tt))
    s = x @ np.asarray(weights, dtype=np.int64)
    f = np.asarray(tt)
    order = np.argsort(s, kind="stable")
    ss, ff = s[order], f[order]
    same = ss[1:] == ss[:-1]
    change = ff[1:] != ff[:-1]
    if np.any(same & change):
        return None
    idx = np.flatnonzero(change & ~same)
    return tuple(float(ss[i] + ss[i + 1]) / 2 for i in idx), int(ff[0])


def static_hazards(weights: Sequence[int], tt: Sequence[int]) -> list[tuple[int, int]]:
    """Single-input changes whose output must hold but whose weighted sum passes a sum level of
    the other output value.

    Returned as (minterm with input j at 0, j). In a threshold generator the cam angle is a
    continuous, increasing function of s, so on such a change it sweeps through a rise and a
    return whatever the linkage dimensions are: the output glitches. No choice of weights avoids
    this for 48 of the 256 functions of three inputs (tests prove it by exhaustion).
    """
    n = n_inputs(tt)
    x = input_matrix(n)
    s = x @ np.asarray(weights, dtype=np.int64)
    f = np.asarray(tt)
    out = []
    for a in range(len(f)):
        for j in range(n):
            bit = 1 << (n - 1 - j)
            if a & bit:
                continue
            b = a | bit
            if f[a] != f[b]:
                continue
            lo, hi = sorted((s[a], s[b]))
            if np.any((s >= lo) & (s <= hi) & (f != f[a])):
                out.append((a, j))
    return out


def default_bound(n: int) -> int:
    """Weight bound of the search: (2**(n-1), ..., 2, 1) separates every minterm, so the search
    always finds a realisation; one more than that leaves room for the optimum."""
    return (1 << (n - 1)) + 1


@lru_cache(maxsize=8)
def _weight_grid(n: int, bound: int) -> np.ndarray:
    return np.array(list(itertools.product(range(-bound, bound + 1), repeat=n)), dtype=np.int64)


def _tie_key(w: np.ndarray) -> tuple:
    return (int(np.abs(w).max()) if len(w) else 0, int((w < 0).sum()), tuple(-int(v) for v in w))


def realise_search(f: Sequence[int] | int, bound: int | None = None, n: int = 3) -> Realisation:
    """Exhaustive search over integer weights in [-bound, bound]^n (vectorised over weights)."""
    tt = as_truth_table(f, n)
    n = n_inputs(tt)
    bound = default_bound(n) if bound is None else bound
    W = _weight_grid(n, bound)
    S = W @ input_matrix(n).T
    fv = np.asarray(tt)
    order = np.argsort(S, axis=1, kind="stable")
    ss = np.take_along_axis(S, order, 1)
    ff = fv[order]
    same = ss[:, 1:] == ss[:, :-1]
    change = ff[:, 1:] != ff[:, :-1]
    feasible = ~np.any(same & change, axis=1)
    k = np.where(feasible, (change & ~same).sum(1), 1 << 30)
    size = np.abs(W).sum(1)
    primary = k * 1000 + size
    cand = np.flatnonzero(primary == primary.min())
    best = min(cand, key=lambda i: (len(static_hazards(W[i], tt)), _tie_key(W[i])))
    th, below = thresholds_for(W[best], tt)
    return Realisation(tuple(int(v) for v in W[best]), th, below)


def realise(f: Sequence[int] | int, n: int = 3, bound: int | None = None) -> Realisation:
    """Minimum realisation by the cost order of this module (exhaustive search)."""
    return realise_search(f, bound=bound, n=n)


def _milp_size(tt: tuple[int, ...], k: int, below: int, bound: int
               ) -> tuple[float, np.ndarray] | None:
    """Smallest sum |w| with exactly k thresholds and the given ``below``, or None if none.

    Variables: w (integer, |w_j| <= bound), a_j >= |w_j|, thresholds T_1..T_k (real), and binary
    y[x, r] putting minterm x in region r (between T_r and T_r+1); only regions whose value
    below XOR (r mod 2) equals f(x) are allowed. Big-M rows keep s(x) 0.5 clear of the region's
    bounding thresholds, which loses nothing with integer sums.
    """
    n = n_inputs(tt)
    X = input_matrix(n)
    P = len(tt)
    regions = [[r for r in range(k + 1) if (below + r) % 2 == tt[p]] for p in range(P)]
    ys = [(p, r) for p in range(P) for r in regions[p]]
    nv = 2 * n + k + len(ys)
    iw, ia, it = 0, n, 2 * n
    iy = {pr: 2 * n + k + i for i, pr in enumerate(ys)}
    big = 2 * (n * bound + 1) + 1
    rows, lo, hi = [], [], []

    def row(coeffs: dict[int, float], lb: float, ub: float) -> None:
        r = np.zeros(nv)
        for i, c in coeffs.items():
            r[i] += c
        rows.append(r)
        lo.append(lb)
        hi.append(ub)

    for j in range(n):  # a_j >= |w_j|
        row({ia + j: 1, iw + j: -1}, 0, np.inf)
        row({ia + j: 1, iw + j: 1}, 0, np.inf)
    for r in range(k - 1):  # ascending thresholds, at least one unit apart
        row({it + r + 1: 1, it + r: -1}, 1, np.inf)
    for p in range(P):
        if not regions[p]:
            return None
        row({iy[(p, r)]: 1 for r in regions[p]}, 1, 1)
        sx = {iw + j: float(X[p, j]) for j in range(n)}
        for r in regions[p]:
            if r >= 1:  # s(x) - T_r >= 0.5 when in region r
                c = dict(sx)
                c[it + r - 1] = -1
                c[iy[(p, r)]] = -big
                row(c, 0.5 - big, np.inf)
            if r <= k - 1:  # T_{r+1} - s(x) >= 0.5
                c = {i: -v for i, v in sx.items()}
                c[it + r] = 1
                c[iy[(p, r)]] = -big
                row(c, 0.5 - big, np.inf)
    cost = np.zeros(nv)
    cost[ia:ia + n] = 1
    lb = np.concatenate([np.full(n, -bound), np.zeros(n), np.full(k, -n * bound - 1.0),
                         np.zeros(len(ys))])
    ub = np.concatenate([np.full(n, bound), np.full(n, bound), np.full(k, n * bound + 1.0),
                         np.ones(len(ys))])
    integrality = np.concatenate([np.ones(n), np.zeros(n + k), np.ones(len(ys))])
    res = milp(cost, constraints=LinearConstraint(np.array(rows), lo, hi),
               integrality=integrality, bounds=Bounds(lb, ub))
    if res.status == 2:  # infeasible
        return None
    if res.status != 0:
        raise RuntimeError(f"MILP for k={k}, below={below} ended with status {res.status}: "
                           f"{res.message}")
    return float(res.fun), np.round(res.x[:n]).astype(int)


def realise_milp(f: Sequence[int] | int, bound: int | None = None, n: int = 3) -> Realisation:
    """Minimum (k, sum |w|) by integer programming: k = 0, 1, 2, ... until feasible."""
    tt = as_truth_table(f, n)
    n = n_inputs(tt)
    bound = default_bound(n) if bound is None else bound
    if len(set(tt)) == 1:
        return Realisation((0,) * n, (), tt[0])
    for k in range(1, len(tt)):
        sols = [s for b in (0, 1) if (s := _milp_size(tt, k, b, bound)) is not None]
        if sols:
            _, w = min(sols, key=lambda s: s[0])
            th, below = thresholds_for(w, tt)
            if len(th) != k:
                raise RuntimeError(f"MILP weights {w} give {len(th)} thresholds, expected {k}")
            return Realisation(tuple(int(v) for v in w), th, below)
    raise RuntimeError(f"no realisation within weight bound {bound}")


def is_linearly_separable_lp(tt: Sequence[int]) -> bool:
    """Single-threshold test by linear programming (real weights): find w, t with
    w.x >= t + 1 on the ones and w.x <= t - 1 on the zeros (scale-free margin)."""
    n = n_inputs(tt)
    if len(set(tt)) == 1:
        return True
    X = input_matrix(n).astype(float)
    sign = np.where(np.asarray(tt) == 1, -1.0, 1.0)  # rows: sign*(w.x - t) <= -1
    A = sign[:, None] * np.hstack([X, -np.ones((len(tt), 1))])
    res = linprog(np.zeros(n + 1), A_ub=A, b_ub=-np.ones(len(tt)), bounds=[(None, None)] * (n + 1),
                  method="highs")
    if res.status not in (0, 2):
        raise RuntimeError(f"LP ended with status {res.status}: {res.message}")
    return res.status == 0


def separable_functions(n: int, bound: int) -> set[int]:
    """Every function of n inputs with at most one threshold and integer weights in
    [-bound, bound], generated from the weights (FV numbers, minterm 0 most significant)."""
    X = input_matrix(n)
    size = 1 << n
    place = 1 << (size - 1 - np.arange(size))
    out = {0, (1 << size) - 1}
    for w in _weight_grid(n, bound):
        s = X @ w
        levels = np.unique(s)
        for t in (levels[:-1] + levels[1:]) / 2:
            v = int((s > t).astype(np.int64) @ place)
            out.add(v)
            out.add((1 << size) - 1 - v)
    return out


def threshold_counts(n: int = 3, bound: int | None = None) -> dict[int, int]:
    """How many functions of n inputs need 0, 1, 2, ... thresholds, for every function at once
    (vectorised over functions for each weight vector)."""
    bound = default_bound(n) if bound is None else bound
    size = 1 << n
    fvs = np.arange(1 << size, dtype=np.int64)
    F = (fvs[:, None] >> (size - 1 - np.arange(size))[None, :]) & 1
    best = np.full(len(fvs), 1 << 30)
    X = input_matrix(n)
    for w in _weight_grid(n, bound):
        s = X @ w
        order = np.argsort(s, kind="stable")
        ss = s[order]
        ff = F[:, order]
        same = ss[1:] == ss[:-1]
        change = ff[:, 1:] != ff[:, :-1]
        ok = ~np.any(change[:, same], axis=1)
        k = change[:, ~same].sum(1)
        best = np.where(ok, np.minimum(best, k), best)
    vals, counts = np.unique(best, return_counts=True)
    return {int(v): int(c) for v, c in zip(vals, counts)}
