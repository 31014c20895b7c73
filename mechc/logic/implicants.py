"""Every cube of a small input space at once: the ternary table of multi-output implicants.

For n inputs there are 3**n cubes (each input 0, 1 or absent). Stored as an n-dimensional
array with three entries per axis (index 2 = the input is absent), the outputs whose on ∪ dc
region holds a cube are the AND of its two halves' entries, so the whole table is n
vectorised steps and costs about 3**n words. A cube c with outputs S = T[c] is a
multi-output prime exactly when every cube one literal larger has fewer outputs (T[c'] ≠ T[c]:
T only shrinks as a cube grows), which is again n vectorised comparisons. Up to ~15 inputs
this enumerates the multi-output primes of the MCNC PLAs in well under a second, where the
Shannon recursion of ``multi.multi_primes`` took seconds or gave up.

The cover's rows are (output i, on-minterm x); ``cover_matrix`` lists each prime's points
directly (``cube_points``) instead of testing every row against every cube.
"""

from __future__ import annotations

import numpy as np
from scipy import sparse

#: Tables above this many bytes are not built (the caller falls back to the heuristic).
MAX_TABLE_BYTES = 160_000_000


def _dtype(m: int) -> np.dtype:
    for t in (np.uint8, np.uint16, np.uint32, np.uint64):
        if m <= 8 * np.dtype(t).itemsize:
            return np.dtype(t)
    raise ValueError("at most 64 outputs")


def table_fits(n: int, m: int) -> bool:
    """Would the ternary table of n inputs and m outputs stay within ``MAX_TABLE_BYTES``?"""
    return m <= 64 and 3 ** n * _dtype(m).itemsize <= MAX_TABLE_BYTES


def ternary_table(sets: np.ndarray, n: int, m: int, combine=np.bitwise_and) -> np.ndarray:
    """(2**n,) per-minterm output masks -> (3**n,) per-cube ``combine`` of its points' masks.

    Cube index: Σ d_k 3**(n-1-k) with d_k = 0, 1 or 2 (absent) for input k (input 0 the
    most significant, as mechc's minterm numbering)."""
    dt = _dtype(m)
    T = np.empty((3,) * n, dtype=dt)
    T[(slice(0, 2),) * n] = np.asarray(sets).astype(dt).reshape((2,) * n)
    for k in range(n):
        # axes < k are complete (0..2); axes > k still hold minterms (0..1)
        lead = (slice(None),) * k
        tail = (slice(0, 2),) * (n - k - 1)
        combine(T[lead + (slice(0, 1),) + tail], T[lead + (slice(1, 2),) + tail],
                out=T[lead + (slice(2, 3),) + tail])
    return T.reshape(-1)


def prime_mask(T: np.ndarray, n: int) -> np.ndarray:
    """Which cubes are multi-output primes: non-empty output set, and every cube one literal
    larger holds fewer outputs. Returns the ternary indices of the primes (ascending)."""
    P = T != 0
    k = 0
    # dense passes while many candidates are left, then only the candidates' parents
    while k < n and P.sum() > len(P) // 16:
        v = T.reshape(3 ** k, 3, 3 ** (n - k - 1))
        p = P.reshape(3 ** k, 3, 3 ** (n - k - 1))
        p[:, 0, :] &= v[:, 0, :] != v[:, 2, :]
        p[:, 1, :] &= v[:, 1, :] != v[:, 2, :]
        k += 1
    idx = np.flatnonzero(P)
    for j in range(k, n):
        step = np.int64(3) ** np.int64(n - 1 - j)
        d = (idx // step) % 3
        idx = idx[(d == 2) | (T[idx] != T[idx + (2 - d) * step])]
    return idx


def decode(idx: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Ternary cube indices -> (masks, values) in mechc's cube bits (input k at bit n-1-k)."""
    idx = np.asarray(idx, dtype=np.int64)
    masks = np.zeros(len(idx), dtype=np.int64)
    values = np.zeros(len(idx), dtype=np.int64)
    rest = idx.copy()
    for k in range(n - 1, -1, -1):  # least significant ternary digit = input n-1 = bit 0
        d = rest % 3
        rest //= 3
        b = np.int64(1) << np.int64(n - 1 - k)
        masks |= np.where(d != 2, b, 0)
        values |= np.where(d == 1, b, 0)
    return masks, values


def encode(masks: np.ndarray, values: np.ndarray, n: int) -> np.ndarray:
    """(masks, values) -> ternary cube indices."""
    masks = np.asarray(masks, dtype=np.int64)
    values = np.asarray(values, dtype=np.int64)
    idx = np.zeros(len(masks), dtype=np.int64)
    for k in range(n):
        b = np.int64(1) << np.int64(n - 1 - k)
        d = np.where((masks & b) == 0, 2, np.where((values & b) != 0, 1, 0))
        idx = idx * 3 + d
    return idx


def multi_output_primes(region: np.ndarray, n: int):
    """Multi-output primes of the (m, 2**n) regions: (masks, values, output masks, the ternary
    table of ``ternary_table``)."""
    m = region.shape[0]
    w = np.left_shift(np.uint64(1), np.arange(m, dtype=np.uint64))
    sets = (region.astype(np.uint64) * w[:, None]).sum(axis=0, dtype=np.uint64)
    T = ternary_table(sets, n, m)
    idx = prime_mask(T, n)
    masks, values = decode(idx, n)
    return masks, values, T[idx].astype(np.int64), T


def cube_points(masks: np.ndarray, values: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Every (cube index, minterm) pair with the minterm inside the cube."""
    cid = np.arange(len(masks), dtype=np.int64)
    pts = np.asarray(values, dtype=np.int64).copy()
    for k in range(n):
        b = np.int64(1) << np.int64(k)
        free = (masks[cid] & b) == 0
        cid = np.concatenate([cid, cid[free]])
        pts = np.concatenate([pts, pts[free] | b])
    return cid, pts


def cover_matrix(masks: np.ndarray, values: np.ndarray, outs: np.ndarray, on: np.ndarray,
                 n: int) -> sparse.csr_matrix:
    """Rows (output i, on-minterm x) in output-major order x columns (cubes, each allowed for
    the outputs of its mask ``outs``): 1 where the cube covers the row."""
    m = on.shape[0]
    counts = on.sum(axis=1)
    offset = np.concatenate([[0], np.cumsum(counts)]).astype(np.int64)
    rowid = np.full(on.shape, -1, dtype=np.int64)
    for i in range(m):
        rowid[i, on[i]] = offset[i] + np.arange(counts[i])
    cid, pts = cube_points(masks, values, n)
    ri, ci = [], []
    for i in range(m):
        r = rowid[i, pts]
        sel = (((outs[cid] >> i) & 1) == 1) & (r >= 0)
        ri.append(r[sel])
        ci.append(cid[sel])
    r = np.concatenate(ri) if ri else np.zeros(0, dtype=np.int64)
    c = np.concatenate(ci) if ci else np.zeros(0, dtype=np.int64)
    return sparse.csr_matrix((np.ones(len(r), dtype=np.int8), (r, c)),
                             shape=(int(offset[-1]), len(masks)))


def raise_to_primes(masks: np.ndarray, values: np.ndarray, outs: np.ndarray, T: np.ndarray,
                    n: int) -> np.ndarray:
    """Each implicant (cube, outputs) raised to a multi-output prime holding it (literals
    dropped in input order while the table keeps every output): ternary indices."""
    idx = encode(masks, values, n)
    need = np.asarray(outs).astype(T.dtype)
    if ((T[idx] & need) != need).any():
        raise ValueError("a cube outside its outputs' regions")
    for k in range(n):
        p = np.int64(3) ** np.int64(n - 1 - k)
        d = (idx // p) % 3
        up = idx + (2 - d) * p
        ok = (d != 2) & ((T[up] & need) == need)
        idx = np.where(ok, up, idx)
    return idx


def region_sets(region: np.ndarray) -> np.ndarray:
    """(m, 2**n) booleans -> (2**n,) per-minterm bit masks of the outputs holding it."""
    m = region.shape[0]
    w = np.left_shift(np.uint64(1), np.arange(m, dtype=np.uint64))
    return (region.astype(np.uint64) * w[:, None]).sum(axis=0, dtype=np.uint64)


def own_primes(T: np.ndarray, n: int, m: int) -> list[tuple[np.ndarray, np.ndarray]]:
    """Every output's own (single-output) primes, read off the ternary table at once.

    A cube is a prime of output i when its region holds it and no cube one literal larger:
    bit i of T[c] & ~(OR of T over c's parents). One pass per input over the table gives the
    parents' OR for all outputs together, so m outputs cost what one does (the Shannon
    recursion of ``primes.py``, once per output, took seconds on 14-input PLAs). Returns
    (masks, values) per output, sorted as ``primes.prime_implicants`` sorts them."""
    U = np.zeros_like(T)
    for k in range(n):
        u = U.reshape(3 ** k, 3, 3 ** (n - k - 1))
        t = T.reshape(3 ** k, 3, 3 ** (n - k - 1))
        u[:, 0, :] |= t[:, 2, :]
        u[:, 1, :] |= t[:, 2, :]
    np.bitwise_and(T, ~U, out=U)
    idx = np.flatnonzero(U)
    bits = U[idx]
    out = []
    for i in range(m):
        sel = idx[(bits >> bits.dtype.type(i)) & 1 == 1]
        masks, values = decode(sel, n)
        order = np.lexsort((values, masks))
        out.append((masks[order], values[order]))
    return out
