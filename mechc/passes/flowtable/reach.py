"""Step 0: the rows a flow table can ever be in. From the initial state, every specified
single-input change (fundamental mode) is followed through its chain of unstable entries; rows
never visited cost memories and constrain merging for nothing, so they are dropped before
reduction (with a warning naming them)."""

from __future__ import annotations

from dataclasses import dataclass

from mechc.ir.seqspec import FlowTable


@dataclass
class Reach:
    """``kept``: rows visited (stable or passed through), in table order; ``dropped``: the
    others; ``transitions``: specified single-input changes from reachable stable states."""

    kept: list[int]
    dropped: list[int]
    transitions: int


def _chain(ft: FlowTable, r: int, k: int) -> list[int]:
    """Rows passed through from row r when the inputs become column k, ending at the stable
    one ([] for '-'); the table has no oscillation or dangling entry (checked on parsing)."""
    out: list[int] = []
    cur = ft.next[r][k]
    while cur is not None:
        out.append(cur)
        if ft.next[cur][k] == cur or len(out) > len(ft.rows):
            break
        cur = ft.next[cur][k]
    return out


def reachable(ft: FlowTable) -> Reach:
    """Breadth-first over stable total states (column, row) from power-up."""
    n = ft.n
    start = (ft.start_column(), ft.initial)
    seen = {start}
    todo = [start]
    visited = {ft.initial}
    transitions = 0
    while todo:
        k, r = todo.pop()
        for i in range(n):
            k2 = ft.column_of(ft.columns[k] ^ (1 << (n - 1 - i)))
            if k2 is None or ft.next[r][k2] is None:
                continue
            transitions += 1
            path = _chain(ft, r, k2)
            visited.update(path)
            node = (k2, path[-1])
            if node not in seen:
                seen.add(node)
                todo.append(node)
    kept = sorted(visited)
    return Reach(kept, [r for r in range(len(ft.rows)) if r not in visited], transitions)


def prune_table(ft: FlowTable, reach: Reach) -> FlowTable:
    """The table without the dropped rows. An entry of a kept row whose chain enters a dropped
    row is never taken (else that row would be visited) and becomes '-'; stable entries and
    every taken chain stay as written, so no entry dangles."""
    if not reach.dropped:
        return ft
    index = {r: i for i, r in enumerate(reach.kept)}
    K = len(ft.columns)
    nxt: list[list[int | None]] = []
    for r in reach.kept:
        line: list[int | None] = []
        for k in range(K):
            path = _chain(ft, r, k)
            line.append(index[path[0]] if path and all(s in index for s in path) else None)
        nxt.append(line)
    names = [ft.rows[r] for r in reach.kept]
    assign = ({nm: code for nm, code in ft.assign.items() if nm in names}
              if ft.assign else ft.assign)
    lines = [ft.lines[r] for r in reach.kept] if len(ft.lines) == len(ft.rows) else []
    return FlowTable(list(ft.inputs), list(ft.outputs), list(ft.columns), names, nxt,
                     [list(ft.out[r]) for r in reach.kept], index[ft.initial], ft.initial_column,
                     lines, assign, list(ft.secondary) if ft.secondary else ft.secondary)


def reach_warnings(path: str, ft: FlowTable, reach: Reach) -> list[str]:
    """What the user should hear: rows never reached (file:line of each), and a table whose
    initial state has no specified input change (nothing to prove beyond power-up)."""
    out = []
    if reach.dropped:
        where = ", ".join(f"{ft.rows[r]} ({path}:{ft.lines[r]})" if len(ft.lines) == len(ft.rows)
                          else ft.rows[r] for r in reach.dropped)
        out.append(f"{len(reach.dropped)} row(s) of the flow table cannot be reached from the "
                   f"initial state {ft.rows[ft.initial]} by single-input changes and are not "
                   f"built: {where}")
    if reach.transitions == 0:
        out.append(f"the initial state {ft.rows[ft.initial]} has no specified single-input "
                   "change: the circuit never leaves power-up, and the proofs have no transition "
                   "to check (only the power-up state)")
    return out
