"""Step 5: transitions and excitation: next code, SET/RESET and outputs per total state, with
don't-cares; a critical race between transitions is reported here, naming the rows."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mechc.errors import DesignError
from mechc.ir.seqspec import SequentialError, bits_text
from mechc.logic.cubes import DC
from mechc.passes.flowtable.assign import Assignment
from mechc.passes.flowtable.reduce import ReducedTable


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
    repair for an output that would otherwise change twice), or the source's where the
    destination leaves the output unspecified."""
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
                end = q == code_of[d]
                for j in range(nout):
                    want = dest_out[j]
                    if want is None:
                        # unspecified at the destination: a repair holds one value all the
                        # way, the destination's (unspecified) stable point included, so the
                        # output changes at most once, with the input (the source's value
                        # where the source columns agree)
                        held = sorted({s[j] for s in srcs if s[j] is not None})
                        if (j, k, code_of[c]) in fix and outs[j][(x << v) | q] == DC:
                            outs[j][(x << v) | q] = held[0] if held else 0
                        continue
                    if end:
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
