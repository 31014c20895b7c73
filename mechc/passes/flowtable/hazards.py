"""Hazards: outputs that could change twice during a transition (repaired by pinning them), and
essential hazards (Unger), which the logic cannot remove and which are reported with the
ordering they need."""

from __future__ import annotations

import numpy as np

from mechc.logic.cubes import eval_cover
from mechc.passes.flowtable.assign import Assignment
from mechc.passes.flowtable.equations import SeqEquations
from mechc.passes.flowtable.excite import Excitation, subcube
from mechc.passes.flowtable.reduce import ReducedTable


def double_changes(rt: ReducedTable, asg: Assignment, exc: Excitation,
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
            # the columns the machine may come from, stable in c: the input's own change at
            # code a is the first change an output may make
            olds = [ft.columns[k0] for k0 in range(len(ft.columns))
                    if rt.next[c][k0] == c and bin(ft.columns[k0] ^ x).count("1") == 1]
            for j in range(len(ft.outputs)):
                if any(_max_changes(f, x, v, a, b) + max(
                        (int(f[(x0 << v) | a] != f[(x << v) | a]) for x0 in olds), default=0)
                       > 1 for f in forms[j]):
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
