"""Static-1 hazard removal: add consensus terms so one product covers every single-input change.

In a linkage an OR bar's position is the max of its inputs and an AND bar's the min, so the sum of
products a·b + ā·c, with b = c = 1 while a moves, dips to half stroke mid-motion: the mechanical
form of a static-1 hazard (outputs must dwell: docs/mechanism.md). A cover is free of it when every
pair of adjacent care-1 minterms (differing in one input) lies inside a single cube; the cheapest
primes that cover the pairs the minimum cover misses are added (exact integer program
with a time limit, greedy fallback).
"""

from __future__ import annotations

import numpy as np
from scipy import sparse
from scipy.optimize import Bounds, LinearConstraint, milp

from mechc.logic.cubes import Cube


def adjacent_on_pairs(table: np.ndarray, n: int) -> list[tuple[np.ndarray, int]]:
    """(lower minterms, bit) for every input bit: both ends of the change are care-1."""
    on = table == 1
    idx = np.arange(len(table), dtype=np.int64)
    out = []
    for k in range(n):
        bit = 1 << (n - 1 - k)
        low = idx[((idx & bit) == 0) & on & on[idx | bit]]
        if len(low):
            out.append((low, bit))
    return out


def _pair_coverage(masks, values, pairs) -> tuple[sparse.csr_matrix, list[tuple[int, int]]]:
    rows, cols, flat = [], [], []
    r = 0
    for low, bit in pairs:
        ok_cube = (masks & bit) == 0
        hit = ((low[:, None] & masks[None, :]) == values[None, :]) & ok_cube[None, :]
        rr, cc = np.nonzero(hit)
        rows.append(rr + r)
        cols.append(cc)
        flat.extend((int(m), bit) for m in low)
        r += len(low)
    if r == 0:
        return sparse.csr_matrix((0, len(masks))), []
    rr, cc = np.concatenate(rows), np.concatenate(cols)
    return sparse.csr_matrix((np.ones(len(rr)), (rr, cc)), shape=(r, len(masks))), flat


def uncovered_pairs(cubes: list[Cube], table: np.ndarray, n: int):
    """Adjacent care-1 pairs that no single cube of the cover contains."""
    pairs = adjacent_on_pairs(table, n)
    out = []
    for low, bit in pairs:
        covered = np.zeros(len(low), dtype=bool)
        for c in cubes:
            if c.mask & bit:
                continue
            covered |= (low & c.mask) == c.value
        if (~covered).any():
            out.append((low[~covered], bit))
    return out


def hazard_free(cubes: list[Cube], table: np.ndarray, n: int, masks: np.ndarray,
                values: np.ndarray, time_limit: float = 5.0,
                timed_out: list[str] | None = None,
                shared: list[Cube] = ()) -> list[Cube]:
    """The cover plus the fewest (then smallest) candidate cubes that close every hazard.

    ``shared`` are products built anyway (for other outputs): those inside this output's
    on ∪ dc cost one OR input instead of a new cell, so they are taken first. When the
    program's time limit runs out its best answer (or a greedy one) is used and
    "hazard-free cover" is appended to ``timed_out``."""
    missing = uncovered_pairs(cubes, table, n)
    if not missing:
        return list(cubes)
    free = _inside_region([c for c in shared if c not in set(cubes)], table)
    if free:
        masks = np.concatenate([masks, np.array([c.mask for c in free], dtype=np.int64)])
        values = np.concatenate([values, np.array([c.value for c in free], dtype=np.int64)])
    A, _ = _pair_coverage(masks, values, missing)
    if A.shape[0] and (np.asarray(A.sum(axis=1)).ravel() == 0).any():
        # candidates miss a pair (they were a partial prime set): add the pair cubes' primes
        extra_m, extra_v = _expand_pairs(missing, table, n)
        masks = np.concatenate([masks, extra_m])
        values = np.concatenate([values, extra_v])
        A, _ = _pair_coverage(masks, values, missing)
    lits = np.array([int(m).bit_count() for m in masks], dtype=float)
    c = (n + 1) * len(masks) + lits
    if free:  # a product already built costs its OR input only
        is_free = np.isin(masks * (1 << n) + values,
                          [f.mask * (1 << n) + f.value for f in free])
        c[is_free] = 1.0
    res = milp(c, integrality=np.ones(len(masks)), bounds=Bounds(0, 1),
               constraints=[LinearConstraint(A, 1, np.inf)],
               options={"time_limit": time_limit})
    if res.x is not None:
        chosen = np.flatnonzero(res.x > 0.5)
    else:
        chosen = _greedy(A, c)
    if res.status != 0 and timed_out is not None:
        timed_out.append("hazard-free cover")
    have = set(cubes)
    added = [Cube(int(masks[i]), int(values[i])) for i in chosen]
    return list(cubes) + [a for a in added if a not in have]


def _greedy(A: sparse.csr_matrix, cost: np.ndarray) -> np.ndarray:
    A = A.tocsc()
    left = np.ones(A.shape[0], dtype=bool)
    chosen = []
    while left.any():
        gain = A.T @ left.astype(float)
        p = int(np.argmax(gain / cost))
        chosen.append(p)
        left &= ~(A[:, p].toarray().ravel() > 0)
    return np.array(chosen, dtype=np.int64)


def _expand_pairs(missing, table: np.ndarray, n: int):
    """A prime containing each missing pair, by greedy literal removal inside on ∪ dc."""
    region = table != 0
    full = (1 << n) - 1
    ms, vs = [], []
    for low, bit in missing:
        # a prime found for an earlier pair often holds this one too (a wide function has
        # thousands of missing pairs and a few primes): expanding each again cost minutes
        # and gigabytes of duplicate candidates
        left = np.ones(len(low), dtype=bool)
        if ms:
            am, av = np.array(ms, dtype=np.int64), np.array(vs, dtype=np.int64)
            ok = (am & bit) == 0
            am, av = am[ok], av[ok]
            for a in range(0, len(am), 256):
                left &= ~((low[:, None] & am[None, a:a + 256]) == av[None, a:a + 256]).any(1)
        for j in np.flatnonzero(left).tolist():
            if not left[j]:
                continue
            m = int(low[j])
            mask, value = full & ~bit, m & ~bit
            for k in range(n):
                b = 1 << (n - 1 - k)
                if not mask & b:
                    continue
                m2 = mask & ~b
                if _inside(region, m2, value & m2, n):
                    mask, value = m2, value & m2
            ms.append(mask)
            vs.append(value)
            left &= (low & mask) != value
    return np.array(ms, dtype=np.int64), np.array(vs, dtype=np.int64)


def _inside(region, mask, value, n) -> bool:
    pts = np.array([value], dtype=np.int64)
    for k in range(n):
        b = 1 << (n - 1 - k)
        if not mask & b:
            pts = np.concatenate([pts, pts | b])
    return bool(region[pts].all())


def _inside_region(cubes: list[Cube], table: np.ndarray) -> list[Cube]:
    """The cubes with no point where the table is 0."""
    if not cubes:
        return []
    off = np.flatnonzero(table == 0).astype(np.int64)
    out = []
    for a in range(0, len(cubes), 64):
        blk = cubes[a:a + 64]
        m = np.array([c.mask for c in blk], dtype=np.int64)
        v = np.array([c.value for c in blk], dtype=np.int64)
        meets = ((off[:, None] & m[None, :]) == v[None, :]).any(axis=0)
        out.extend(c for c, bad in zip(blk, meets) if not bad)
    return out
