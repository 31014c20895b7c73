"""Multi-output two-level minimisation: one set of products shared by every output.

A product (input cube) built once can feed the OR of every output whose on ∪ dc region holds
it, so the cost that matters is the number of *distinct* products (each one AND cell with its
own fan-out), then their literals, then the OR inputs. Per-output minimum covers shared
afterwards miss this: on the MCNC PLAs they had up to 2.4 times espresso's product count.

Engines, all on truth tables (n <= MAX_TABLE_INPUTS):

* table (``_by_table``, when the ternary table of ``implicants.py`` fits): every multi-output
  prime at once, a unate covering problem with a row per (output, on-minterm) and a column
  per prime, solved exactly (HiGHS; fewest columns, then the fewest parts the mapper spends on
  them, ``product_parts``) when it finishes in time, else by row weighting local search
  (``setcover.py``) from the greedy cover and from the starting covers raised to primes, then
  the program over the columns those covers use;
* exact by recursion, for specs whose table is too large: the multi-output primes by Shannon
  recursion with output sets as bit masks (``multi_primes``), then the same program;
* heuristic: espresso's loop (``espresso.espresso``) on the characteristic function, each
  output a one-hot variable: a cube (c, S) is c · Π_{j∉S} ȳ_j, the points (x, e_i) carry output
  i's value and every point whose y is not one-hot is a don't-care. Its cover's products are
  then handed to the same covering program together with every output's own primes, which
  keeps the better cover.

Each output then takes the fewest of the chosen products that cover it (its OR inputs).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np
from scipy import sparse

from mechc.logic.cover import _terms_then_cost, coverage, solve_cover, unique_rows
from mechc.logic.cubes import Cube
from mechc.logic.espresso import ComplementTooLarge, complement, espresso, pack, unpack
from mechc.logic.implicants import (
    cover_matrix,
    encode,
    multi_output_primes,
    raise_to_primes,
    table_fits,
)
from mechc.logic.primes import TooManyPrimes, prime_implicants
from mechc.logic.setcover import heuristic_cover

#: More multi-output primes than this (or more cover-matrix entries than ``TABLE_MAX_NNZ``):
#: the table engine gives way to espresso's loop.
TABLE_MAX_PRIMES = 400_000
TABLE_MAX_NNZ = 40_000_000
#: The integer program runs on the whole (essential-reduced) covering problem up to this many
#: cells (rows x columns); past it its dominance reduction alone took minutes (alu4: 26,572 x
#: 6,900 took 170 s), so it runs on the columns of the heuristic covers only.
EXACT_MAX_CELLS = 60_000_000
#: Steps of row weighting local search, shared by its starts (20,000 steps took ex1010 from
#: 287 products (greedy) to 270, in 5 s of one core).
LOCAL_STEPS = 24_000
#: Steps it takes even past the time limit (ex1010: 287 -> 277 products in 5,000 steps, about
#: 1.5 s of one core), so the result does not hang on how busy the machine is.
LOCAL_MIN_STEPS = 6_000
#: ... scaled down on problems with more matrix entries than this (a step's cost grows with
#: them: on b12, 1.6 million entries, 6,000 steps took 10 s).
LOCAL_MIN_NNZ = 200_000
#: Each output's OR inputs are chosen exactly among up to this many products, greedily beyond
#: (the exact program's greedy start alone took 12 s for 1,900 products over 2**16 rows).
PICK_EXACT_COLUMNS = 400

_EMPTY3 = (np.zeros(0, dtype=np.int64),) * 3


@dataclass
class MultiCover:
    """Distinct products and which of them each output ORs together."""

    cubes: list[Cube]
    use: list[list[int]]  # per output: indices into ``cubes``
    proven: bool  # the fewest distinct products (then literals) is proven
    method: str  # "exact" | "multi-output espresso" | "multi-output espresso+cover"
    seconds: float = 0.0
    time_limited: list[str] = field(default_factory=list)  # steps whose time limit ran out

    @property
    def products(self) -> int:
        return len(self.cubes)

    def output_cubes(self, i: int) -> list[Cube]:
        return [self.cubes[k] for k in self.use[i]]


# ---- multi-output primes --------------------------------------------------------------------
def multi_primes(sets: np.ndarray, limit: int | None = None, deadline: float | None = None):
    """Multi-output primes of ``sets`` (length 2**n, entry = bit mask of the outputs whose
    on ∪ dc holds that minterm): arrays (masks, values, output masks). Raises TooManyPrimes
    past ``limit`` primes (or pairwise candidates) or past ``deadline``."""
    size = len(sets)
    n = size.bit_length() - 1
    if size != 1 << n:
        raise ValueError("table length must be a power of two")
    memo: dict[bytes, tuple] = {}
    m, v, s = _mprimes(np.ascontiguousarray(sets, dtype=np.int64), n, 0, memo,
                       (limit, deadline))
    order = np.lexsort((s, v, m))
    return m[order], v[order], s[order]


def _mprimes(f: np.ndarray, n: int, k: int, memo, caps):
    if not f.any():
        return _EMPTY3
    if (f == f[0]).all():
        z = np.zeros(1, dtype=np.int64)
        return z, z.copy(), np.array([f[0]], dtype=np.int64)
    key = f.tobytes() if len(f) <= 4096 else None
    if key is not None and key in memo:
        return memo[key]
    half = len(f) // 2
    f0, f1 = f[:half], f[half:]
    bit = np.int64(1 << (n - 1 - k))
    if np.array_equal(f0, f1):
        res = _mprimes(f0, n, k + 1, memo, caps)
    else:
        m0, v0, s0 = _mprimes(f0, n, k + 1, memo, caps)
        m1, v1, s1 = _mprimes(f1, n, k + 1, memo, caps)
        limit, deadline = caps
        if limit is not None and len(m0) + len(m1) > limit:
            raise TooManyPrimes(len(m0) + len(m1))
        if deadline is not None and time.perf_counter() > deadline:
            raise TooManyPrimes("time")
        if len(m0) and len(m1):
            cm, cv, cs = _mconsensus(m0, v0, s0, m1, v1, s1, limit, deadline)
        else:
            cm = cv = cs = np.zeros(0, dtype=np.int64)
        keep0 = ~_mmember(m0, v0, s0, cm, cv, cs)
        keep1 = ~_mmember(m1, v1, s1, cm, cv, cs)
        res = (np.concatenate([cm, m0[keep0] | bit, m1[keep1] | bit]),
               np.concatenate([cv, v0[keep0], v1[keep1] | bit]),
               np.concatenate([cs, s0[keep0], s1[keep1]]))
        if caps[0] is not None and len(res[0]) > caps[0]:
            raise TooManyPrimes(len(res[0]))
    if key is not None:
        memo[key] = res
    return res


def _mconsensus(m0, v0, s0, m1, v1, s1, limit: int | None, deadline: float | None,
                budget: int = 4_000_000):
    """Maximal (cube, outputs) among the consistent intersections with a common output."""
    step = max(1, budget // max(1, len(m1)))
    parts = []
    for a in range(0, len(m0), step):
        am, av, as_ = m0[a:a + step, None], v0[a:a + step, None], s0[a:a + step, None]
        cs = as_ & s1[None, :]
        ok = (((av ^ v1[None, :]) & am & m1[None, :]) == 0) & (cs != 0)
        parts.append(np.stack([(am | m1[None, :])[ok], (av | v1[None, :])[ok], cs[ok]], 1))
    trip = np.unique(np.concatenate(parts), axis=0)
    if limit is not None and len(trip) > 4 * limit:  # the pairwise maximality step is quadratic
        raise TooManyPrimes(len(trip))
    return _mmaximal(trip[:, 0].copy(), trip[:, 1].copy(), trip[:, 2].copy(), deadline)


def _mmember(m, v, s, cm, cv, cs) -> np.ndarray:
    if len(cm) == 0 or len(m) == 0:
        return np.zeros(len(m), dtype=bool)
    out = np.zeros(len(m), dtype=bool)
    step = max(1, 4_000_000 // len(cm))
    for a in range(0, len(m), step):
        out[a:a + step] = ((m[a:a + step, None] == cm[None, :]) & (v[a:a + step, None] == cv)
                           & (s[a:a + step, None] == cs)).any(axis=1)
    return out


def _mmaximal(m, v, s, deadline: float | None = None, block: int = 1024):
    """Drop every (cube, outputs) contained in another of the set."""
    if len(m) <= 1:
        return m, v, s
    lits = np.array([int(x).bit_count() for x in m])
    keep = np.ones(len(m), dtype=bool)
    for a in range(0, len(m), block):
        if deadline is not None and time.perf_counter() > deadline:
            raise TooManyPrimes("time")
        bm, bv, bs, bl = m[a:a + block], v[a:a + block], s[a:a + block], lits[a:a + block]
        cont = (((m[None, :] & ~bm[:, None]) == 0) & ((bv[:, None] & m[None, :]) == v[None, :])
                & ((bs[:, None] & ~s[None, :]) == 0))
        # strictly larger: fewer literals, or the same cube with more outputs
        cont &= (lits[None, :] < bl[:, None]) | ((m[None, :] == bm[:, None])
                                                  & (s[None, :] != bs[:, None]))
        keep[a:a + block] = ~cont.any(axis=1)
    return m[keep], v[keep], s[keep]


# ---- tables ---------------------------------------------------------------------------------
def output_sets(region: np.ndarray) -> np.ndarray:
    """(m, 2**n) booleans -> per minterm the bit mask of outputs whose region holds it."""
    weights = np.left_shift(np.int64(1), np.arange(region.shape[0], dtype=np.int64))
    return (region.astype(np.int64) * weights[:, None]).sum(axis=0)


def _cube_points(mask: int, value: int, n: int) -> np.ndarray:
    pts = np.array([value], dtype=np.int64)
    for k in range(n):
        b = 1 << (n - 1 - k)
        if not mask & b:
            pts = np.concatenate([pts, pts | b])
    return pts


def max_outputs(cubes: list[Cube], sets: np.ndarray, n: int) -> np.ndarray:
    """For each cube, the bit mask of every output whose region holds all of it."""
    out = np.zeros(len(cubes), dtype=np.int64)
    for j, c in enumerate(cubes):
        out[j] = np.bitwise_and.reduce(sets[_cube_points(c.mask, c.value, n)])
    return out


# ---- the covering program -------------------------------------------------------------------
def product_parts(mask: int, value: int) -> int:
    """Parts the mapper spends on a product (standard bar cells): none for a lone literal
    (a wire, or an OR-NOT input), an AND bar of 2 + p parts for p plain literals, and an
    inverting lever stage (an AND-NOT cell, 6 parts) per complemented literal."""
    lits = mask.bit_count()
    if lits <= 1:
        return 0
    neg = (mask & ~value).bit_count()
    pos = lits - neg
    return (2 + pos if pos >= 2 else 0) + 6 * neg


def _weights(masks: np.ndarray, values: np.ndarray) -> np.ndarray:
    return np.array([product_parts(int(a), int(b)) for a, b in zip(masks, values)],
                    dtype=np.int64)


def _rows_matrix(masks, values, outs, on: np.ndarray) -> sparse.csr_matrix:
    """Rows (output i, on-minterm r) x columns (candidate cubes allowed for output i)."""
    blocks = []
    for i in range(on.shape[0]):
        rows = np.flatnonzero(on[i]).astype(np.int64)
        allowed = np.flatnonzero((outs >> i) & 1)
        A = coverage(masks[allowed], values[allowed], rows).tocoo()
        blocks.append(sparse.csr_matrix((A.data, (A.row, allowed[A.col])),
                                        shape=(len(rows), len(masks))))
    return sparse.vstack(blocks).tocsr()


def _pick_uses(cubes: list[Cube], outs: np.ndarray, on: np.ndarray, n: int,
               deadline: float) -> tuple[list[list[int]], bool]:
    """Per output the fewest (then smallest) chosen products covering its on-set."""
    masks = np.array([c.mask for c in cubes], dtype=np.int64)
    values = np.array([c.value for c in cubes], dtype=np.int64)
    lits = _weights(masks, values)
    use, complete = [], True
    for i in range(on.shape[0]):
        rows = np.flatnonzero(on[i]).astype(np.int64)
        allowed = np.flatnonzero((outs >> i) & 1)
        if not len(rows):
            use.append([])
            continue
        A = coverage(masks[allowed], values[allowed], rows)
        chosen, proven = solve_cover(A, lits[allowed], n, max(0.05, deadline - time.perf_counter()))
        complete &= proven
        use.append(sorted(allowed[chosen].tolist()))
    return use, complete


def _finish(cubes: list[Cube], outs: np.ndarray, on: np.ndarray, n: int, proven: bool,
            method: str, t0: float, deadline: float, limited: list[str]) -> MultiCover:
    use, complete = _pick_uses(cubes, outs, on, n, deadline)
    if not complete:
        limited.append("OR inputs per output")
    used = sorted({k for u in use for k in u})
    remap = {k: j for j, k in enumerate(used)}
    return MultiCover([cubes[k] for k in used], [[remap[k] for k in u] for u in use], proven,
                      method, time.perf_counter() - t0, limited)


# ---- entry ----------------------------------------------------------------------------------
def minimise_multi(n: int, on: np.ndarray, region: np.ndarray, start: list[list[Cube]],
                   dc_cubes: list[list[Cube]] | None = None, time_limit: float = 10.0,
                   prime_limit: int = 20_000,
                   extra: tuple[np.ndarray, np.ndarray] | None = None,
                   seeds: list[list[list[Cube]]] = ()) -> MultiCover:
    """Fewest distinct products covering every output's on-set inside its region.

    ``on`` and ``region`` are (m, 2**n) booleans (region = on ∪ dc); ``start`` is a valid cover
    per output (the heuristic starts from it); ``dc_cubes`` the don't-care set per output as
    cubes (derived from the table when None); ``extra`` more candidate cubes (masks, values)
    for the covering program; ``seeds`` more starting covers for the heuristic (e.g. the
    PLA's own rows). The whole call keeps to about ``time_limit`` seconds.
    """
    t0 = time.perf_counter()
    deadline = t0 + time_limit
    m = on.shape[0]
    limited: list[str] = []
    if m <= 62 and table_fits(n, m):
        res = _by_table(n, on, region, [start, *seeds], t0, deadline, limited, prime_limit)
        if res is not None:
            return res
    sets = output_sets(region)
    if m <= 62:
        try:
            pm, pv, ps = multi_primes(sets, prime_limit, t0 + 0.3 * time_limit)
        except TooManyPrimes as e:
            pm = None
            if e.args == ("time",):
                limited.append("multi-output primes")
        if pm is not None:
            A = _rows_matrix(pm, pv, ps, on)
            useful = np.asarray(A.sum(axis=0)).ravel() > 0
            lits = _weights(pm, pv)
            chosen, proven = solve_cover(A[:, useful], lits[useful], n,
                                         0.6 * time_limit)
            idx = np.flatnonzero(useful)[chosen]
            if proven:
                cubes = [Cube(int(pm[k]), int(pv[k])) for k in idx]
                return _finish(cubes, ps[idx], on, n, True, "exact", t0, deadline, limited)
            limited.append("exact multi-output cover")
    # heuristic: espresso on the one-hot characteristic function
    starts = [*seeds, start]  # a PLA's own rows first: a better start than minimum covers
    share = 0.5 * (deadline - time.perf_counter()) / len(starts)
    cubes, cand = None, {}
    for k, s in enumerate(starts):
        got, timed_out = _espresso_multi(n, m, s, dc_cubes, on, region, max(0.1, share))
        if timed_out:
            limited.append(f"multi-output espresso (start {k + 1})")
        cand.update((c, None) for c in got)
        if cubes is None or len(got) < len(cubes):
            cubes = got
    method = "multi-output espresso"
    # the covering program over those products and every output's own primes
    for cover in start:
        cand.update((c, None) for c in cover)
    if extra is not None:
        cand.update((Cube(int(a), int(b)), None) for a, b in zip(*extra))
    pair_end = time.perf_counter() + 0.3 * (deadline - time.perf_counter())
    if not _pair_primes(cand, on, region, prime_limit, pair_end):
        limited.append("primes shared by two outputs")
    pool = list(cand)
    outs = max_outputs(pool, sets, n)
    pm = np.array([c.mask for c in pool], dtype=np.int64)
    pv = np.array([c.value for c in pool], dtype=np.int64)
    A = _rows_matrix(pm, pv, outs, on)
    useful = np.asarray(A.sum(axis=0)).ravel() > 0
    lits = _weights(pm, pv)
    remaining = deadline - time.perf_counter()
    if remaining > 0.2:
        chosen, proven = solve_cover(A[:, useful], lits[useful], n, 0.7 * remaining)
        idx = np.flatnonzero(useful)[chosen]
        own = sum(product_parts(c.mask, c.value) for c in cubes)
        if len(idx) < len(cubes) or (len(idx) == len(cubes) and lits[idx].sum() < own):
            cubes = [pool[k] for k in idx]
            method = "multi-output espresso+cover"
        if not proven:
            limited.append("multi-output cover of espresso's products")
    else:
        limited.append("multi-output cover of espresso's products")
    outs = max_outputs(cubes, sets, n)
    return _finish(cubes, outs, on, n, False, method, t0, deadline, limited)


def _essentials(A) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Columns some row has as its only cover, repeatedly: (forced, rows left, columns left
    that still cover a row)."""
    A = A.tocsr()
    rows = np.arange(A.shape[0])
    cols = np.arange(A.shape[1])
    forced: list[np.ndarray] = []
    while len(rows):
        sub = A[rows][:, cols].tocsr()
        deg = np.diff(sub.indptr)
        if (deg == 0).any():
            raise ValueError("a row no candidate covers")
        ess = np.unique(sub.indices[sub.indptr[:-1][deg == 1]])
        live = np.asarray(sub.sum(axis=0)).ravel() > 0
        if not len(ess):
            cols = cols[live]
            break
        forced.append(cols[ess])
        rows = rows[~(np.asarray(sub[:, ess].sum(axis=1)).ravel() > 0)]
        live[ess] = False
        cols = cols[live]
    f = np.concatenate(forced) if forced else np.zeros(0, dtype=np.int64)
    return np.sort(f), rows, cols


def _start_columns(starts: list[list[list[Cube]]], pool: np.ndarray, T: np.ndarray,
                   n: int) -> list[np.ndarray]:
    """Each starting cover (a cube list per output) as pool columns: its cubes raised to
    multi-output primes (those that cover no on-minterm are left out)."""
    out = []
    for cover in starts:
        merged: dict[Cube, int] = {}
        for i, cubes in enumerate(cover):
            for c in cubes:
                merged[c] = merged.get(c, 0) | (1 << i)
        if not merged:
            continue
        cm = np.array([c.mask for c in merged], dtype=np.int64)
        cv = np.array([c.value for c in merged], dtype=np.int64)
        idx = raise_to_primes(cm, cv, np.array(list(merged.values()), dtype=np.int64), T, n)
        pos = np.clip(np.searchsorted(pool, idx), 0, len(pool) - 1)
        out.append(np.unique(pos[pool[pos] == idx]))
    return out


def _by_table(n: int, on: np.ndarray, region: np.ndarray, starts: list[list[list[Cube]]],
              t0: float, deadline: float, limited: list[str],
              prime_limit: int) -> MultiCover | None:
    """Every multi-output prime from the ternary table, then the covering program: exact
    (HiGHS) when it is small enough, else row weighting local search from the greedy cover
    and from the starting covers, and the integer program over the columns of those covers.
    None when the primes or the matrix are too large (the caller uses espresso's loop). More
    than ``prime_limit`` primes: no exact program on the whole problem."""
    pm, pv, ps, T = multi_output_primes(region, n)
    if len(pm) > TABLE_MAX_PRIMES:
        return None
    free = n - np.bitwise_count(pm.astype(np.uint64)).astype(np.int64)
    if int(np.ldexp(1.0, free).sum()) > TABLE_MAX_NNZ:  # the (prime, minterm) pairs to list
        return None
    A = cover_matrix(pm, pv, ps, on, n).tocsc()
    if A.nnz > TABLE_MAX_NNZ:
        return None
    useful = np.diff(A.indptr) > 0  # primes that cover an on-minterm of one of their outputs
    pm, pv, ps = pm[useful], pv[useful], ps[useful]
    full = A[:, useful].tocsr()  # rows output-major: output i's on-minterms in a block
    A = unique_rows(full)
    cost = _weights(pm, pv)
    pool = encode(pm, pv, n)
    forced, rows, cols = _essentials(A)
    sub = A[rows][:, cols].tocsr()
    c_sub = cost[cols]

    def left() -> float:
        return deadline - time.perf_counter()

    def result(chosen: np.ndarray, proven: bool, method: str) -> MultiCover:
        idx = np.union1d(forced, cols[chosen]).astype(np.int64)
        cubes = [Cube(int(pm[k]), int(pv[k])) for k in idx]
        blocks = np.concatenate([[0], np.cumsum(on.sum(axis=1))])
        use = []
        for i in range(on.shape[0]):  # each output: the fewest chosen products covering it
            mine = idx[(ps[idx] >> i) & 1 == 1]
            Ai = full[blocks[i]:blocks[i + 1]][:, mine]
            if Ai.shape[0] == 0:
                use.append([])
                continue
            if len(mine) <= PICK_EXACT_COLUMNS:
                got, done = solve_cover(Ai, cost[mine], n, max(0.05, left() / on.shape[0]))
                if not done and "OR inputs per output" not in limited:
                    limited.append("OR inputs per output")
            else:
                got = heuristic_cover(Ai, cost[mine], 0.0)
            use.append(np.searchsorted(idx, mine[got]).tolist())
        used = sorted({k for u in use for k in u})
        remap = {k: j for j, k in enumerate(used)}
        return MultiCover([cubes[k] for k in used], [sorted(remap[k] for k in u) for u in use],
                          proven, method, time.perf_counter() - t0, limited)

    if sub.shape[0] == 0:
        return result(np.zeros(0, dtype=np.int64), True, "exact")
    # a first cover by local search: a bound for the integer program and a fallback
    best = heuristic_cover(sub, c_sub, max(0.05, 0.1 * left()), max_steps=LOCAL_STEPS // 8)
    core: set[int] = set(best.tolist())
    if len(pm) <= prime_limit:
        chosen, proven = _program(sub, c_sub, n, 0.5 * left(), best)
        if proven:
            return result(chosen, True, "exact")
        limited.append("exact multi-output cover")
        if _better(chosen, best, c_sub):
            best = chosen
    # local search from the best of the starting covers (made irredundant) and the cover so far
    col_pos = np.full(A.shape[1], -1, dtype=np.int64)
    col_pos[cols] = np.arange(len(cols))
    for s in _start_columns(starts, pool, T, n):
        got = heuristic_cover(sub, c_sub, 0.0, start=col_pos[s][col_pos[s] >= 0])
        core.update(got.tolist())
        if _better(got, best, c_sub):
            best = got
    share = max(0.05, 0.7 * left())
    t_ls = time.perf_counter()
    floor = int(LOCAL_MIN_STEPS * min(1.0, LOCAL_MIN_NNZ / max(1, sub.nnz)))
    got = heuristic_cover(sub, c_sub, share, start=best, seed=1, max_steps=LOCAL_STEPS,
                          min_steps=floor)
    if time.perf_counter() - t_ls >= share:
        limited.append("local search")
    core.update(got.tolist())
    if _better(got, best, c_sub):
        best = got
    # the integer program over the columns those covers use
    core_cols = np.array(sorted(core), dtype=np.int64)
    if left() > 0.2 and len(core_cols):
        core_sub = sub[:, core_cols]
        start = np.flatnonzero(np.isin(core_cols, best))
        got, _ = _program(core_sub, c_sub[core_cols], n, 0.9 * left(), start)
        got = core_cols[got]
        if _better(got, best, c_sub):
            best = got
    return result(best, False, "multi-output primes+local search")


def _program(A, cost: np.ndarray, n: int, seconds: float,
             fallback: np.ndarray) -> tuple[np.ndarray, bool]:
    """The covering program (fewest columns, then least cost), ``fallback`` if it finds
    nothing better. Small problems go through ``solve_cover``'s dominance reductions;
    large ones straight to HiGHS, whose presolve does without the reductions' pairwise
    products (alu4's 26,572 x 6,900 problem: proven in 1 s of CPU, against minutes)."""
    seconds = max(0.1, seconds)
    if A.shape[0] * A.shape[1] <= EXACT_MAX_CELLS:
        return solve_cover(A, cost, n, seconds)
    t_end = time.perf_counter() + seconds
    picked, proven = _terms_then_cost(A, cost.astype(float),
                                      lambda: max(0.05, t_end - time.perf_counter()),
                                      len(fallback))
    if picked is None:
        return fallback, False
    return np.flatnonzero(picked), proven


def _better(a: np.ndarray, b: np.ndarray, cost: np.ndarray) -> bool:
    return (len(a), int(cost[a].sum())) < (len(b), int(cost[b].sum()))


def _pair_primes(cand: dict, on: np.ndarray, region: np.ndarray, limit: int,
                 deadline: float) -> bool:
    """Add the primes of every output and of every two outputs' common region (the products
    two outputs can share) to ``cand``; False if the deadline stopped it."""
    m = on.shape[0]
    pairs = [(i, i) for i in range(m)]
    pairs += [(i, j) for i in range(m) for j in range(i + 1, m)
              if (on[i] & region[j]).any() or (on[j] & region[i]).any()]
    total = 0
    for i, j in pairs:
        if time.perf_counter() > deadline or total > limit:
            return False
        both = region[i] & region[j]
        try:
            pm, pv = prime_implicants(both, limit=limit)
        except TooManyPrimes:
            continue
        need = on[i] | on[j]
        for a, b in zip(pm.tolist(), pv.tolist()):
            cand[Cube(a, b)] = None
        total += len(pm)
        del need
    return True


def _espresso_multi(n: int, m: int, start: list[list[Cube]], dc_cubes, on: np.ndarray,
                    region: np.ndarray, time_limit: float) -> tuple[list[Cube], bool]:
    """Espresso on the one-hot characteristic function; returns the distinct input cubes."""
    full_y = (1 << m) - 1
    merged: dict[Cube, int] = {}
    for i, cover in enumerate(start):
        for c in cover:
            merged[c] = merged.get(c, 0) | (1 << (m - 1 - i))
    F = [Cube((c.mask << m) | (full_y & ~s), c.value << m) for c, s in merged.items()]
    D, O = [], []
    for i in range(m):
        yi = 1 << (m - 1 - i)
        dcs = dc_cubes[i] if dc_cubes is not None else _table_cubes(region[i] & ~on[i], n)
        D.extend(Cube((c.mask << m) | full_y, (c.value << m) | yi) for c in dcs)
        fd = list(start[i]) + list(dcs)
        try:
            off = unpack(complement(pack(fd, n))) if fd else [Cube(0, 0)]
        except ComplementTooLarge:
            off = _table_cubes(~region[i], n)
        O.extend(Cube((c.mask << m) | full_y, (c.value << m) | yi) for c in off)
    res = espresso(n + m, F, D, O, rest=2, time_limit=time_limit)
    out: dict[Cube, None] = {}
    for c in res.cubes:
        out[Cube(c.mask >> m, c.value >> m)] = None
    return list(out), not res.complete


def _table_cubes(region: np.ndarray, n: int) -> list[Cube]:
    """Cubes covering exactly the true entries of a table (each minterm grown greedily)."""
    idx = np.flatnonzero(region).astype(np.int64)
    covered = np.zeros(len(region), dtype=bool)
    out = []
    full = (1 << n) - 1
    for start in idx.tolist():
        if covered[start]:
            continue
        mask, value = full, start
        for k in range(n):
            b = 1 << (n - 1 - k)
            m2 = mask & ~b
            pts = _cube_points(m2, value & m2, n)
            if region[pts].all():
                mask, value = m2, value & m2
        out.append(Cube(mask, value))
        covered[_cube_points(mask, value, n)] = True
    return out
