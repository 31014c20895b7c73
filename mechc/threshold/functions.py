"""Boolean functions of a few inputs as truth tables: FV numbering (001 §3.7.1), NPN classes.

Bit convention (as in ``mechc.logic.cubes``): input 0 (the dissertation's x1) is the most
significant bit of a minterm number, so minterm ``m`` has input ``j`` equal to
``(m >> (n - 1 - j)) & 1``. A truth table is a tuple of 0/1 of length 2**n indexed by minterm.

The function value of 001 §3.7.1 is FV = sum TV_i 2**(7-i), TV_i the value on minterm i: the
all-zero minterm is the *most* significant bit of FV, so FV is the truth table read as a binary
number from minterm 0 to minterm 7. Table IV lists FV 0..127 only; FV > 127 is found through its
complement 255 - FV (same weights and thresholds, output inverted).
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence
from functools import cache, lru_cache

import numpy as np

TruthTable = tuple[int, ...]


def input_matrix(n: int) -> np.ndarray:
    """(2**n, n) array of input values, row m = minterm m (input 0 most significant)."""
    m = np.arange(1 << n)
    return ((m[:, None] >> (n - 1 - np.arange(n))[None, :]) & 1).astype(np.int64)


def as_truth_table(f: Sequence[int] | int, n: int = 3) -> TruthTable:
    """Accept a truth table (0/1 per minterm) or, for ``n`` inputs, an FV number."""
    if isinstance(f, (int, np.integer)):
        return truth_table_from_fv(int(f), n)
    tt = tuple(int(v) for v in f)
    if len(tt) & (len(tt) - 1) or len(tt) < 2 or any(v not in (0, 1) for v in tt):
        raise ValueError(f"truth table must hold 2**n values of 0/1, got {tt!r}")
    return tt


def n_inputs(tt: Sequence[int]) -> int:
    return len(tt).bit_length() - 1


def function_value(tt: Sequence[int]) -> int:
    """FV of 001 §3.7.1: minterm 0 is the most significant bit."""
    size = len(tt)
    return sum(int(v) << (size - 1 - i) for i, v in enumerate(tt))


def truth_table_from_fv(fv: int, n: int = 3) -> TruthTable:
    size = 1 << n
    if not 0 <= fv < 1 << size:
        raise ValueError(f"FV {fv} out of range for {n} inputs")
    return tuple((fv >> (size - 1 - i)) & 1 for i in range(size))


def table_fv(fv: int, n: int = 3) -> tuple[int, bool]:
    """(FV to look up in Table IV, whether the output is inverted): 001 Chart I step 4."""
    full = (1 << (1 << n)) - 1
    return (fv, False) if fv <= full // 2 else (full - fv, True)


def depends_on(tt: Sequence[int]) -> list[int]:
    """Indices of the inputs the function actually depends on."""
    n = n_inputs(tt)
    t = np.asarray(tt)
    out = []
    for j in range(n):
        bit = 1 << (n - 1 - j)
        m = np.arange(len(t))
        if np.any(t[m] != t[m ^ bit]):
            out.append(j)
    return out


def is_unate(tt: Sequence[int]) -> bool:
    """True if the function is monotone (either way) in every input: necessary for a
    single threshold, and cheap, so the LP check only runs on unate functions."""
    n = n_inputs(tt)
    t = np.asarray(tt)
    m = np.arange(len(t))
    for j in range(n):
        bit = 1 << (n - 1 - j)
        lo = m[(m & bit) == 0]
        d = t[lo | bit] - t[lo]
        if np.any(d > 0) and np.any(d < 0):
            return False
    return True


@cache
def npn_transforms(n: int) -> np.ndarray:
    """(n! * 2**n, 2**n) minterm maps g: the transformed function is f'(m) = f(g[m]).
    Output negation is handled separately (it is a complement, not a minterm map)."""
    X = input_matrix(n)
    maps = []
    for perm in itertools.permutations(range(n)):
        for neg in range(1 << n):
            negbits = (neg >> (n - 1 - np.arange(n))) & 1
            Y = X[:, perm] ^ negbits[None, :]
            maps.append(Y @ (1 << (n - 1 - np.arange(n))))
    return np.array(maps, dtype=np.int64)


def npn_canonical(tt: Sequence[int]) -> TruthTable:
    """Smallest truth table (read as an FV) over all input permutations, input negations and
    output negation: two functions are NPN-equivalent iff their canonical forms agree."""
    t = np.asarray(tt, dtype=np.int64)
    n = n_inputs(tt)
    g = npn_transforms(n)
    cands = np.concatenate([t[g], 1 - t[g]])
    weights = 1 << (len(t) - 1 - np.arange(len(t)))
    best = cands[np.argmin(cands @ weights)]
    return tuple(int(v) for v in best)


@lru_cache(maxsize=4)
def npn_class_ids(n: int) -> np.ndarray:
    """Canonical FV of every function of ``n`` inputs (index = FV), all at once (read-only).

    Vectorised over the 2**(2**n) functions so that n = 4 (65 536 functions, 768 transforms)
    takes a few seconds.
    """
    size = 1 << n
    fvs = np.arange(1 << size, dtype=np.int64)
    bits = (fvs[:, None] >> (size - 1 - np.arange(size))[None, :]) & 1  # bits[fv, m] = f(m)
    weights = (1 << (size - 1 - np.arange(size))).astype(np.int64)
    best = np.full(len(fvs), np.iinfo(np.int64).max)
    full = (1 << size) - 1
    for g in npn_transforms(n):
        v = bits[:, g] @ weights
        np.minimum(best, v, out=best)
        np.minimum(best, full - v, out=best)
    best.flags.writeable = False
    return best
