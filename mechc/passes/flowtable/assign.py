"""Step 4: secondary codes without critical races (Tracey's single-transition-time assignment),
or the codes the spec's ``assign`` gives."""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np
from scipy import sparse
from scipy.optimize import Bounds, LinearConstraint, milp

from mechc.errors import DesignError
from mechc.ir.seqspec import FlowTable
from mechc.passes.flowtable.reduce import ReducedTable

#: Exact minimum-variable assignment (all bipartitions of the merged rows) up to this many rows;
#: beyond, a set cover over bipartitions grown from the dichotomies (not proven minimal).
EXACT_ASSIGN_MAX_ROWS = 10
#: Randomised greedy merges per dichotomy for the candidate pool of larger tables.
POOL_ROUNDS = 6
#: Seconds for the pool's set cover (it finds good covers early and rarely proves them).
POOL_TIME_LIMIT = 5.0


@dataclass
class Assignment:
    codes: list[int]  # code of each merged row
    width: int
    proven: bool  # minimum number of variables proven
    method: str


def dichotomies(rt: ReducedTable) -> list[tuple[frozenset[int], frozenset[int]]]:
    """Tracey's conditions: per column, each pair of transitions (stable entries count as
    transitions to themselves) with different destinations; plus every pair of rows."""
    C = len(rt.classes)
    out = set()
    for k in range(len(rt.ft.columns)):
        trans = [(c, rt.next[c][k]) for c in range(C) if rt.next[c][k] is not None]
        for (a, da), (b, db) in itertools.combinations(trans, 2):
            if da != db:
                A, B = frozenset({a, da}), frozenset({b, db})
                out.add(tuple(sorted((A, B), key=sorted)))
    for a, b in itertools.combinations(range(C), 2):
        out.add((frozenset({a}), frozenset({b})))
    # a pair already implied by a larger one is redundant
    dd = sorted(out, key=lambda d: -(len(d[0]) + len(d[1])))
    keep = []
    for d in dd:
        if not any(_dich_contains(e, d) for e in keep):
            keep.append(d)
    return keep


def _dich_contains(big, small) -> bool:
    return (small[0] <= big[0] and small[1] <= big[1]) or \
        (small[0] <= big[1] and small[1] <= big[0])


def _covers(part: int, d, C: int) -> bool:
    """Does the bipartition ``part`` (bit c = side of row c) separate dichotomy d?"""
    a = {(part >> c) & 1 for c in d[0]}
    b = {(part >> c) & 1 for c in d[1]}
    return len(a) == 1 and len(b) == 1 and a != b


def assign_states(rt: ReducedTable, time_limit: float = 20.0) -> Assignment:
    """Fewest variables whose bipartitions separate every dichotomy (set cover by integer
    programming): over all bipartitions up to EXACT_ASSIGN_MAX_ROWS merged rows (exact), over
    a pool grown from the dichotomies beyond."""
    C = len(rt.classes)
    if C == 1:
        return Assignment([0], 0, True, "single state")
    dich = dichotomies(rt)
    lower = (C - 1).bit_length()  # ceil(log2 C): distinct codes need at least this many
    if C <= EXACT_ASSIGN_MAX_ROWS:
        parts = np.arange(1, 1 << (C - 1), dtype=np.int64)  # row C-1 always on side 0
        exact, method = True, "tracey (exact)"
    else:
        parts = np.array(sorted(_pool(dich, C)), dtype=np.int64)
        exact, method = False, "tracey (pool cover)"
    M = _separates(parts, dich, C)
    res = milp(np.ones(len(parts)), integrality=np.ones(len(parts)), bounds=Bounds(0, 1),
               constraints=[LinearConstraint(sparse.csr_matrix(M.astype(float)), 1, np.inf),
                            LinearConstraint(np.ones((1, len(parts))), lower, np.inf)],
               options={"time_limit": time_limit if exact else min(time_limit,
                                                                      POOL_TIME_LIMIT)})
    if res.x is None:
        chosen = _greedy_parts(dich, C, list(range(len(dich))))
        return _codes_from_parts(rt, chosen, len(chosen) == lower, "tracey (greedy)")
    chosen = [int(parts[i]) for i in np.flatnonzero(res.x > 0.5)]
    proven = (exact and res.status == 0) or len(chosen) == lower
    return _codes_from_parts(rt, chosen, proven, method)


def _separates(parts: np.ndarray, dich, C: int) -> np.ndarray:
    """(dichotomies, parts): does bipartition p keep both sides of dichotomy d constant and
    apart (the two transition subcubes then never meet)?"""
    side = (parts[None, :] >> np.arange(C)[:, None]) & 1  # (C, P)
    M = np.zeros((len(dich), len(parts)), dtype=bool)
    for i, (A, B) in enumerate(dich):
        sa, sb = side[sorted(A)], side[sorted(B)]
        M[i] = (sa == sa[0]).all(axis=0) & (sb == sb[0]).all(axis=0) & (sa[0] != sb[0])
    return M


def _pool(dich, C: int, rounds: int = POOL_ROUNDS, seed: int = 0) -> set[int]:
    """Candidate bipartitions: from each dichotomy, merge the others that fit (in random
    orders, seeded); rows left unplaced go to side 0 and to side 1 (two candidates)."""
    rng = np.random.default_rng(seed)
    full = (1 << C) - 1
    pool: set[int] = set()
    for start in range(len(dich)):
        for r in range(rounds):
            order = [start] + [int(i) for i in rng.permutation(len(dich)) if i != start]
            zero, one = _merge_dichotomies(dich, order)
            base = sum(1 << c for c in one)
            free = full & ~base & ~sum(1 << c for c in zero)
            for p in (base, base | free) if r == 0 else (base | (free & int(rng.integers(
                    0, 1 << C))),):
                p = p ^ full if p >> (C - 1) & 1 else p  # row C-1 on side 0: one per pair
                if p:
                    pool.add(p)
    return pool


def _merge_dichotomies(dich, order) -> tuple[set[int], set[int]]:
    zero, one = set(dich[order[0]][0]), set(dich[order[0]][1])
    for i in order[1:]:
        A, B = dich[i]
        if not (A & one or B & zero):
            zero |= A
            one |= B
        elif not (A & zero or B & one):
            zero |= B
            one |= A
    return zero, one


def _greedy_parts(dich, C: int, order: list[int]) -> list[int]:
    """Merge compatible dichotomies greedily into variables (fallback)."""
    left = [dich[i] for i in order]
    parts = []
    while left:
        zero, one = _merge_dichotomies(left, list(range(len(left))))
        part = sum(1 << c for c in one)
        parts.append(part)
        left = [d for d in left if not _covers(part, d, C)]
    return parts


def _codes_from_parts(rt: ReducedTable, parts: list[int], proven: bool,
                      method: str) -> Assignment:
    C = len(rt.classes)
    # variable order: by the first row they separate; polarity: the initial state is all 0
    init = rt.rep[rt.ft.initial]
    parts = [p ^ ((1 << C) - 1) if (p >> init) & 1 else p for p in parts]
    parts.sort(key=lambda p: [(p >> c) & 1 for c in range(C)], reverse=True)
    v = len(parts)
    codes = [sum(((p >> c) & 1) << (v - 1 - j) for j, p in enumerate(parts)) for c in range(C)]
    return Assignment(codes, v, proven, method)


def given_assignment(ft: FlowTable, comp: np.ndarray) -> tuple[list[frozenset[int]], list[int],
                                                               int]:
    """Classes and codes from the spec's ``assign`` (rows with equal codes are merged; they
    must be compatible)."""
    codes_by_row = {r: ft.assign[name] for r, name in enumerate(ft.rows)}
    width = len(next(iter(codes_by_row.values())))
    groups: dict[str, list[int]] = {}
    for r in range(len(ft.rows)):
        groups.setdefault(codes_by_row[r], []).append(r)
    classes, codes = [], []
    for code, members in groups.items():
        for a, b in itertools.combinations(members, 2):
            if not comp[a, b]:
                raise DesignError(f"rows {ft.rows[a]} and {ft.rows[b]} share code {code} but "
                                  "cannot be merged (their outputs or successors conflict)")
        classes.append(frozenset(members))
        codes.append(int(code, 2) if code else 0)
    return classes, codes, width


def drop_constant_bits(asg: Assignment) -> tuple[Assignment, list[int]]:
    """The assignment without the variables that have one value in every merged row (a given
    ``assign`` whose other rows were unreachable): such a memory would never be set or reset
    and is not built. Dropping a variable that separates no two codes keeps every code distinct
    and every transition's subcube to itself. Returns it and the dropped positions (MSB
    first)."""
    v = asg.width
    gone = [j for j in range(v)
            if len({(c >> (v - 1 - j)) & 1 for c in asg.codes}) == 1]
    if not gone:
        return asg, []
    keep = [j for j in range(v) if j not in gone]

    def squeeze(c: int) -> int:
        return sum(((c >> (v - 1 - j)) & 1) << (len(keep) - 1 - i) for i, j in enumerate(keep))

    return Assignment([squeeze(c) for c in asg.codes], len(keep), asg.proven,
                      asg.method), gone
