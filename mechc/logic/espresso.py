"""Heuristic two-level minimisation on cube lists, for specs too wide for truth tables.

The exact engine enumerates 2**n rows and stops at ``MAX_TABLE_INPUTS``; MCNC PLAs reach 117
inputs. This module follows espresso (Brayton et al., 1984) instead: the off-set comes from
complementing on ∪ dc by the unate recursive paradigm (memoised: structured PLAs reach the same
cofactor along many paths), every on-cube is EXPANDed to a prime that avoids it, IRREDUNDANT
drops cubes the rest already covers, and REDUCE / EXPAND / IRREDUNDANT (then LAST_GASP) repeat
while the cost (terms, then literals) falls. Sparse wide functions can have off-sets of 10**5
cubes and more; past a budget EXPAND asks tautology questions of on ∪ dc instead. Nothing here
is proven minimal. ``check_cover`` is an exact verifier on cubes (cofactors and tautology
only, no complement) for any n, so a result never leaves unchecked.

Representation: a cube set is a pair ``(M, V)`` of C-ordered uint64 arrays of shape (k, W),
W = ceil(n / 64). Word w holds bit positions 64w..64w+63 of mechc's integer cube (input j at
position n-1-j, see ``cubes.py``), so any n works and pairwise steps stay numpy operations; M
marks the literals, V their values (V ⊆ M). A lone cube is a pair of (W,) arrays. Cofactors
that depend on at most ``LEAF_VARS`` inputs are settled on a local table of 2**k points.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from mechc.errors import MechcError
from mechc.logic.cubes import DC, Cube

_WORD = (1 << 64) - 1
#: Past this many cubes a complement is refused (it would exhaust memory long before finishing).
MAX_COMPLEMENT_CUBES = 400_000
#: Cubes whose supercube with the cube being expanded is tried per step of EXPAND.
EXPAND_CANDIDATES = 256
#: Off-sets larger than this many cubes are not built; EXPAND then uses tautology checks.
OFFSET_BUDGET = 20_000
#: Share of the time limit the off-set may take before EXPAND does without it.
OFFSET_TIME_SHARE = 0.25
#: Pairwise blocks are cut so no temporary exceeds this many uint64 words.
_BLOCK_WORDS = 4_000_000

CubeSet = tuple[np.ndarray, np.ndarray]


class WideLogicError(MechcError):
    """The cube engine cannot handle this function (e.g. a complement too large)."""


# ---- packing ------------------------------------------------------------------------------
def n_words(n: int) -> int:
    return max(1, (n + 63) // 64)


def pack(cubes: Sequence[Cube], n: int) -> CubeSet:
    """mechc cubes -> (M, V) word arrays."""
    W = n_words(n)
    rows_m = [[(c.mask >> (64 * w)) & _WORD for w in range(W)] for c in cubes]
    rows_v = [[(c.value >> (64 * w)) & _WORD for w in range(W)] for c in cubes]
    M = np.array(rows_m, dtype=np.uint64).reshape(len(cubes), W)
    V = np.array(rows_v, dtype=np.uint64).reshape(len(cubes), W)
    return M, V


def unpack(S: CubeSet) -> list[Cube]:
    M, V = S
    out = []
    for m_row, v_row in zip(M.tolist(), V.tolist()):
        mask = sum(int(x) << (64 * w) for w, x in enumerate(m_row))
        value = sum(int(x) << (64 * w) for w, x in enumerate(v_row))
        out.append(Cube(mask, value))
    return out


def _empty(W: int) -> CubeSet:
    return np.zeros((0, W), dtype=np.uint64), np.zeros((0, W), dtype=np.uint64)


def _universe(W: int) -> CubeSet:
    return np.zeros((1, W), dtype=np.uint64), np.zeros((1, W), dtype=np.uint64)


def _cat(*sets: CubeSet) -> CubeSet:
    return np.concatenate([s[0] for s in sets]), np.concatenate([s[1] for s in sets])


def _take(S: CubeSet, idx) -> CubeSet:
    return S[0][idx], S[1][idx]


def _bits(X: np.ndarray) -> np.ndarray:
    """(k, W) words -> (k, 64W) 0/1 matrix, column p = bit position p."""
    X = np.ascontiguousarray(X, dtype="<u8")
    return np.unpackbits(X.view(np.uint8), axis=-1, bitorder="little")


def _words(cols: np.ndarray, W: int) -> np.ndarray:
    """Boolean vector over bit positions -> (W,) words."""
    b = np.zeros(64 * W, dtype=np.uint8)
    b[:len(cols)] = cols
    return np.packbits(b, bitorder="little").view("<u8").astype(np.uint64)


def _bit(p: int, W: int) -> np.ndarray:
    w = np.zeros(W, dtype=np.uint64)
    w[p // 64] = np.uint64(1 << (p % 64))
    return w


def _lits(M: np.ndarray) -> np.ndarray:
    return np.bitwise_count(M).sum(axis=1, dtype=np.int64)


def _polarity_counts(S: CubeSet) -> tuple[np.ndarray, np.ndarray]:
    """Per bit position: how many cubes have the positive / the negative literal."""
    M, V = S
    return _bits(M & V).sum(axis=0, dtype=np.int64), _bits(M & ~V).sum(axis=0, dtype=np.int64)


def _has_universe(S: CubeSet) -> bool:
    return bool((~S[0].any(axis=1)).any())


def cofactor(S: CubeSet, cm: np.ndarray, cv: np.ndarray) -> CubeSet:
    """Cubes of S meeting the cube (cm, cv), with cm's literals removed."""
    M, V = S
    keep = ~(((V ^ cv) & M & cm).any(axis=1))
    ncm = ~cm
    return M[keep] & ncm, V[keep] & ncm


def _split(S: CubeSet, p: int) -> tuple[CubeSet, CubeSet]:
    """Cofactors for bit position p = 0 and p = 1."""
    W = S[0].shape[1]
    b = _bit(p, W)
    return cofactor(S, b, np.zeros(W, dtype=np.uint64)), cofactor(S, b, b)


def _binate_choice(pos: np.ndarray, neg: np.ndarray) -> int:
    """Most binate position (most literals, then most balanced); -1 if the set is unate."""
    both = (pos > 0) & (neg > 0)
    if not both.any():
        return -1
    score = np.where(both, (pos + neg) * 4096 - np.abs(pos - neg), -1)
    return int(np.argmax(score))


def contains(A: CubeSet, B: CubeSet) -> np.ndarray:
    """(len A, len B) boolean: A[i] ⊇ B[j]."""
    (Am, Av), (Bm, Bv) = A, B
    W = Am.shape[1]
    out = np.zeros((len(Am), len(Bm)), dtype=bool)
    step = max(1, _BLOCK_WORDS // max(1, len(Bm) * W))
    for s in range(0, len(Am), step):
        am, av = Am[s:s + step, None, :], Av[s:s + step, None, :]
        out[s:s + step] = (((am & ~Bm[None]) | ((av ^ Bv[None]) & am)) == 0).all(axis=2)
    return out


def scc(S: CubeSet) -> CubeSet:
    """Single-cube containment: drop duplicates and cubes inside another cube of the set."""
    M, V = S
    if len(M) <= 1:
        return S
    W = M.shape[1]
    both = np.unique(np.concatenate([M, V], axis=1), axis=0)
    M, V = both[:, :W].copy(), both[:, W:].copy()
    order = np.argsort(_lits(M), kind="stable")  # containers have fewer literals
    M, V = M[order], V[order]
    c = contains((M, V), (M, V))
    np.fill_diagonal(c, False)
    keep = ~c.any(axis=0)
    return M[keep], V[keep]


def supercube(S: CubeSet) -> tuple[np.ndarray, np.ndarray]:
    """Smallest cube containing every cube of the (non-empty) set."""
    M, V = S
    pos = np.bitwise_and.reduce(M & V, axis=0)
    neg = np.bitwise_and.reduce(M & ~V, axis=0)
    return pos | neg, pos


# ---- tautology ------------------------------------------------------------------------------
#: Cofactors over at most this many variables are settled on a local table of 2**k points
#: instead of further splitting (one numpy step instead of a deep Python recursion).
LEAF_VARS = 12


def _leaf(S: CubeSet, pos: np.ndarray, neg: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
    """(support positions, which of their 2**k points the cubes cover) for small supports."""
    support = np.flatnonzero((pos + neg) > 0)
    k = len(support)
    if k > LEAF_VARS or len(S[0]) << k > _BLOCK_WORDS:
        return None
    weights = np.left_shift(1, np.arange(k, dtype=np.int64))
    m = _bits(S[0])[:, support].astype(np.int64) @ weights
    v = _bits(S[1])[:, support].astype(np.int64) @ weights
    idx = np.arange(1 << k, dtype=np.int64)
    return support, ((idx[None, :] & m[:, None]) == v[:, None]).any(axis=0)


def _point_cube(support: np.ndarray, point: int, W: int) -> tuple[np.ndarray, np.ndarray]:
    """The cube fixing the support variables to the bits of ``point`` (a leaf-table index)."""
    on = np.array([(point >> j) & 1 for j in range(len(support))], dtype=bool)
    cols = np.zeros(64 * W, dtype=bool)
    cols[support] = True
    vals = np.zeros(64 * W, dtype=bool)
    vals[support[on]] = True
    return _words(cols, W), _words(vals, W)


def tautology(S: CubeSet) -> bool:
    """Does the union of the cubes cover every point? (unate recursive paradigm)"""
    while True:
        M, V = S
        if len(M) == 0:
            return False
        if _has_universe(S):
            return True
        # a cover whose cubes hold less than the whole space in total cannot be a tautology
        if np.ldexp(1.0, -_lits(M)).sum() < 1.0 - 1e-9:
            return False
        pos, neg = _polarity_counts(S)
        p = _binate_choice(pos, neg)
        if p < 0:
            return False  # unate, and no universal cube
        unate = (pos > 0) != (neg > 0)
        if unate.any():
            # a unate variable's cofactor away from its literals is the smaller one, and it is
            # a tautology iff the whole is: keep the cubes free of unate variables
            um = _words(unate, M.shape[1])
            S = _take(S, ~((M & um).any(axis=1)))
            continue
        leaf = _leaf(S, pos, neg)
        if leaf is not None:
            return bool(leaf[1].all())
        s0, s1 = _split(S, p)
        if len(s0[0]) > len(s1[0]):
            s0, s1 = s1, s0
        if not tautology(s0):
            return False
        S = s1


def find_uncovered(S: CubeSet) -> tuple[np.ndarray, np.ndarray] | None:
    """A cube no cube of S meets (free positions may take any value), or None (tautology)."""
    M, V = S
    W = M.shape[1]
    if len(M) == 0:
        return np.zeros(W, dtype=np.uint64), np.zeros(W, dtype=np.uint64)
    if _has_universe(S):
        return None
    pos, neg = _polarity_counts(S)
    p = _binate_choice(pos, neg)
    unate = (pos > 0) != (neg > 0)
    if p < 0 or unate.any():
        # set every unate variable against its literals: that kills every cube using one
        um = _words(unate, W)
        uv = _words(neg > 0, W) & um
        rest = _take(S, ~((M & um).any(axis=1)))
        if p < 0:
            return um, uv
        hole = find_uncovered(rest)
        return None if hole is None else (hole[0] | um, hole[1] | uv)
    leaf = _leaf(S, pos, neg)
    if leaf is not None:
        holes = np.flatnonzero(~leaf[1])
        return None if not len(holes) else _point_cube(leaf[0], int(holes[0]), W)
    b = _bit(p, W)
    branches = list(zip((0, 1), _split(S, p)))
    branches.sort(key=lambda t: np.ldexp(1.0, -_lits(t[1][0])).sum())  # emptier half first
    for val, sub in branches:
        hole = find_uncovered(sub)
        if hole is not None:
            return hole[0] | b, hole[1] | (b if val else 0)
    return None


# ---- complement -----------------------------------------------------------------------------
class ComplementTooLarge(WideLogicError):
    """The complement outgrew the caller's budget (the caller may work without it)."""


def complement(S: CubeSet, max_cubes: int = MAX_COMPLEMENT_CUBES,
               deadline: float | None = None) -> CubeSet:
    """Cubes covering exactly the points no cube of S covers (unate recursive paradigm).

    Raises ComplementTooLarge once a partial result exceeds ``max_cubes`` cubes or the clock
    passes ``deadline``.
    """
    return _complement(S, max_cubes, deadline, {})


def _literal_cubes(m: np.ndarray, v: np.ndarray, W: int) -> CubeSet:
    """One single-literal cube per literal of (m, v), each with the opposite value."""
    positions = np.flatnonzero(_bits(m[None])[0])
    k = len(positions)
    M = np.zeros((k, W), dtype=np.uint64)
    bits = np.left_shift(np.uint64(1), (positions % 64).astype(np.uint64))
    M[np.arange(k), positions // 64] = bits
    V = M & ~v[None]
    return M, V


def _complement(S: CubeSet, max_cubes: int, deadline: float | None, memo: dict) -> CubeSet:
    M, V = S
    W = M.shape[1]
    if len(M) == 0:
        return _universe(W)
    if _has_universe(S):
        return _empty(W)
    if len(M) == 1:
        return _literal_cubes(M[0], V[0], W)
    # structured PLAs reach the same cofactor along many paths
    key = M.tobytes() + V.tobytes()
    hit = memo.get(key)
    if hit is None:
        hit = memo[key] = _complement_split(S, max_cubes, deadline, memo)
    return hit


def _complement_split(S: CubeSet, max_cubes: int, deadline: float | None,
                      memo: dict) -> CubeSet:
    M, V = S
    W = M.shape[1]
    # literals every cube shares: F = c·F'  =>  ¬F = ¬c + ¬F'
    cm, cv = supercube(S)
    if cm.any():
        rest = _complement((M & ~cm, V & ~cm), max_cubes, deadline, memo)
        return _cat(_literal_cubes(cm, cv, W), rest)
    pos, neg = _polarity_counts(S)
    p = _binate_choice(pos, neg)
    if p < 0:
        p = int(np.argmax(pos + neg))
    s0, s1 = _split(S, p)
    c0 = _complement(s0, max_cubes, deadline, memo)
    c1 = _complement(s1, max_cubes, deadline, memo)
    if len(c0[0]) + len(c1[0]) > max_cubes:
        raise ComplementTooLarge(f"complement too large: over {max_cubes} cubes")
    if deadline is not None and time.perf_counter() > deadline:
        raise ComplementTooLarge("complement took too long")
    return _merge(c0, c1, _bit(p, W))


#: Above this many cube pairs, merging looks only for identical cubes, not containment.
_MERGE_PAIRS = 1_000_000


def _merge(c0: CubeSet, c1: CubeSet, b: np.ndarray) -> CubeSet:
    """x̄·C0 + x·C1, where a cube inside a cube of the other half needs no literal on x
    (x̄·d ⊆ ¬F and d ⊆ e with x·e ⊆ ¬F give d ⊆ ¬F)."""
    k0, k1 = len(c0[0]), len(c1[0])
    free0 = np.zeros(k0, dtype=bool)
    free1 = np.zeros(k1, dtype=bool)
    if k0 and k1:
        if k0 * k1 <= _MERGE_PAIRS:
            free0 = contains(c1, c0).any(axis=0)
            free1 = contains(c0, c1).any(axis=0)
        else:
            key0 = np.concatenate(c0, axis=1)
            key1 = np.concatenate(c1, axis=1)
            _, inv = np.unique(np.concatenate([key0, key1]), axis=0, return_inverse=True)
            inv = inv.ravel()
            common = np.intersect1d(inv[:k0], inv[k0:])
            free0 = np.isin(inv[:k0], common)
            free1 = np.isin(inv[k0:], common)
    M0, V0 = c0
    M1, V1 = c1
    M0 = np.where(free0[:, None], M0, M0 | b)
    M1 = np.where(free1[:, None], M1, M1 | b)
    V1 = np.where(free1[:, None], V1, V1 | b)
    S = (np.concatenate([M0, M1]), np.concatenate([V0, V1]))
    if free0.any() or free1.any():
        S = _drop_inside_free(S, b)
    return S


def _drop_inside_free(S: CubeSet, b: np.ndarray) -> CubeSet:
    """Remove duplicates, and cubes inside a cube that has no literal on b (after a merge only
    those can contain another cube)."""
    W = S[0].shape[1]
    both = np.unique(np.concatenate(S, axis=1), axis=0)
    M, V = both[:, :W].copy(), both[:, W:].copy()
    free = np.flatnonzero(~(M & b).any(axis=1))
    inside = contains((M[free], V[free]), (M, V))
    inside[np.arange(len(free)), free] = False
    keep = ~inside.any(axis=0)
    return M[keep], V[keep]


def sharp(A: CubeSet, B: CubeSet, max_cubes: int = MAX_COMPLEMENT_CUBES,
          deadline: float | None = None) -> CubeSet:
    """Points of A outside B, cube by cube of A (only B's cubes meeting it matter)."""
    W = A[0].shape[1]
    parts = [_empty(W)]
    for am, av in zip(*A):
        sub = cofactor(B, am, av)
        if len(sub[0]) == 0:
            parts.append((am[None], av[None]))
            continue
        cm, cv = complement(sub, max_cubes, deadline)
        parts.append((cm | am, cv | av))
        if sum(len(x[0]) for x in parts) > max_cubes:
            raise ComplementTooLarge(f"sharp product too large: over {max_cubes} cubes")
    return scc(_cat(*parts))


def smallest_cube_outside(S: CubeSet) -> tuple[np.ndarray, np.ndarray] | None:
    """Supercube of the complement of S, or None when S is a tautology (for REDUCE).

    Start from one point outside S: only its values can be literals of the supercube. A
    literal x = q survives iff S's cofactor at x = ¬q is a tautology; each cofactor that is not
    yields another outside point, which removes every literal it disagrees with at once. A
    cofactor of total volume below the whole space cannot be a tautology (no check needed).
    """
    M, V = S
    W = M.shape[1]
    zero = np.zeros(W, dtype=np.uint64)
    if len(M) == 0:
        return zero, zero.copy()
    if _has_universe(S):
        return None
    pos, neg = _bits(M & V).astype(bool), _bits(M & ~V).astype(bool)
    leaf = _leaf(S, pos.sum(axis=0), neg.sum(axis=0))
    if leaf is not None:
        support, covered = leaf
        holes = np.flatnonzero(~covered)
        if not len(holes):
            return None
        k = len(support)
        ones = int(np.bitwise_and.reduce(holes))
        zeros = int(np.bitwise_and.reduce(~holes & ((1 << k) - 1)))
        cols = np.zeros(64 * W, dtype=bool)
        vals = np.zeros(64 * W, dtype=bool)
        for j in range(k):
            if (ones | zeros) >> j & 1:
                cols[support[j]] = True
                vals[support[j]] = bool(ones >> j & 1)
        return _words(cols, W), _words(vals, W)
    hole = find_uncovered(S)
    if hole is None:
        return None
    lm, lv = hole
    w = np.ldexp(1.0, -_lits(M))[:, None]
    # volume of the cofactor at x = 1: cubes without x̄, doubled where they had x
    vol1 = (w * (~neg) * (1.0 + pos)).sum(axis=0)
    vol0 = (w * (~pos) * (1.0 + neg)).sum(axis=0)
    qv = _bits(lv[None])[0].astype(bool)
    maybe = _bits(lm[None])[0].astype(bool) & (np.where(qv, vol0, vol1) >= 1.0 - 1e-9)
    lm = _words(maybe, W)
    for p in np.flatnonzero(maybe).tolist():
        b = _bit(p, W)
        if not (lm & b).any():
            continue  # ruled out by an earlier outside point
        opp = b & ~lv
        h = find_uncovered(cofactor(S, b, opp))
        if h is None:
            continue  # all of ¬S has x = q: the literal stays
        hm, hv = h[0] | b, h[1] | opp
        lm &= hm & ~(hv ^ lv)
    return lm, lv & lm


# ---- the espresso loop ----------------------------------------------------------------------
@dataclass
class EspressoResult:
    cubes: list[Cube]
    passes: int  # REDUCE/EXPAND/IRREDUNDANT passes after the first EXPAND/IRREDUNDANT
    seconds: float
    complete: bool  # False when the time limit stopped the improvement loop early
    offset_cubes: int  # size of the off-set the cubes were expanded against


def espresso(n: int, on: Sequence[Cube], dc: Sequence[Cube] = (), off: Sequence[Cube] = (),
             rest: int = 0, time_limit: float = 20.0,
             offset_budget: int = OFFSET_BUDGET) -> EspressoResult:
    """A prime, irredundant cover of one output given as cubes.

    ``rest`` is what a point in none of on/dc/off is (``OutputSpec`` semantics: 0, ``DC`` or 1;
    dc overrides on overrides off). The off-set is computed when it fits in ``offset_budget``
    cubes; past that EXPAND asks tautology questions of on ∪ dc instead (slower per literal,
    but sparse wide functions have off-sets of 10**5 cubes and more). The time limit stops the
    improvement loop (and EXPAND midway, leaving later cubes as they were); the result is a
    valid cover either way.
    """
    t0 = time.perf_counter()
    deadline = t0 + time_limit
    W = n_words(n)
    F, D, O = pack(on, n), pack(dc, n), pack(off, n)
    if rest not in (0, 1, DC):
        raise ValueError(f"rest must be 0, 1 or DC, not {rest}")
    if rest == 0:
        O = _empty(W)
    space = _Space(_cat(F, D), O, rest)
    # the off-set may take at most a quarter of the time
    off_deadline = t0 + OFFSET_TIME_SHARE * time_limit
    try:
        space.R = complement(space.FD, offset_budget, off_deadline) if rest == 0 \
            else sharp(O, space.FD, offset_budget, off_deadline)
    except ComplementTooLarge:
        if rest == 1:
            raise WideLogicError(f"the on-set of a type-r output is the complement of its "
                                 f"off-set, which exceeds {offset_budget} cubes or "
                                 f"{OFFSET_TIME_SHARE * time_limit:.1f} s") from None
    if rest == 1:
        F = complement(_cat(space.R, D), offset_budget)
    must = F  # the cover must contain these cubes minus D
    F = scc(F)
    n_off = -1 if space.R is None else len(space.R[0])
    if len(F[0]) == 0:
        return EspressoResult([], 0, time.perf_counter() - t0, True, n_off)
    if n_off == 0:
        return EspressoResult(unpack(_universe(W)), 0, time.perf_counter() - t0, True, 0)
    # with rest = DC, points outside on/dc/off are free too: redundancy needs the on-cubes
    exact_must = must if rest == DC else None
    G = _expand(F, space, deadline)
    G = _irredundant(G, D, exact_must, deadline)
    best, passes, complete = G, 0, True
    while True:
        if time.perf_counter() > deadline:
            complete = False
            break
        passes += 1
        G2 = _reduce(best, D, deadline)
        G2 = _expand(G2, space, deadline)
        G2 = _irredundant(G2, D, exact_must, deadline)
        if _cost(G2) >= _cost(best):
            G2 = _last_gasp(best, D, space, exact_must, deadline)
        if _cost(G2) < _cost(best):
            best = G2
        else:
            break
    cubes = unpack(best)
    return EspressoResult(cubes, passes, time.perf_counter() - t0, complete, n_off)


@dataclass
class _Space:
    """Where a cube may lie: outside the off-set R when it is known, else inside FD (rest 0)
    or meeting the given off-cubes only inside FD (rest DC / 1)."""

    FD: CubeSet
    O: CubeSet
    rest: int
    R: CubeSet | None = None

    def allows(self, cm: np.ndarray, cv: np.ndarray) -> bool:
        if self.R is not None:
            Rm, Rv = self.R
            return bool(((Rm & cm & (Rv ^ cv)) != 0).any(axis=1).all())
        if self.rest == 0:
            return tautology(cofactor(self.FD, cm, cv))
        Om, Ov = self.O
        meet = ~((Om & cm & (Ov ^ cv)) != 0).any(axis=1)
        return all(tautology(cofactor(self.FD, cm | rm, cv | rv))
                   for rm, rv in zip(Om[meet], Ov[meet]))


def _last_gasp(G: CubeSet, D: CubeSet, space: _Space, must: CubeSet | None,
               deadline: float) -> CubeSet:
    """Espresso's LAST_GASP: reduce every cube against the unchanged rest, expand those that
    shrank, and offer the primes that swallow two or more of them to IRREDUNDANT."""
    M, V = G
    keep = np.ones(len(M), dtype=bool)
    red_m, red_v = [], []
    for i in range(len(M)):
        if time.perf_counter() > deadline:
            return G
        keep[i] = False
        sc = smallest_cube_outside(cofactor(_cat(_take(G, keep), D), M[i], V[i]))
        keep[i] = True
        if sc is not None and (sc[0] & ~M[i]).any():
            red_m.append(M[i] | sc[0])
            red_v.append(V[i] | sc[1])
    if len(red_m) < 2:
        return G
    R = np.array(red_m, dtype=np.uint64), np.array(red_v, dtype=np.uint64)
    E = _expand(R, space, deadline)
    useful = contains(E, R).sum(axis=1) >= 2
    if not useful.any():
        return G
    return _irredundant(_cat(_take(E, useful), G), D, must, deadline)


def _cost(S: CubeSet) -> tuple[int, int]:
    return len(S[0]), int(_lits(S[0]).sum())


def _expand(G: CubeSet, space: _Space, deadline: float) -> CubeSet:
    """Each cube raised to a prime, preferring primes that swallow other cubes of G; cubes
    swallowed by an earlier prime are dropped."""
    M, V = G
    k = len(M)
    order = np.argsort(_lits(M), kind="stable")  # largest cubes first
    alive = np.ones(k, dtype=bool)
    out_m, out_v = [], []
    for i in order.tolist():
        if not alive[i]:
            continue
        alive[i] = False
        if time.perf_counter() > deadline:
            out_m.append(M[i])
            out_v.append(V[i])
            continue
        if space.R is not None:
            em, ev = _expand_cube(M[i], V[i], G, alive, space.R)
        else:
            em, ev = _expand_cube_oracle(M[i], V[i], G, alive, space)
        alive &= ~contains((em[None], ev[None]), G)[0]
        out_m.append(em)
        out_v.append(ev)
    W = M.shape[1]
    return scc((np.array(out_m, dtype=np.uint64).reshape(-1, W),
                np.array(out_v, dtype=np.uint64).reshape(-1, W)))


#: Supercubes tried per step when EXPAND works without an off-set (each costs a tautology).
ORACLE_CANDIDATES = 8


def _expand_cube_oracle(cm, cv, G: CubeSet, alive: np.ndarray, space: _Space):
    """EXPAND without an off-set: each raise is checked by ``space.allows``."""
    Gm, Gv = G
    cur = cm.copy()
    cand = np.flatnonzero(alive)
    tried = np.zeros(len(Gm), dtype=bool)
    # 1) supercubes with the nearest other cubes, while they stay inside the allowed region
    while len(cand):
        sm = cur & Gm[cand] & ~(Gv[cand] ^ cv)
        grow = (sm != cur).any(axis=1) & ~tried[cand]
        cand, sm = cand[grow], sm[grow]
        if not len(cand):
            break
        order = np.argsort(-_lits(sm), kind="stable")[:ORACLE_CANDIDATES]
        for j in order.tolist():
            tried[cand[j]] = True
            if space.allows(sm[j], sm[j] & cv):
                cur = sm[j]
                break
        else:
            break
        keep = ~contains((cur[None], (cur & cv)[None]), _take(G, cand))[0]
        cand = cand[keep]
    # 2) single literals, those most other cubes disagree with first
    positions = np.flatnonzero(_bits(cur[None])[0])
    if len(positions):
        live = np.flatnonzero(alive)
        agree = _bits(Gm[live] & ~(Gv[live] ^ cv))[:, positions].sum(axis=0) if len(live) \
            else np.zeros(len(positions), dtype=np.int64)
        W = len(cm)
        for p in positions[np.argsort(agree, kind="stable")].tolist():
            trial = cur & ~_bit(p, W)
            if space.allows(trial, trial & cv):
                cur = trial
    return cur, cv & cur


def _expand_cube(cm, cv, G: CubeSet, alive: np.ndarray, R: CubeSet):
    Rm, Rv = R
    W = len(cm)
    # blocking words: the literals of c that keep it apart from each off-cube
    block = Rm & cm & (Rv ^ cv)
    nblock = np.bitwise_count(block).sum(axis=1)
    if (nblock == 0).any():
        r = int(np.flatnonzero(nblock == 0)[0])
        raise RuntimeError(f"internal error: cube meets off-set cube {r} before expansion")
    # a literal that alone separates c from some off-cube must stay
    ess = np.bitwise_or.reduce(block[nblock == 1], axis=0) if (nblock == 1).any() \
        else np.zeros(W, dtype=np.uint64)
    open_rows = ~((block & ess).any(axis=1))
    block = block[open_rows]
    cur = cm.copy()
    Gm, Gv = G
    cand = np.flatnonzero(alive)
    # 1) raise literals to cover other cubes of G, while the supercube stays off R
    while len(cand):
        sm = cur & Gm[cand] & ~(Gv[cand] ^ cv)  # literals of cur that cube g agrees with
        ok = ((ess & ~sm) == 0).all(axis=1) & (sm != cur).any(axis=1)
        cand = cand[ok]
        sm = sm[ok]
        if not len(cand):
            break
        if len(cand) > EXPAND_CANDIDATES:
            top = np.argsort(-_lits(sm), kind="stable")[:EXPAND_CANDIDATES]
            cand, sm = cand[top], sm[top]
        # the supercube must still share a separating literal with every open off-cube
        feasible = _rows_all_hit(sm, block) if len(block) else np.ones(len(sm), dtype=bool)
        if not feasible.any():
            break
        sm = sm[feasible]
        gains = contains((sm, sm & cv), _take(G, cand)).sum(axis=1)
        pick = int(np.lexsort((_lits(sm), -gains))[0])
        cur = sm[pick]
        cand = cand[~contains((cur[None], (cur & cv)[None]), _take(G, cand))[0]]
    # 2) keep the fewest literals of cur that still separate c from every off-cube
    keep = ess.copy()
    if len(block):
        B = _bits(block & cur).astype(bool)
        rows = np.ones(len(B), dtype=bool)
        chosen = []
        while rows.any():
            counts = B[rows].sum(axis=0)
            p = int(np.argmax(counts))
            if counts[p] == 0:
                raise RuntimeError("internal error: an off-cube no literal separates")
            chosen.append(p)
            rows &= ~B[:, p]
        # drop any chosen literal whose rows the others already cover (makes the cube prime)
        for p in sorted(chosen, key=lambda q: B[:, q].sum()):
            others = [q for q in chosen if q != p]
            if others and B[:, others].any(axis=1).all():
                chosen = others
        for p in chosen:
            keep |= _bit(p, W)
    return keep, cv & keep


def _rows_all_hit(sm: np.ndarray, block: np.ndarray) -> np.ndarray:
    """For each candidate literal set sm[i]: does it share a literal with every block row?"""
    out = np.zeros(len(sm), dtype=bool)
    W = sm.shape[1]
    step = max(1, _BLOCK_WORDS // max(1, len(block) * W))
    for s in range(0, len(sm), step):
        hit = ((sm[s:s + step, None, :] & block[None]) != 0).any(axis=2)
        out[s:s + step] = hit.all(axis=1)
    return out


def _covered(cm, cv, others: CubeSet, must: CubeSet | None) -> bool:
    """Is cube c redundant given ``others`` (the rest of the cover plus don't-cares)?"""
    if tautology(cofactor(others, cm, cv)):
        return True
    if must is None:
        return False
    # only c's points in the must-cover cubes count (the others are free)
    Mm, Mv = must
    meet = ~((Mm & cm & (Mv ^ cv)) != 0).any(axis=1)
    for fm, fv in zip(Mm[meet], Mv[meet]):
        if not tautology(cofactor(others, cm | fm, cv | fv)):
            return False
    return True


def _irredundant(G: CubeSet, D: CubeSet, must: CubeSet | None, deadline: float) -> CubeSet:
    """Drop cubes covered by the rest of the cover and the don't-cares, smallest cubes first."""
    M, V = G
    k = len(M)
    alive = np.ones(k, dtype=bool)
    for i in np.argsort(-_lits(M), kind="stable").tolist():
        if time.perf_counter() > deadline:
            break
        alive[i] = False
        others = _cat(_take(G, alive), D)
        if not _covered(M[i], V[i], others, must):
            alive[i] = True
    return _take(G, alive)


def _reduce(G: CubeSet, D: CubeSet, deadline: float) -> CubeSet:
    """Shrink each cube to the smallest cube holding its points no other cube covers."""
    M, V = G[0].copy(), G[1].copy()
    alive = np.ones(len(M), dtype=bool)
    for i in np.argsort(_lits(M), kind="stable").tolist():
        if time.perf_counter() > deadline:
            break
        alive[i] = False
        others = _cat((M[alive], V[alive]), D)
        sc = smallest_cube_outside(cofactor(others, M[i], V[i]))
        if sc is None:
            continue  # nothing of its own: leave it out
        M[i] |= sc[0]
        V[i] |= sc[1]
        alive[i] = True
    return M[alive], V[alive]


# ---- exact verification ---------------------------------------------------------------------
@dataclass
class CoverFault:
    kind: str  # "meets off-set" | "misses on-set"
    point: str  # an input vector (input order, 0/1) where the cover is wrong

    def __str__(self) -> str:
        return f"cover {self.kind} at input {self.point}"


def check_cover(n: int, cover: Sequence[Cube], on: Sequence[Cube], dc: Sequence[Cube] = (),
                off: Sequence[Cube] = (), rest: int = 0) -> CoverFault | None:
    """Exact check of a cover against a cube spec (``OutputSpec`` semantics), for any n.

    The cover is 1 nowhere the spec says 0 and 1 everywhere it says 1; both reduce to
    tautologies of cofactors, so no complement (and no code shared with EXPAND) is involved.
    """
    C, F, D, O = (pack(x, n) for x in (cover, on, dc, off))
    FD = _cat(F, D)

    def fault(kind, space: CubeSet, cm, cv):
        hole = find_uncovered(cofactor(space, cm, cv))
        assert hole is not None
        value = int(sum(int(x) << (64 * w) for w, x in enumerate((hole[1] & ~cm) | cv)))
        return CoverFault(kind, Cube.minterm(value, n).to_string(n))

    # 1) never 1 where the spec is 0
    for cm, cv in zip(*C):
        if rest == 0:
            if not tautology(cofactor(FD, cm, cv)):
                return fault("meets off-set", FD, cm, cv)
            continue
        Om, Ov = O
        meet = ~((Om & cm & (Ov ^ cv)) != 0).any(axis=1)
        for rm, rv in zip(Om[meet], Ov[meet]):
            xm, xv = cm | rm, cv | rv
            if not tautology(cofactor(FD, xm, xv)):
                return fault("meets off-set", FD, xm, xv)
    # 2) 1 wherever the spec is 1
    CD = _cat(C, D)
    for fm, fv in zip(*F):
        if not tautology(cofactor(CD, fm, fv)):
            return fault("misses on-set", CD, fm, fv)
    if rest == 1:
        CDO = _cat(CD, O)
        zero = np.zeros(n_words(n), dtype=np.uint64)
        if not tautology(CDO):
            return fault("misses on-set", CDO, zero, zero)
    return None

