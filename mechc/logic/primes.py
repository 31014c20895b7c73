"""All prime implicants of a function given as a truth table (on ∪ don't-care region).

Recursive Shannon expansion: primes(f) are the maximal cubes among  x̄·primes(f0),
x·primes(f1) and the pairwise intersections primes(f0) ∧ primes(f1). Identical cofactors are
detected (no literal on that variable) and cofactors are memoised, so structured functions stay
cheap; cube sets are numpy arrays so the pairwise steps are vectorised.
"""

from __future__ import annotations

import time

import numpy as np

_EMPTY = (np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64))


class TooManyPrimes(Exception):
    """Raised when the prime count passes the caller's cap (the exact method is not practical)."""


def prime_implicants(region: np.ndarray, limit: int | None = None,
                     deadline: float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Primes of the boolean table ``region`` (length 2**n): arrays (masks, values), sorted.
    Raises TooManyPrimes past ``limit`` primes or past the clock time ``deadline``."""
    size = len(region)
    n = size.bit_length() - 1
    if size != 1 << n:
        raise ValueError("table length must be a power of two")
    memo: dict[bytes, tuple[np.ndarray, np.ndarray]] = {}
    masks, values = _primes(np.ascontiguousarray(region, dtype=bool), n, 0, memo,
                            (limit, deadline))
    order = np.lexsort((values, masks))
    return masks[order], values[order]


def _primes(f: np.ndarray, n: int, k: int, memo, caps):
    """Primes of cofactor ``f`` over variables k..n-1 (bit of variable k is 1 << (n-1-k))."""
    if not f.any():
        return _EMPTY
    if f.all():
        return np.zeros(1, dtype=np.int64), np.zeros(1, dtype=np.int64)
    key = None
    if len(f) <= 4096:
        key = f.tobytes()
        hit = memo.get(key)
        if hit is not None:
            return hit
    half = len(f) // 2
    f0, f1 = f[:half], f[half:]
    bit = np.int64(1 << (n - 1 - k))
    if np.array_equal(f0, f1):
        res = _primes(f0, n, k + 1, memo, caps)
    else:
        m0, v0 = _primes(f0, n, k + 1, memo, caps)
        m1, v1 = _primes(f1, n, k + 1, memo, caps)
        limit, deadline = caps
        if deadline is not None and time.perf_counter() > deadline:
            raise TooManyPrimes("time")
        # pairwise intersections (consensus on x_k): cubes without a literal on x_k
        if limit is not None and len(m0) + len(m1) > limit:
            raise TooManyPrimes(len(m0) + len(m1))
        if len(m0) and len(m1):
            cm, cv = _consensus(m0, v0, m1, v1)
        else:
            cm = cv = np.zeros(0, dtype=np.int64)
        # x̄·p survives unless p itself is among the intersections (then p ⊂ f1 too)
        keep0 = ~_member(m0, v0, cm, cv)
        keep1 = ~_member(m1, v1, cm, cv)
        masks = np.concatenate([cm, m0[keep0] | bit, m1[keep1] | bit])
        values = np.concatenate([cv, v0[keep0], v1[keep1] | bit])
        res = (masks, values)
        if caps[0] is not None and len(masks) > caps[0]:
            raise TooManyPrimes(len(masks))
    if key is not None:
        memo[key] = res
    return res


def _consensus(m0, v0, m1, v1, budget: int = 4_000_000):
    """Maximal cubes among all consistent intersections p ∧ q (p from set 0, q from set 1)."""
    step = max(1, budget // max(1, len(m1)))
    parts_m, parts_v = [], []
    for s in range(0, len(m0), step):
        a_m, a_v = m0[s:s + step, None], v0[s:s + step, None]
        ok = ((a_v ^ v1[None, :]) & a_m & m1[None, :]) == 0
        pm, pv = _unique((a_m | m1[None, :])[ok], (a_v | v1[None, :])[ok])
        parts_m.append(pm)
        parts_v.append(pv)
    cm, cv = _unique(np.concatenate(parts_m), np.concatenate(parts_v))
    return _maximal(cm, cv)


def _unique(m: np.ndarray, v: np.ndarray):
    if len(m) == 0:
        return m, v
    pairs = np.unique(np.stack([m, v], axis=1), axis=0)
    return pairs[:, 0].copy(), pairs[:, 1].copy()


def _member(m, v, cm, cv) -> np.ndarray:
    if len(cm) == 0 or len(m) == 0:
        return np.zeros(len(m), dtype=bool)
    return ((m[:, None] == cm[None, :]) & (v[:, None] == cv[None, :])).any(axis=1)


def _maximal(m: np.ndarray, v: np.ndarray, block: int = 2048):
    """Drop every cube contained in another (distinct) cube of the set."""
    if len(m) <= 1:
        return m, v
    # fewer literals first: a cube can only be contained in one with fewer (or equal) literals
    lits = np.array([int(x).bit_count() for x in m])
    order = np.argsort(lits, kind="stable")
    m, v, lits = m[order], v[order], lits[order]
    keep = np.ones(len(m), dtype=bool)
    for s in range(0, len(m), block):
        bm, bv, bl = m[s:s + block], v[s:s + block], lits[s:s + block]
        # container a contains b iff a.mask ⊆ b.mask and b.value agrees with a on a.mask
        cont = ((m[None, :] & ~bm[:, None]) == 0) & ((bv[:, None] & m[None, :]) == v[None, :])
        cont &= lits[None, :] < bl[:, None]  # strictly larger cubes only (set is unique)
        keep[s:s + block] = ~cont.any(axis=1)
    return m[keep], v[keep]
