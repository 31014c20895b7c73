"""Flow-table synthesis: a fundamental-mode flow table becomes SET/RESET equations of MEMORY
elements and output equations (``001_…`` Appendix B, done by program).

Steps, each a plain function:

1. ``compatibility``: the implication table (pairs of rows that may share a state).
2. ``closed_cover``: a minimum closed cover of compatibles (exact by integer programming over
   the prime compatibles for small tables; over the maximal compatibles, not proven, beyond).
3. ``reduce_table``: the merged (reduced) table, outputs attached to stable total states.
4. ``assign_states``: secondary codes without critical races: Tracey's single-transition-time
   assignment (every pair of transitions in a column that go to different states is separated
   by a variable that stays constant in both), minimum variables exact up to 14 merged rows.
   Each transition then moves inside its own subcube, which no other transition of the column
   touches, so every order in which the changing memories switch ends in the same state.
5. ``excitation``: next state, SET/RESET and outputs per total state, with don't-cares.
6. ``derive_equations``: exact minimisation of SET, then RESET with zeros where the built SET
   is on (so S·R = 0 on every total state, reachable or not; the other order is tried too and
   the cheaper kept), consensus terms against static-1 hazards, outputs that change at most
   once per transition; every reachable total state checked for S·R = 0, races and outputs.

Essential hazards (Unger: a single input change applied three times ends elsewhere than applied
once) are reported with the ordering they need: they cannot be removed by the logic.
"""

from __future__ import annotations

import itertools
import time
from dataclasses import dataclass, field, replace

import networkx as nx
import numpy as np
from scipy import sparse
from scipy.optimize import Bounds, LinearConstraint, milp

from mechc.errors import DesignError
from mechc.ir import expr as ex
from mechc.ir.equations import Equations
from mechc.ir.seqspec import (
    FlowTable,
    SeqSpec,
    SequentialError,
    bits_text,
    memory_targets,
    settle_async,
)
from mechc.ir.spec import OutputSpec, Spec
from mechc.logic.cubes import DC, Cube, eval_cover
from mechc.passes.minimise import MinimiseOptions, count_shared, minimise

#: Enumerate every compatible (for prime compatibles) up to this many; beyond, maximal only.
MAX_COMPATIBLES = 5_000
#: Exact minimum-variable assignment (all bipartitions of the merged rows) up to this many rows;
#: beyond, a set cover over bipartitions grown from the dichotomies (not proven minimal).
EXACT_ASSIGN_MAX_ROWS = 10
#: Randomised greedy merges per dichotomy for the candidate pool of larger tables.
POOL_ROUNDS = 6
#: Seconds for the pool's set cover (it finds good covers early and rarely proves them).
POOL_TIME_LIMIT = 5.0
#: Inputs + state variables: the equations are minimised on full truth tables.
MAX_TOTAL_VARIABLES = 20


@dataclass
class SynthOptions:
    minimise: MinimiseOptions = field(default_factory=MinimiseOptions)
    time_limit: float = 20.0  # seconds per integer program (cover, assignment)


# ---- 1. compatibility ------------------------------------------------------------------------
def stable_outputs(ft: FlowTable, r: int, k: int) -> list[int | None] | None:
    """Outputs of row r at column k if it is stable there (Mealy view), else None."""
    return ft.out[r] if ft.stable(r, k) else None


def compatibility(ft: FlowTable) -> np.ndarray:
    """Boolean N×N matrix: rows i, j may share a state (implication table to a fixed point).

    Outputs belong to stable total states: two rows conflict when both are stable in a column
    with different specified outputs; they imply the pair of their destinations per column."""
    N, K = len(ft.rows), len(ft.columns)
    comp = np.ones((N, N), dtype=bool)
    implied: dict[tuple[int, int], set[tuple[int, int]]] = {}
    for i in range(N):
        for j in range(i + 1, N):
            ok = True
            imp: set[tuple[int, int]] = set()
            for k in range(K):
                oi, oj = stable_outputs(ft, i, k), stable_outputs(ft, j, k)
                if oi is not None and oj is not None and any(
                        a is not None and b is not None and a != b for a, b in zip(oi, oj)):
                    ok = False
                    break
                di, dj = ft.dest(i, k), ft.dest(j, k)
                if di is not None and dj is not None and di != dj:
                    imp.add((min(di, dj), max(di, dj)))
            if not ok:
                comp[i, j] = comp[j, i] = False
            else:
                implied[(i, j)] = imp - {(i, j)}
    changed = True
    while changed:
        changed = False
        for (i, j), imp in implied.items():
            if comp[i, j] and any(not comp[a, b] for a, b in imp):
                comp[i, j] = comp[j, i] = False
                changed = True
    return comp


def implied_set(ft: FlowTable, cls: frozenset[int], k: int) -> frozenset[int]:
    return frozenset(d for r in cls if (d := ft.dest(r, k)) is not None)


def class_set(ft: FlowTable, cls: frozenset[int]) -> set[frozenset[int]]:
    """Implied classes a compatible needs elsewhere in a closed cover."""
    out = set()
    for k in range(len(ft.columns)):
        s = implied_set(ft, cls, k)
        if len(s) >= 2 and not s <= cls:
            out.add(s)
    return out


# ---- 2. closed cover ------------------------------------------------------------------------
@dataclass
class CoverResult:
    classes: list[frozenset[int]]
    proven: bool  # proven minimum number of merged rows
    candidates: int
    method: str  # "prime compatibles" | "maximal compatibles"


def maximal_compatibles(comp: np.ndarray) -> list[frozenset[int]]:
    g = _compat_graph(comp)
    return sorted((frozenset(c) for c in nx.find_cliques(g)), key=lambda c: (-len(c), sorted(c)))


def _compat_graph(comp: np.ndarray) -> nx.Graph:
    N = len(comp)
    g = nx.Graph()
    g.add_nodes_from(range(N))
    g.add_edges_from((i, j) for i in range(N) for j in range(i + 1, N) if comp[i, j])
    return g


def all_compatibles(comp: np.ndarray, limit: int = MAX_COMPATIBLES) -> list[frozenset[int]] | None:
    """Every compatible (clique of the compatibility graph), or None past ``limit``."""
    out = []
    for c in nx.enumerate_all_cliques(_compat_graph(comp)):
        out.append(frozenset(c))
        if len(out) > limit:
            return None
    return out


def prime_compatibles(ft: FlowTable, comps: list[frozenset[int]]) -> list[frozenset[int]]:
    """Compatibles not excluded by a larger one whose class set is no harder to close
    (Grasselli–Luccio): some minimum closed cover uses prime compatibles only."""
    cs = {c: class_set(ft, c) for c in comps}
    as_int = np.array([sum(1 << r for r in c) for c in comps], dtype=np.uint64) \
        if len(ft.rows) <= 64 else None
    primes = []
    for i, c in enumerate(comps):
        pc = cs[c]
        if as_int is not None:  # the strict supersets of c, vectorised
            cm = as_int[i]
            sup = np.flatnonzero(((as_int & cm) == cm) & (as_int != cm))
        else:
            sup = [j for j, d in enumerate(comps) if c < d]
        if not any(all(any(kd <= kc for kc in pc) for kd in cs[comps[j]]) for j in sup):
            primes.append(c)
    return primes


def is_closed_cover(ft: FlowTable, classes: list[frozenset[int]]) -> bool:
    N = len(ft.rows)
    if not classes or set().union(*classes) != set(range(N)):
        return False
    for c in classes:
        for k in class_set(ft, c):
            if not any(k <= d for d in classes):
                return False
    return True


def closed_cover(ft: FlowTable, comp: np.ndarray | None = None,
                 time_limit: float = 20.0) -> CoverResult:
    """Minimum closed cover: binary x_C per candidate; every row covered; a chosen C forces
    some chosen D ⊇ K for each class K it implies. Exact over prime compatibles."""
    comp = compatibility(ft) if comp is None else comp
    N = len(ft.rows)
    comps = all_compatibles(comp)
    if comps is not None:
        cands = prime_compatibles(ft, comps)
        method, exact = "prime compatibles", True
    else:
        cands = maximal_compatibles(comp)
        method, exact = "maximal compatibles", False
    cands = sorted(set(cands), key=lambda c: (-len(c), sorted(c)))
    index = {c: i for i, c in enumerate(cands)}
    P = len(cands)
    rows, cols, vals = [], [], []
    r = 0
    for s in range(N):  # cover
        for c, i in index.items():
            if s in c:
                rows.append(r)
                cols.append(i)
                vals.append(1.0)
        r += 1
    n_cover = r
    for c, i in index.items():  # closure: sum_{D ⊇ K} x_D - x_C >= 0
        for k in class_set(ft, c):
            sup = [index[d] for d in cands if k <= d]
            if not sup:
                raise DesignError(f"internal error: no candidate compatible contains the "
                                  f"implied class {{{', '.join(ft.rows[s] for s in sorted(k))}}}")
            for j in sup:
                rows.append(r)
                cols.append(j)
                vals.append(1.0)
            if i not in sup:
                rows.append(r)
                cols.append(i)
                vals.append(-1.0)
            r += 1
    A = sparse.csr_matrix((vals, (rows, cols)), shape=(r, P))
    lo = np.concatenate([np.ones(n_cover), np.zeros(r - n_cover)])
    # fewest classes; among equals the fewest members in all (a row in two classes adds
    # specified entries, so overlapping covers leave fewer don't-cares to the equations)
    cost = np.array([1.0 + 0.5 * len(c) / (N * N + 1) for c in cands])
    res = milp(cost, integrality=np.ones(P), bounds=Bounds(0, 1),
               constraints=[LinearConstraint(A, lo, np.inf)],
               options={"time_limit": time_limit})
    if res.x is None:
        # the maximal compatibles always form a closed cover: fall back to it
        chosen = maximal_compatibles(comp)
        return CoverResult(chosen, False, P, method + " (solver gave no answer)")
    chosen = [cands[i] for i in np.flatnonzero(res.x > 0.5)]
    proven = exact and res.status == 0
    chosen = _shrink(ft, _drop_redundant(ft, chosen))
    return CoverResult(sorted(chosen, key=lambda c: min(c)), proven, P, method)


def _drop_redundant(ft: FlowTable, classes: list[frozenset[int]]) -> list[frozenset[int]]:
    out = list(classes)
    for c in sorted(classes, key=len):
        rest = [d for d in out if d != c]
        if rest and is_closed_cover(ft, rest):
            out = rest
    return out


def _shrink(ft: FlowTable, classes: list[frozenset[int]]) -> list[frozenset[int]]:
    """Take each row out of all but one of the classes that hold it, where the cover stays
    closed: prime compatibles are as large as possible, but a row held twice only adds
    specified entries (fewer don't-cares for the equations)."""
    out = list(classes)
    for r in range(len(ft.rows)):
        holders = [i for i, c in enumerate(out) if r in c]
        for i in sorted(holders, key=lambda i: -len(out[i]))[:-1]:
            trial = list(out)
            trial[i] = out[i] - {r}
            if trial[i] and is_closed_cover(ft, trial):
                out = trial
    return out


def brute_force_min_cover(ft: FlowTable, comp: np.ndarray | None = None) -> int:
    """Size of a minimum closed cover by trying every set of compatibles (tests only)."""
    comp = compatibility(ft) if comp is None else comp
    comps = all_compatibles(comp, 1 << 20)
    for size in range(1, len(ft.rows) + 1):
        for combo in itertools.combinations(comps, size):
            if is_closed_cover(ft, list(combo)):
                return size
    return len(ft.rows)


# ---- 3. reduced table -----------------------------------------------------------------------
@dataclass
class ReducedTable:
    """Merged rows. ``next[c][k]`` is a class index or None; ``out[c][k]`` the outputs at a
    stable total state (None where the class is not stable in column k)."""

    ft: FlowTable
    classes: list[frozenset[int]]
    next: list[list[int | None]]
    out: list[list[list[int | None] | None]]
    rep: list[int]  # class representing each original row (first containing it)

    def name(self, c: int) -> str:
        members = sorted(self.classes[c])
        if len(members) == 1:
            return self.ft.rows[members[0]]
        return "{" + ",".join(self.ft.rows[s] for s in members) + "}"

    def stable(self, c: int, k: int) -> bool:
        return self.next[c][k] == c


def reduce_table(ft: FlowTable, classes: list[frozenset[int]]) -> ReducedTable:
    K = len(ft.columns)
    C = len(classes)

    def target(c: int, k: int) -> int | None:
        seen = set()
        while True:
            I = implied_set(ft, classes[c], k)
            if not I:
                return None
            if I <= classes[c]:
                return c
            sup = [d for d in range(C) if I <= classes[d]]
            if not sup:
                raise DesignError("internal error: the cover is not closed")
            stable = [d for d in sup if implied_set(ft, classes[d], k) <= classes[d]]
            nxt = stable[0] if stable else sup[0]
            if nxt in seen:
                raise DesignError("internal error: merged rows oscillate")
            seen.add(nxt)
            c = nxt
            if stable:
                return c

    nxt = [[target(c, k) for k in range(K)] for c in range(C)]
    out: list[list[list[int | None] | None]] = []
    for c in range(C):
        line = []
        for k in range(K):
            if nxt[c][k] != c:
                line.append(None)
                continue
            vals: list[int | None] = [None] * len(ft.outputs)
            for r in classes[c]:
                if ft.stable(r, k):
                    for j, v in enumerate(ft.out[r]):
                        if v is not None:
                            vals[j] = v
            line.append(vals)
        out.append(line)
    rep = [next(c for c in range(C) if r in classes[c]) for r in range(len(ft.rows))]
    return ReducedTable(ft, classes, nxt, out, rep)


# ---- 4. state assignment --------------------------------------------------------------------
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


# ---- 5. transitions and excitation ----------------------------------------------------------
def subcube(a: int, b: int) -> list[int]:
    """Codes reachable while the bits where a and b differ switch in any order."""
    diff = a ^ b
    out = []
    sub = diff
    while True:
        out.append(a ^ sub)
        if sub == 0:
            break
        sub = (sub - 1) & diff
    return out


@dataclass
class Transition:
    column: int
    source: int  # class
    dest: int  # class


def next_state_map(rt: ReducedTable, asg: Assignment) -> list[dict[int, int]]:
    """Per column: code -> destination class, over every code a transition may pass through.
    Two transitions of a column that could meet on a code, or a transition passing a code of a
    state that goes elsewhere there, is a critical race (error naming the rows)."""
    ft = rt.ft
    K, C = len(ft.columns), len(rt.classes)
    code_of = asg.codes
    owner = {}
    for c in range(C):
        if code_of[c] in owner:
            raise DesignError(f"states {rt.name(owner[code_of[c]])} and {rt.name(c)} have the "
                              f"same code {bits_text(code_of[c], asg.width)}")
        owner[code_of[c]] = c
    maps = []
    for k in range(K):
        m: dict[int, int] = {}
        via: dict[int, int] = {}
        order = sorted(range(C), key=lambda c: (rt.next[c][k] != c, c))  # stable ones first
        for c in order:
            d = rt.next[c][k]
            if d is None:
                continue
            for q in subcube(code_of[c], code_of[d]):
                if q in m and m[q] != d:
                    raise _race(rt, asg, k, (c, d), (via[q], m[q]), q)
                m[q] = d
                via.setdefault(q, c)
        maps.append(m)
    return maps


def _race(rt: ReducedTable, asg: Assignment, k: int, t1: tuple[int, int],
          t2: tuple[int, int], q: int) -> SequentialError:
    ft, w = rt.ft, asg.width

    def code(c):
        return bits_text(asg.codes[c], w)

    other = (f"where state {rt.name(t2[0])} is stable" if t2[0] == t2[1] else
             f"which the transition {rt.name(t2[0])} → {rt.name(t2[1])} (codes "
             f"{code(t2[0])} → {code(t2[1])}) also passes")
    rows = list(dict.fromkeys(rt.name(c) for c in (*t1, *t2)))
    return SequentialError(
        "race", f"critical race in column {ft.label(k)} ({' '.join(ft.inputs)} = "
        f"{ft.label(k)}): the transition {rt.name(t1[0])} → {rt.name(t1[1])} (codes "
        f"{code(t1[0])} → {code(t1[1])}) may pass through code {bits_text(q, w)}, {other}; "
        f"the memories may settle in either state (rows {', '.join(rows)})", tuple(rows))


@dataclass
class Excitation:
    """Tables over the total-state index (x << v) | q: 0, 1 or DC."""

    names: list[str]  # inputs + state variables
    next: np.ndarray  # (2**(n+v),) destination code or -1
    sets: list[np.ndarray]
    resets: list[np.ndarray]
    outputs: list[np.ndarray]
    source_out: dict  # (column, code) -> transitions passing there: [(src class, dst class)]


def excitation(rt: ReducedTable, asg: Assignment, names: list[str],
               maps: list[dict[int, int]], fix: set[tuple[int, int, int]] = frozenset()
               ) -> Excitation:
    """``fix``: (output, column, code) whose transient value must be the destination's (a
    repair for an output that would otherwise change twice)."""
    ft = rt.ft
    n, v = ft.n, asg.width
    size = 1 << (n + v)
    nxt = np.full(size, -1, dtype=np.int64)
    code_of = asg.codes
    nout = len(ft.outputs)
    outs = [np.full(size, DC, dtype=np.int8) for _ in range(nout)]
    passing: dict[tuple[int, int], list[tuple[int, int]]] = {}
    for k, m in enumerate(maps):
        x = ft.columns[k]
        for q, d in m.items():
            nxt[(x << v) | q] = code_of[d]
    for k in range(len(ft.columns)):
        x = ft.columns[k]
        for c in range(len(rt.classes)):
            d = rt.next[c][k]
            if d is None:
                continue
            if d == c:
                for j, val in enumerate(rt.out[c][k]):
                    if val is not None:
                        outs[j][(x << v) | code_of[c]] = val
                continue
            dest_out = rt.out[d][k]
            srcs = [rt.out[c][k0] for k0 in range(len(ft.columns))
                    if rt.out[c][k0] is not None and bin(ft.columns[k0] ^ x).count("1") == 1]
            for q in subcube(code_of[c], code_of[d]):
                passing.setdefault((k, q), []).append((c, d))
                if q == code_of[d]:
                    continue
                for j in range(nout):
                    want = dest_out[j]
                    if want is None:
                        continue
                    if (j, k, q) in fix or any(s[j] == want for s in srcs):
                        outs[j][(x << v) | q] = want
    sets, resets = [], []
    qs = np.arange(size, dtype=np.int64) & ((1 << v) - 1)
    known = nxt >= 0
    for j in range(v):
        bit = 1 << (v - 1 - j)
        cur = (qs & bit) != 0
        tgt = (nxt & bit) != 0
        s = np.full(size, DC, dtype=np.int8)
        r = np.full(size, DC, dtype=np.int8)
        s[known & ~cur & ~tgt] = 0
        s[known & ~cur & tgt] = 1
        r[known & ~cur & tgt] = 0
        s[known & cur & ~tgt] = 0
        r[known & cur & ~tgt] = 1
        r[known & cur & tgt] = 0
        sets.append(s)
        resets.append(r)
    return Excitation(names, nxt, sets, resets, outs, passing)


# ---- 6. equations ---------------------------------------------------------------------------
@dataclass
class SeqEquations:
    """What the mapper builds and the JSON reports: equations over inputs + memories."""

    inputs: list[str]
    outputs: list[str]
    memories: list[str]
    initial: dict[str, int]
    set_names: dict[str, str]  # memory -> name of its SET function in ``eq``
    reset_names: dict[str, str]
    eq: Equations  # over inputs + memories; outputs: SET, RESET functions and spec outputs
    form: str  # "table" | "setreset"
    classes: list[list[str]] = field(default_factory=list)
    codes: dict[str, str] = field(default_factory=dict)  # merged row -> code
    state_codes: dict[str, str] = field(default_factory=dict)  # spec row -> code
    cover: dict = field(default_factory=dict)
    assignment: dict = field(default_factory=dict)
    essential_hazards: list[dict] = field(default_factory=list)
    checked: dict = field(default_factory=dict)
    seconds: float = 0.0

    def text(self, name: str) -> str:
        return self.eq.text(name)

    def cover_of(self, name: str) -> list[Cube]:
        """The cover the mapper builds (with consensus terms)."""
        return (self.eq.hazard_free.get(name) or self.eq.covers[name]).cubes

    def to_json(self) -> dict:
        d = {
            "form": self.form,
            "memories": [{"name": m, "set": self.text(self.set_names[m]),
                          "reset": self.text(self.reset_names[m]),
                          "initial": self.initial[m]} for m in self.memories],
            "outputs": {o: self.text(o) for o in self.outputs},
            "essential_hazards": self.essential_hazards,
            "checked": self.checked,
        }
        if self.form == "table":
            d["merged_rows"] = self.classes
            d["assignment"] = {"variables": list(self.memories), "codes": dict(self.codes),
                               "state_codes": dict(self.state_codes), **self.assignment}
            d["cover"] = self.cover
        return d


def unique_names(base: list[str], taken: set[str]) -> list[str]:
    out = []
    for b in base:
        name, i = b, 1
        while name in taken:
            name = f"{b}_{i}"
            i += 1
        taken.add(name)
        out.append(name)
    return out


def synthesise_table(spec: SeqSpec, opts: SynthOptions | None = None,
                     polarity: int = 0) -> SeqEquations:
    """Flow table -> SET/RESET and output equations (steps 1-6 of the module docstring).

    ``polarity``: state variables to complement (bit j for variable j, MSB first). The literal
    count is the same for every polarity (complementing a variable swaps its SET and RESET and
    the sign of its literals); the mapper's inverter count is not, so the pipeline tries them."""
    opts = opts or SynthOptions()
    t0 = time.perf_counter()
    ft = spec.table
    comp = compatibility(ft)
    if ft.assign:
        classes, codes, width = given_assignment(ft, comp)
        cover = CoverResult(classes, False, 0, "given by 'assign'")
        rt = reduce_table(ft, classes)
        _check_given_closed(ft, rt)
        asg = Assignment(codes, width, False, "given")
    else:
        cover = closed_cover(ft, comp, opts.time_limit)
        rt = reduce_table(ft, cover.classes)
        asg = assign_states(rt, opts.time_limit)
    if polarity:
        asg = replace(asg, codes=[c ^ polarity for c in asg.codes])
    v = asg.width
    if ft.secondary is not None and len(ft.secondary) != v:
        raise DesignError(f"'secondary' names {len(ft.secondary)} state variable(s); the "
                          f"assignment needs {v}")
    taken = set(ft.inputs) | set(ft.outputs)
    mem = list(ft.secondary) if ft.secondary else unique_names(
        [f"y{j + 1}" for j in range(v)], taken)
    if ft.n + v > MAX_TOTAL_VARIABLES:
        raise DesignError(f"{ft.n} inputs and {v} state variables: at most "
                          f"{MAX_TOTAL_VARIABLES} together")
    maps = next_state_map(rt, asg)
    names = list(ft.inputs) + mem
    # power-up: a merged row holding the initial state and stable in its column
    init_code = asg.codes[rt.next[rt.rep[ft.initial]][ft.start_column()]]
    fix: set[tuple[int, int, int]] = set()
    for _ in range(8):
        exc = excitation(rt, asg, names, maps, fix)
        se = _equations(spec, exc, mem, opts,
                        {m: (init_code >> (v - 1 - j)) & 1 for j, m in enumerate(mem)})
        bad = _double_changes(rt, asg, exc, se)
        if not bad:
            break
        fix |= bad
    else:
        raise DesignError("outputs still change twice in some transitions after 8 repairs")
    se.form = "table"
    se.classes = [[ft.rows[s] for s in sorted(c)] for c in rt.classes]
    se.codes = {rt.name(c): bits_text(asg.codes[c], v) for c in range(len(rt.classes))}
    se.state_codes = {ft.rows[r]: bits_text(asg.codes[_holding(rt, r)], v)
                      for r in range(len(ft.rows))}
    se.cover = {"rows": len(ft.rows), "merged": len(rt.classes), "proven_minimum": cover.proven,
                "candidates": cover.candidates, "method": cover.method}
    se.assignment = {"width": v, "proven_minimum": asg.proven, "method": asg.method}
    se.essential_hazards = essential_hazards(rt, asg, mem)
    se.checked = check_equations(spec, se)
    se.seconds = time.perf_counter() - t0
    return se


def _holding(rt: ReducedTable, r: int) -> int:
    """The merged row the circuit sits in while in state r (stable in r's first stable
    column)."""
    k = next(k for k in range(len(rt.ft.columns)) if rt.ft.stable(r, k))
    return rt.next[rt.rep[r]][k]


def _check_given_closed(ft: FlowTable, rt: ReducedTable) -> None:
    for c, cls in enumerate(rt.classes):
        for k in range(len(ft.columns)):
            I = implied_set(ft, cls, k)
            if len(I) >= 2 and not any(I <= d for d in rt.classes):
                raise DesignError(f"rows {rt.name(c)} share a code but in column {ft.label(k)} "
                                  f"they go to states {', '.join(ft.rows[s] for s in sorted(I))}"
                                  ", which have different codes")


def _spec_of(names: list[str], tables: dict[str, np.ndarray], path: str) -> Spec:
    nv = len(names)
    funcs = {}
    for o, t in tables.items():
        funcs[o] = OutputSpec(o, on=[Cube.minterm(int(i), nv) for i in np.flatnonzero(t == 1)],
                              dc=[Cube.minterm(int(i), nv) for i in np.flatnonzero(t == DC)])
    return Spec(path, "fsm", list(names), list(tables), funcs)


def _equations(spec: SeqSpec, exc: Excitation, mem: list[str], opts: SynthOptions,
               initial: dict[str, int]) -> SeqEquations:
    """Minimise SET, RESET (one kind first, the other with zeros where the first is built on;
    both orders tried) and the outputs; merge into one Equations for the mapper."""
    names = exc.names
    taken = set(names) | set(spec.outputs)
    set_names = dict(zip(mem, unique_names([f"set_{m}" for m in mem], taken)))
    reset_names = dict(zip(mem, unique_names([f"reset_{m}" for m in mem], taken)))
    mopts = replace(opts.minimise, complements=False)
    best = None
    # both orders for a few memories; beyond, SET first (each order costs 2 minimisations)
    for first in ("set", "reset") if len(mem) <= 4 else ("set",):
        a = {(set_names if first == "set" else reset_names)[m]: t
             for m, t in zip(mem, exc.sets if first == "set" else exc.resets)}
        eq_a = minimise(_spec_of(names, a, spec.path), mopts) if a else None
        b = {}
        for j, m in enumerate(mem):
            other = (exc.resets if first == "set" else exc.sets)[j].copy()
            built = _built(eq_a, (set_names if first == "set" else reset_names)[m], len(names))
            clash = built & (other == 1)
            if clash.any():
                raise DesignError(f"internal error: SET and RESET of {m} required on together")
            other[built] = 0
            b[(reset_names if first == "set" else set_names)[m]] = other
        eq_b = minimise(_spec_of(names, b, spec.path), mopts) if b else None
        lits = (eq_a.literals if eq_a else 0) + (eq_b.literals if eq_b else 0)
        if best is None or lits < best[0]:
            best = (lits, eq_a, eq_b)
    _, eq_a, eq_b = best
    outs = {o: exc.outputs[j] for j, o in enumerate(spec.outputs)}
    eq_z = minimise(_spec_of(names, outs, spec.path), opts.minimise)
    eq = _merge(names, [e for e in (eq_a, eq_b) if e is not None], eq_z, set_names, reset_names,
                mem, spec.outputs)
    return SeqEquations(list(spec.inputs), list(spec.outputs), mem, initial, set_names,
                        reset_names, eq, "table")


def _built(eq: Equations | None, name: str, nv: int) -> np.ndarray:
    """Where the function the mapper will build (the hazard-free cover) is on."""
    if eq is None:
        return np.zeros(1 << nv, dtype=bool)
    cover = eq.hazard_free.get(name) or eq.covers[name]
    return eval_cover(cover.cubes, np.arange(1 << nv, dtype=np.int64))


def _merge(names, sr_eqs: list[Equations], eq_z: Equations, set_names, reset_names, mem,
           outputs) -> Equations:
    order = [set_names[m] for m in mem] + [reset_names[m] for m in mem] + list(outputs)
    eq = Equations(list(names), order, {})
    for e in [*sr_eqs, eq_z]:
        eq.covers.update(e.covers)
        eq.hazard_free.update(e.hazard_free)
    # SET/RESET are built as the sums of products they are (their don't-cares were spent on
    # S·R = 0); the outputs may use the mapper's complement and XOR forms
    # (XOR forms are left out: their don't-care resolution is not checked for double changes)
    eq.complements.update(eq_z.complements)
    eq.hazard_free_complements.update(eq_z.hazard_free_complements)
    eq.covers = {o: eq.covers[o] for o in order}
    eq.shared_terms = count_shared(eq)
    return eq


def _double_changes(rt: ReducedTable, asg: Assignment, exc: Excitation,
                    se: SeqEquations) -> set[tuple[int, int, int]]:
    """(output, column, code) to pin where an output could change twice during a transition
    (paths through the transition subcube in any switching order)."""
    ft = rt.ft
    v = asg.width
    nv = len(exc.names)
    rows = np.arange(1 << nv, dtype=np.int64)
    # every form the mapper may build: the cover and the complement of the complement's cover
    # (they can resolve the don't-cares differently)
    forms = []
    for o in ft.outputs:
        fs = [eval_cover(se.cover_of(o), rows)]
        for comp in (se.eq.complements.get(o), se.eq.hazard_free_complements.get(o)):
            if comp is not None:
                fs.append(~eval_cover(comp.cubes, rows))
        forms.append(fs)
    bad = set()
    for k in range(len(ft.columns)):
        x = ft.columns[k]
        for c in range(len(rt.classes)):
            d = rt.next[c][k]
            if d is None or d == c:
                continue
            a, b = asg.codes[c], asg.codes[d]
            for j in range(len(ft.outputs)):
                if any(_max_changes(f, x, v, a, b) > 1 for f in forms[j]):
                    bad |= {(j, k, q) for q in subcube(a, b) if q != b}
    return bad


def _max_changes(val: np.ndarray, x: int, v: int, a: int, b: int) -> int:
    """Most changes of an output along any monotone path from code a to code b."""
    best: dict[int, int] = {}
    for q in sorted(subcube(a, b), key=lambda q: bin(q ^ a).count("1"), reverse=True):
        if q == b:
            best[q] = 0
            continue
        here = val[(x << v) | q]
        opts = []
        diff = q ^ b
        for i in range(v):
            bit = 1 << i
            if diff & bit:
                s = q ^ bit
                opts.append(best[s] + int(val[(x << v) | s] != here))
        best[q] = max(opts)
    return best[a]


# ---- essential hazards and the final check --------------------------------------------------
def essential_hazards(rt: ReducedTable, asg: Assignment, mem: list[str]) -> list[dict]:
    """Unger's test per stable total state and input: the change applied three times ends in
    another state than applied once. The logic cannot remove this; it needs an ordering."""
    ft = rt.ft
    out = []
    v = asg.width
    for c in range(len(rt.classes)):
        for k in range(len(ft.columns)):
            if not rt.stable(c, k):
                continue
            for i, name in enumerate(ft.inputs):
                k2 = ft.column_of(ft.columns[k] ^ (1 << (ft.n - 1 - i)))
                if k2 is None:
                    continue
                d1 = rt.next[c][k2]
                d2 = None if d1 is None else rt.next[d1][k]
                d3 = None if d2 is None else rt.next[d2][k2]
                if d3 is None or d3 == d1:
                    continue
                changing = [mem[j] for j in range(v)
                            if (asg.codes[c] ^ asg.codes[d1]) >> (v - 1 - j) & 1]
                state = next(ft.rows[r] for r in sorted(rt.classes[c]) if ft.stable(r, k))
                out.append({
                    "state": state, "input": name, "from": ft.label(k), "to": ft.label(k2),
                    "expected": rt.name(d1), "wrong": rt.name(d3), "memories": changing,
                    "requires": f"{name} must reach every SET/RESET generator before "
                                f"{', '.join(changing) or 'the memories'} switch"
                                f"{'es' if len(changing) == 1 else ''} (no AMPLIFIER or other "
                                f"delay on {name}'s paths longer than the MEMORY switching time)"
                                f"; else the machine may end in {rt.name(d3)} instead of "
                                f"{rt.name(d1)}"})
    return out


def check_equations(spec: SeqSpec, se: SeqEquations) -> dict:
    """Run the equations (the covers the mapper builds) through every specified transition
    from every reachable stable state, every memory switching order included: the result must
    be unique, S·R = 0 at every total state passed, outputs as the spec says. Raises."""
    from mechc.ir.seqspec import initial_total_state, next_stable, output_values

    nv = len(se.eq.inputs)
    v = len(se.memories)
    rows = np.arange(1 << nv, dtype=np.int64)
    S = [eval_cover(se.cover_of(se.set_names[m]), rows) for m in se.memories]
    R = [eval_cover(se.cover_of(se.reset_names[m]), rows) for m in se.memories]
    Z = {o: eval_cover(se.cover_of(o), rows) for o in spec.outputs}
    overlap_anywhere = int(sum(int((s & r).sum()) for s, r in zip(S, R)))

    def excite_at(x):
        def f(q):
            i = (x << v) | q
            return memory_targets(((S[j][i], R[j][i]) for j in range(v)), q, v)
        return f

    x0, st0 = initial_total_state(spec)
    q0 = sum(se.initial[m] << (v - 1 - j) for j, m in enumerate(se.memories))
    first = settle_async(excite_at(x0), q0, v)
    if first.finals != [q0]:
        raise DesignError(f"internal error: the initial state is not stable in the equations "
                          f"({bits_text(q0, v)} → {[bits_text(f, v) for f in first.finals]})")
    seen = {(x0, st0, q0)}
    todo = [(x0, st0, q0)]
    transitions = 0
    while todo:
        x, st, q = todo.pop()
        want = output_values(spec, st, x)
        for o, w in want.items():
            got = int(Z[o][(x << v) | q])
            if w is not None and got != w:
                raise DesignError(f"internal error: output {o} is {got} at "
                                  f"{_where(spec, x, st)}, spec says {w}")
        from mechc.ir.seqspec import allowed_changes

        for x2 in allowed_changes(spec, st, x):
            transitions += 1
            st2 = next_stable(spec, st, x, x2)
            res = settle_async(excite_at(x2), q, v)
            if res.overlaps:
                qq, j = res.overlaps[0]
                raise DesignError(f"SET and RESET of {se.memories[j]} both on at "
                                  f"{' '.join(spec.inputs)} = {bits_text(x2, spec.n)}, "
                                  f"{' '.join(se.memories)} = {bits_text(qq, v)}")
            if res.cycle or len(res.finals) != 1:
                raise DesignError(f"internal error: race after {_where(spec, x, st)} → "
                                  f"{bits_text(x2, spec.n)}")
            node = (x2, st2, res.finals[0])
            if node not in seen:
                seen.add(node)
                todo.append(node)
    return {"stable_states": len(seen), "transitions": transitions,
            "sr_overlap_total_states": overlap_anywhere}


def _where(spec: SeqSpec, x: int, st) -> str:
    from mechc.ir.seqspec import describe_total

    return describe_total(spec, x, st)


# ---- set/reset specs ------------------------------------------------------------------------
def setreset_equations(spec: SeqSpec, opts: SynthOptions | None = None) -> SeqEquations:
    """The given SET/RESET/output expressions minimised exactly (no don't-cares: the
    expressions are the spec) with consensus terms; then the same reachability check."""
    opts = opts or SynthOptions()
    t0 = time.perf_counter()
    mem = spec.memory_names
    names = list(spec.inputs) + mem
    if len(names) > MAX_TOTAL_VARIABLES:
        raise DesignError(f"{len(names)} inputs and memories: at most {MAX_TOTAL_VARIABLES}")
    t = spec.sr_tables()
    taken = set(names) | set(spec.outputs)
    set_names = dict(zip(mem, unique_names([f"set_{m}" for m in mem], taken)))
    reset_names = dict(zip(mem, unique_names([f"reset_{m}" for m in mem], taken)))
    sr = {}
    for m in mem:
        sr[set_names[m]] = t["S:" + m].astype(np.int8)
        sr[reset_names[m]] = t["R:" + m].astype(np.int8)
    mopts = replace(opts.minimise, complements=False)
    eq_sr = minimise(_spec_of(names, sr, spec.path), mopts) if sr else None
    eq_z = minimise(_spec_of(names, {o: t["Z:" + o].astype(np.int8) for o in spec.outputs},
                             spec.path), opts.minimise)
    eq = _merge(names, [eq_sr] if eq_sr else [], eq_z, set_names, reset_names, mem,
                spec.outputs)
    se = SeqEquations(list(spec.inputs), list(spec.outputs), mem,
                      {m.name: m.initial for m in spec.memories}, set_names, reset_names, eq,
                      "setreset")
    se.checked = check_equations(spec, se)
    se.seconds = time.perf_counter() - t0
    return se


def derive_equations(spec: SeqSpec, opts: SynthOptions | None = None) -> SeqEquations:
    """The ``SeqSpec -> equations`` stage for either form."""
    if spec.table is not None:
        return synthesise_table(spec, opts)
    return setreset_equations(spec, opts)


def expr_of(se: SeqEquations, name: str) -> ex.Expr:
    return se.eq.expr(name)
