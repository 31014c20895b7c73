"""Sequential specifications (``.fsm``) and their reference semantics (fundamental mode).

A :class:`SeqSpec` is either a flow table (rows are states, columns input combinations, stable
entries marked, outputs per row; ``001_…`` Appendix B) or MEMORY set/reset equations with output
equations (``001_…`` eq. B.1: y = S + y·R̄). The functions here say, for a total state (input
vector + internal state) and a new input vector, which stable state the machine reaches and what
its outputs are there. They are the reference the logic-level proof holds a netlist to, and the
walks the dynamic level drives are planned on them.

Bit conventions follow ``mechc.logic.cubes``: input 0 is the most significant bit of an input
vector ``x``; memory 0 the most significant bit of a memory vector ``q``; a total state's index
over inputs + memories is ``(x << m) | q``.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field

import numpy as np

from mechc.errors import DesignError
from mechc.ir import expr as ex
from mechc.logic.cubes import input_matrix

#: Set/reset specs are tabulated over inputs + memories; beyond this many the tables get big.
MAX_TOTAL_VARIABLES = 20


class SequentialError(DesignError):
    """A sequential behaviour that cannot be built: overlap, race, oscillation, unspecified.

    ``kind`` is one of "overlap", "race", "oscillation", "unspecified"; ``rows`` names the flow
    table rows (or memories) involved, so front ends can point at them."""

    def __init__(self, kind: str, message: str, rows: tuple[str, ...] = ()):
        self.kind, self.rows = kind, tuple(rows)
        super().__init__(message)


# ---- flow tables ---------------------------------------------------------------------------
@dataclass
class FlowTable:
    """A flow table as written. ``next[r][k]`` is a row index or None (``-``); a row is stable
    in column k when ``next[r][k] == r``. Outputs belong to rows (0, 1 or None for ``-``)."""

    inputs: list[str]
    outputs: list[str]
    columns: list[int]  # input vector of each column, in the order written
    rows: list[str]
    next: list[list[int | None]]
    out: list[list[int | None]]
    initial: int = 0
    initial_column: int | None = None  # column index; None: the initial row's first stable one
    lines: list[int] = field(default_factory=list)  # source line of each row (messages)
    assign: dict[str, str] | None = None  # fixed state codes (row -> bits), else synthesised
    secondary: list[str] | None = None  # names of the state variables
    _dest: list[list[int | None]] | None = field(default=None, repr=False, compare=False)

    @property
    def n(self) -> int:
        return len(self.inputs)

    def label(self, k: int) -> str:
        return format(self.columns[k], f"0{self.n}b") if self.n else ""

    def column_of(self, x: int) -> int | None:
        try:
            return self.columns.index(x)
        except ValueError:
            return None

    def stable(self, r: int, k: int) -> bool:
        return self.next[r][k] == r

    def dest(self, r: int, k: int) -> int | None:
        """The stable row reached from row r when the inputs become column k (None: '-')."""
        if self._dest is None:
            self._dest = resolve_destinations(self)
        return self._dest[r][k]

    def start_column(self) -> int:
        if self.initial_column is not None:
            return self.initial_column
        for k in range(len(self.columns)):
            if self.stable(self.initial, k):
                return k
        raise SequentialError("unspecified", f"initial state {self.rows[self.initial]} has no "
                              "stable entry", (self.rows[self.initial],))

    def where(self, r: int, k: int) -> str:
        ins = "".join(self.inputs) if all(len(i) == 1 for i in self.inputs) else \
            " ".join(self.inputs)
        return f"row {self.rows[r]}, column {self.label(k)} ({ins} = {self.label(k)})"

    def to_json(self) -> dict:
        def entry(r, k):
            v = self.next[r][k]
            return "-" if v is None else (f"({self.rows[v]})" if v == r else self.rows[v])

        d = {"columns": [self.label(k) for k in range(len(self.columns))],
             "rows": [{"name": name,
                       "next": [entry(r, k) for k in range(len(self.columns))],
                       "outputs": "".join("-" if v is None else str(v) for v in self.out[r])}
                      for r, name in enumerate(self.rows)],
             "initial": self.rows[self.initial]}
        if self.initial_column is not None:
            d["initial_column"] = self.label(self.initial_column)
        if self.assign:
            d["assign"] = dict(self.assign)
        if self.secondary:
            d["secondary"] = list(self.secondary)
        return d

    @staticmethod
    def from_json(d: dict, inputs: list[str], outputs: list[str]) -> FlowTable:
        rows = [r["name"] for r in d["rows"]]
        index = {name: i for i, name in enumerate(rows)}
        cols = [int(c, 2) if c else 0 for c in d["columns"]]
        nxt = []
        for r in d["rows"]:
            line = []
            for e in r["next"]:
                line.append(None if e == "-" else index[e.strip("()")])
            nxt.append(line)
        out = [[None if ch == "-" else int(ch) for ch in r["outputs"]] for r in d["rows"]]
        ic = d.get("initial_column")
        ft = FlowTable(list(inputs), list(outputs), cols, rows, nxt, out, index[d["initial"]],
                       cols.index(int(ic, 2)) if ic else None, [0] * len(rows),
                       d.get("assign"), d.get("secondary"))
        problems = table_problems(ft)
        if problems:
            raise SequentialError(problems[0].kind, problems[0].message)
        return ft


@dataclass
class TableProblem:
    kind: str  # "unknown" | "stable" | "missing" | "dangling" | "oscillation" | "initial"
    row: int
    column: int | None
    message: str


def table_problems(ft: FlowTable) -> list[TableProblem]:
    """Everything wrong with a flow table, in row then column order (the parser reports the
    first with its line and column; ``from_json`` refuses the table)."""
    out: list[TableProblem] = []
    ncol = len(ft.columns)
    for r in range(len(ft.rows)):
        if not any(ft.next[r][k] == r for k in range(ncol)):
            out.append(TableProblem(
                "missing", r, None, f"state {ft.rows[r]} is missing from its own row: row "
                f"{ft.rows[r]} has no stable entry ({ft.rows[r]})"))
    for r in range(len(ft.rows)):
        for k in range(ncol):
            e = ft.next[r][k]
            if e is None or e == r:
                continue
            seen = [r]
            cur = e
            while True:
                nxt = ft.next[cur][k]
                if nxt == cur:
                    break
                if nxt is None:
                    via = "" if cur == e else " (reached through " + " → ".join(
                        ft.rows[s] for s in seen[1:] + [cur]) + ")"
                    out.append(TableProblem(
                        "dangling", r, k, f"unstable entry {ft.rows[e]} in row {ft.rows[r]}: "
                        f"column {ft.label(k)} has no stable state {ft.rows[cur]} (row "
                        f"{ft.rows[cur]} has '-' there){via}"))
                    break
                if cur in seen:
                    loop = seen[seen.index(cur):] + [cur]
                    out.append(TableProblem(
                        "oscillation", r, k, f"row {ft.rows[r]} oscillates in column "
                        f"{ft.label(k)}: rows " + " → ".join(ft.rows[s] for s in loop)
                        + " never reach a stable state"))
                    break
                seen.append(cur)
                cur = nxt
    if ft.initial_column is not None and not ft.stable(ft.initial, ft.initial_column):
        out.append(TableProblem("initial", ft.initial, ft.initial_column,
                                f"initial state {ft.rows[ft.initial]} is not stable in column "
                                f"{ft.label(ft.initial_column)}"))
    return out


def resolve_destinations(ft: FlowTable) -> list[list[int | None]]:
    """Final stable row of every entry (chains of unstable entries followed); assumes a table
    without problems (see :func:`table_problems`)."""
    ncol = len(ft.columns)
    dest: list[list[int | None]] = []
    for r in range(len(ft.rows)):
        line: list[int | None] = []
        for k in range(ncol):
            cur = ft.next[r][k]
            steps = 0
            while cur is not None and ft.next[cur][k] != cur:
                cur = ft.next[cur][k]
                steps += 1
                if steps > len(ft.rows):
                    raise SequentialError("oscillation", f"{ft.where(r, k)} never settles",
                                          (ft.rows[r],))
            line.append(cur)
        dest.append(line)
    return dest


# ---- set/reset specs -----------------------------------------------------------------------
@dataclass
class MemorySpec:
    name: str
    set: ex.Expr
    reset: ex.Expr
    initial: int = 0
    line: int = 0

    def to_json(self) -> dict:
        return {"name": self.name, "set": ex.to_text(self.set), "reset": ex.to_text(self.reset),
                "initial": self.initial}


@dataclass
class SeqSpec:
    """A sequential spec: a flow table (``table``), or memories + output ``equations``."""

    path: str
    inputs: list[str]
    outputs: list[str]
    memories: list[MemorySpec] = field(default_factory=list)
    equations: dict[str, ex.Expr] = field(default_factory=dict)
    table: FlowTable | None = None
    start_inputs: int = 0  # set/reset form: the input vector at power-up
    kind: str = "fsm"
    _tables: dict | None = field(default=None, repr=False, compare=False)

    @property
    def n(self) -> int:
        return len(self.inputs)

    @property
    def form(self) -> str:
        return "table" if self.table is not None else "setreset"

    @property
    def memory_names(self) -> list[str]:
        return [m.name for m in self.memories]

    def to_json(self) -> dict:
        d: dict = {"source": self.path, "kind": "fsm", "form": self.form,
                   "inputs": list(self.inputs), "outputs": list(self.outputs),
                   "functions": {o: {"expr": ex.to_text(e)} for o, e in self.equations.items()}}
        if self.table is not None:
            d["table"] = self.table.to_json()
        else:
            d["memories"] = [m.to_json() for m in self.memories]
            d["start"] = format(self.start_inputs, f"0{self.n}b") if self.n else ""
        return d

    # ---- set/reset tables over (x, q) -------------------------------------------------------
    def sr_tables(self) -> dict[str, np.ndarray]:
        """Boolean tables over the total-state index (x << m) | q: ``S:name``, ``R:name`` per
        memory and ``Z:name`` per output."""
        if self._tables is None:
            names = self.inputs + self.memory_names
            v = len(names)
            if v > MAX_TOTAL_VARIABLES:
                raise SequentialError("unspecified", f"{len(self.inputs)} inputs and "
                                      f"{len(self.memories)} memories: at most "
                                      f"{MAX_TOTAL_VARIABLES} together")
            mat = input_matrix(v)
            env = {nm: mat[k] for k, nm in enumerate(names)}
            t: dict[str, np.ndarray] = {}
            for mspec in self.memories:
                t["S:" + mspec.name] = ex.evaluate(mspec.set, env, 1 << v)
                t["R:" + mspec.name] = ex.evaluate(mspec.reset, env, 1 << v)
            for o in self.outputs:
                t["Z:" + o] = ex.evaluate(self.equations[o], env, 1 << v)
            self._tables = t
        return self._tables


# ---- asynchronous settling (shared by the reference and the netlist simulator) -------------
@dataclass
class Settling:
    """All ways a set of memories can settle after an input change, when any non-empty subset
    of the excited memories may switch first (every order and every simultaneity)."""

    start: int
    finals: list[int]  # stable memory vectors reachable
    succ: dict[int, list[int]]  # explored graph on unstable vectors
    overlaps: list[tuple[int, int]]  # (memory vector, memory index) with S and R both on
    cycle: list[int] | None  # a reachable cycle of unstable vectors (may never settle)


def settle_async(excite: Callable[[int], tuple[int, int]], q0: int, m: int,
                 limit: int = 1 << 16) -> Settling:
    """``excite(q)`` gives (target, overlap mask): target = S | (q & ~R) per memory bit (the
    memory's next value), overlap = S & R. A memory in overlap may go either way."""
    succ: dict[int, list[int]] = {}
    finals: list[int] = []
    overlaps: list[tuple[int, int]] = []
    todo = deque([q0])
    seen = {q0}
    while todo:
        q = todo.popleft()
        target, ov = excite(q)
        if ov:
            overlaps.extend((q, j) for j in range(m) if ov >> (m - 1 - j) & 1)
        excited = (q ^ target) | ov
        if not excited:
            finals.append(q)
            continue
        nxt = []
        sub = excited
        while sub:
            nxt.append(q ^ sub)
            sub = (sub - 1) & excited
        succ[q] = nxt
        for s in nxt:
            if s not in seen:
                seen.add(s)
                if len(seen) > limit:
                    raise SequentialError("oscillation", f"more than {limit} transient states")
                todo.append(s)
    return Settling(q0, sorted(finals), succ, overlaps, _find_cycle(succ))


def _find_cycle(succ: dict[int, list[int]]) -> list[int] | None:
    color: dict[int, int] = {}
    for root in succ:
        if color.get(root):
            continue
        stack = [(root, iter(succ.get(root, ())))]
        path = [root]
        color[root] = 1
        while stack:
            node, it = stack[-1]
            for s in it:
                if s not in succ:
                    continue  # stable: no way on
                c = color.get(s, 0)
                if c == 1:
                    return path[path.index(s):]
                if c == 0:
                    color[s] = 1
                    stack.append((s, iter(succ[s])))
                    path.append(s)
                    break
            else:
                color[node] = 2
                stack.pop()
                path.pop()
    return None


# ---- reference semantics -------------------------------------------------------------------
State = int  # flow table: row index; set/reset form: memory vector q


def bits_text(v: int, width: int) -> str:
    return format(v, f"0{width}b") if width else ""


def describe_total(spec: SeqSpec, x: int, state: State) -> str:
    ins = f"{' '.join(spec.inputs)} = {bits_text(x, spec.n)}"
    if spec.table is not None:
        return f"state {spec.table.rows[state]} at {ins}"
    mem = spec.memory_names
    return f"{ins}, {' '.join(mem)} = {bits_text(state, len(mem))}"


def _sr_excite(spec: SeqSpec, x: int) -> Callable[[int], tuple[int, int]]:
    t = spec.sr_tables()
    m = len(spec.memories)
    S = [t["S:" + mm.name] for mm in spec.memories]
    R = [t["R:" + mm.name] for mm in spec.memories]

    def excite(q: int) -> tuple[int, int]:
        i = (x << m) | q
        return memory_targets(((S[j][i], R[j][i]) for j in range(m)), q, m)

    return excite


def memory_targets(sr: Iterable[tuple[int, int]], q: int, m: int) -> tuple[int, int]:
    """Where each of ``m`` memories (bit j from the MSB of ``q``) heads given its (SET, RESET):
    Q' = S + Q·R̄; returns (target state, bits whose SET and RESET are both on)."""
    target = ov = 0
    for j, (s, r) in enumerate(sr):
        b = 1 << (m - 1 - j)
        if s and r:
            ov |= b
        if s or (q & b and not r):
            target |= b
    return target, ov


def initial_total_state(spec: SeqSpec) -> tuple[int, State]:
    """The power-up total state (inputs, state), settled."""
    if spec.table is not None:
        ft = spec.table
        return ft.columns[ft.start_column()], ft.initial
    q0 = 0
    m = len(spec.memories)
    for j, mm in enumerate(spec.memories):
        q0 |= mm.initial << (m - 1 - j)
    x0 = spec.start_inputs
    return x0, _settle_sr(spec, q0, x0, None)


def _settle_sr(spec: SeqSpec, q: int, x: int, x_from: int | None) -> int:
    st = settle_async(_sr_excite(spec, x), q, len(spec.memories))
    how = "at power-up" if x_from is None else \
        f"after {' '.join(spec.inputs)} {bits_text(x_from, spec.n)} → {bits_text(x, spec.n)}"
    if st.overlaps:
        qq, j = st.overlaps[0]
        raise SequentialError("overlap", f"SET and RESET of {spec.memories[j].name} are both on "
                              f"at {describe_total(spec, x, qq)} ({how})",
                              (spec.memories[j].name,))
    if st.cycle:
        raise SequentialError("oscillation", f"the memories may oscillate {how} from "
                              f"{describe_total(spec, x if x_from is None else x_from, q)}: "
                              + " → ".join(bits_text(c, len(spec.memories)) for c in st.cycle),
                              tuple(spec.memory_names))
    if len(st.finals) > 1:
        raise SequentialError("race", f"critical race {how} from "
                              f"{describe_total(spec, x if x_from is None else x_from, q)}: "
                              "the memories may settle at "
                              + " or ".join(bits_text(f, len(spec.memories)) for f in st.finals),
                              tuple(spec.memory_names))
    return st.finals[0]


def next_stable(spec: SeqSpec, state: State, x_old: int, x_new: int) -> State:
    """The stable state reached when the inputs change from x_old to x_new (fundamental mode:
    the machine was stable at x_old)."""
    if spec.table is not None:
        ft = spec.table
        k = ft.column_of(x_new)
        d = None if k is None else ft.dest(state, k)
        if d is None:
            raise SequentialError("unspecified", f"{describe_total(spec, x_old, state)}: the "
                                  f"change to {bits_text(x_new, spec.n)} is not specified",
                                  (ft.rows[state],))
        return d
    return _settle_sr(spec, state, x_new, x_old)


def allowed_changes(spec: SeqSpec, state: State, x: int) -> list[int]:
    """New input vectors (one input changed) that the spec specifies from this stable state."""
    out = []
    for k in range(spec.n):
        x2 = x ^ (1 << (spec.n - 1 - k))
        if spec.table is not None:
            c = spec.table.column_of(x2)
            if c is None or spec.table.next[state][c] is None:
                continue
        out.append(x2)
    return out


def output_values(spec: SeqSpec, state: State, x: int) -> dict[str, int | None]:
    """Outputs at a stable total state (None: unspecified)."""
    if spec.table is not None:
        return dict(zip(spec.outputs, spec.table.out[state]))
    t = spec.sr_tables()
    i = (x << len(spec.memories)) | state
    return {o: int(t["Z:" + o][i]) for o in spec.outputs}


@dataclass
class StableGraph:
    """Stable total states reachable from power-up and the specified single-input changes."""

    initial: tuple[int, State]
    nodes: list[tuple[int, State]]
    edges: dict[tuple[int, State], list[tuple[int, tuple[int, State]]]]  # (x_new, target)

    @property
    def transitions(self) -> int:
        return sum(len(v) for v in self.edges.values())


def stable_graph(spec: SeqSpec, limit: int = 200_000) -> StableGraph:
    """Breadth-first over every specified transition (raises SequentialError on a spec that
    overlaps, races or oscillates)."""
    init = initial_total_state(spec)
    nodes = [init]
    edges: dict = {}
    seen = {init}
    todo = deque([init])
    while todo:
        x, s = todo.popleft()
        out = []
        for x2 in allowed_changes(spec, s, x):
            t = (x2, next_stable(spec, s, x, x2))
            out.append((x2, t))
            if t not in seen:
                seen.add(t)
                if len(seen) > limit:
                    raise SequentialError("unspecified", f"more than {limit} stable states")
                nodes.append(t)
                todo.append(t)
        edges[(x, s)] = out
    return StableGraph(init, nodes, edges)


