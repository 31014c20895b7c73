"""Step 3: the merged (reduced) flow table, outputs attached to stable total states, so the later
steps work on merged rows only."""

from __future__ import annotations

from dataclasses import dataclass

from mechc.errors import DesignError
from mechc.ir.seqspec import FlowTable
from mechc.passes.flowtable.compatibles import implied_set


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
