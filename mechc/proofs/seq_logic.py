"""Logic-level proof of a sequential netlist (cells + MEMORY) in fundamental mode.

From power-up, every specified single-input change from every reachable stable state: the
combinational cells are evaluated as Boolean functions, the memories switch in every possible
order and grouping (each non-empty subset of the excited memories may switch first), and the
result must be one stable state whose outputs are the spec's (flow table or set/reset
reference, :mod:`mechc.ir.seqspec`). Failures: wrong output, SET and RESET of a memory on
together at any total state passed, a critical race (two possible end states), an oscillation,
an output that changes when it must hold or twice when it must change once.

A second, ternary pass (Eichelberger's algorithms A and B, with the moving input at mid-stroke
as X and every memory free to switch while it travels) finds what binary switching orders
cannot: an output that dips while an input moves (a static hazard of the linkage: failure), a
memory whose SET and RESET move together (they must be driven without relative delay, the
situation of ``001_…`` Appendix B.2), and a memory whose end state depends on switching before
the input has finished its stroke (an essential hazard: the ordering it needs is reported).

Also exported for the kinematic and dynamic levels: :func:`transition_tour` (input sequences
covering every specified transition, plus seeded random walks) and :func:`expected_after` (the
spec's outputs at each stable state of a sequence).
"""

from __future__ import annotations

import time
from collections import deque
from dataclasses import dataclass

import numpy as np

from mechc.cells.library import Library
from mechc.errors import UsageError
from mechc.ir.design import Design
from mechc.ir.logic_types import evaluate_type
from mechc.ir.netlist import Netlist
from mechc.ir.seqspec import (
    SeqSpec,
    allowed_changes,
    bits_text,
    describe_total,
    initial_total_state,
    memory_targets,
    next_stable,
    output_values,
    settle_async,
    stable_graph,
)
from mechc.logic.cubes import input_matrix
from mechc.proofs.registry import OnProgress, check_interface, engine
from mechc.proofs.report import LOGIC_FIGURES, ProofReport
from mechc.proofs.settings import ProofSettings

X = 2  # the ternary "moving" value
MAX_LISTED = 50
#: A cell with more inputs than this is evaluated through numpy instead of a lookup table.
TABLE_MAX_INPUTS = 10


class SeqNetlist:
    """A netlist split for state-by-state evaluation: combinational cells in order (MEMORY
    outputs are sources), each with its truth table; the MEMORY cells with their nets."""

    def __init__(self, nl: Netlist, inputs: list[str]):
        self.nl = nl
        self.inputs = list(inputs)  # the spec's order: bit 0 of x is the MSB
        mems = [c for c in nl.cells.values() if c.type == "MEMORY"]
        self.mems = sorted(mems, key=lambda c: c.outputs[0])
        self.m = len(self.mems)
        self.mem_nets = [c.outputs[0] for c in self.mems]
        self.comb = [c for c in nl.topo_cells() if c.type != "MEMORY"]
        self.tables: dict[str, list[int]] = {}
        for c in self.comb:
            k = len(c.inputs)
            if c.type == "CONST":
                self.tables[c.id] = [int(bool(c.params.get("value", 0)))]
                continue
            if k > TABLE_MAX_INPUTS:
                raise UsageError(f"cell {c.id} has {k} inputs; the sequential simulator handles "
                                 f"at most {TABLE_MAX_INPUTS}")
            mat = input_matrix(k)
            out = evaluate_type(c.type, [mat[i] for i in range(k)], c.params, 1 << k)
            self.tables[c.id] = [int(v) for v in out]
        self._cache: dict[tuple[int, int], dict[str, int]] = {}

    def initial(self) -> int:
        q = 0
        for j, c in enumerate(self.mems):
            q |= int(c.params.get("initial", 0)) << (self.m - 1 - j)
        return q

    def _base(self, x: int, q: int) -> dict[str, int]:
        n = len(self.inputs)
        vals = {name: (x >> (n - 1 - k)) & 1 for k, name in enumerate(self.inputs)}
        for j, net in enumerate(self.mem_nets):
            vals[net] = (q >> (self.m - 1 - j)) & 1
        return vals

    def eval(self, x: int, q: int) -> dict[str, int]:
        """Every net's value at the total state (x, q)."""
        key = (x, q)
        hit = self._cache.get(key)
        if hit is None:
            hit = self.eval3(self._base(x, q))
            self._cache[key] = hit
        return hit

    def eval3(self, vals: dict[str, int]) -> dict[str, int]:
        """Ternary evaluation (0, 1, X): a cell's output is X when its inputs' unknown values
        could make it either 0 or 1."""
        vals = dict(vals)
        for c in self.comb:
            t = self.tables[c.id]
            ins = [vals[n] for n in c.inputs]
            unknown = [i for i, v in enumerate(ins) if v == X]
            k = len(ins)
            base = 0
            for i, v in enumerate(ins):
                if v == 1:
                    base |= 1 << (k - 1 - i)
            if not unknown:
                out = t[base] if k else t[0]
            else:
                seen = set()
                for sub in range(1 << len(unknown)):
                    idx = base
                    for b, i in enumerate(unknown):
                        if sub >> b & 1:
                            idx |= 1 << (k - 1 - i)
                    seen.add(t[idx])
                    if len(seen) == 2:
                        break
                out = X if len(seen) == 2 else seen.pop()
            for net in c.outputs:
                vals[net] = out
        return vals

    def sr(self, vals: dict[str, int], j: int) -> tuple[int, int]:
        c = self.mems[j]
        return vals[c.inputs[0]], vals[c.inputs[1]]

    def excite(self, x: int):
        def f(q: int) -> tuple[int, int]:
            vals = self.eval(x, q)
            return memory_targets((self.sr(vals, j) for j in range(self.m)), q, self.m)

        return f


def _mem_next3(s: int, r: int, q: int) -> int:
    """Ternary MEMORY: Q' = S + Q·R̄ over every binary reading of the X's (S·R = 1: either)."""
    outs = set()
    for sv in ((0, 1) if s == X else (s,)):
        for rv in ((0, 1) if r == X else (r,)):
            for qv in ((0, 1) if q == X else (q,)):
                if sv and rv:
                    outs |= {0, 1}
                else:
                    outs.add(1 if sv or (qv and not rv) else 0)
    return X if len(outs) == 2 else outs.pop()


def ternary_transition(sn: SeqNetlist, x_old: int, x_new: int, q: int) -> dict:
    """Algorithms A and B for one input change: A with the moving input at X, memories free to
    switch (each takes X when it might); B with the input at its new value. Returns the memory
    values after A and B and the nets at the start of the motion and after A."""
    n = len(sn.inputs)
    moving = x_old ^ x_new
    base = sn._base(x_old, q)
    for k, name in enumerate(sn.inputs):
        if moving >> (n - 1 - k) & 1:
            base[name] = X
    start = sn.eval3(base)  # input mid-stroke, no memory has moved yet
    mem = {net: base[net] for net in sn.mem_nets}
    vals = start
    for _ in range(2 * sn.m + 2):  # A: values only ever become X, so this terminates
        changed = False
        for j, net in enumerate(sn.mem_nets):
            s, r = sn.sr(vals, j)
            nv = _mem_next3(s, r, mem[net])
            if nv != mem[net]:
                mem[net] = X
                changed = True
        if not changed:
            break
        vals = sn.eval3({**base, **mem})
    after_a = vals
    mem_a = dict(mem)
    new_base = sn._base(x_new, 0)
    for _ in range(2 * sn.m + 2):  # B: X's can only resolve
        vals = sn.eval3({**new_base, **mem})
        nxt = {}
        for j, net in enumerate(sn.mem_nets):
            s, r = sn.sr(vals, j)
            nxt[net] = _mem_next3(s, r, mem[net])
        if nxt == mem:
            break
        mem = nxt
    return {"start": start, "after_a": after_a, "mem_a": mem_a, "mem_b": mem}


def _max_changes(sn: SeqNetlist, out_net: str, x_old: int, x_new: int, q0: int,
                 settling) -> int:
    """Most changes of a net along any switching order: (x_old, q0) → (x_new, q0) → ... →
    a final state."""
    memo: dict[int, int] = {}

    def best(q: int) -> int:
        if q in memo:
            return memo[q]
        memo[q] = 0  # cycles are reported separately; cut them here
        here = sn.eval(x_new, q)[out_net]
        m = 0
        for s in settling.succ.get(q, ()):
            m = max(m, best(s) + int(sn.eval(x_new, s)[out_net] != here))
        memo[q] = m
        return m

    first = int(sn.eval(x_old, q0)[out_net] != sn.eval(x_new, q0)[out_net])
    return first + best(q0)


@engine("logic", "sequential")
def sequential_logic_engine(design: Design, spec: SeqSpec, lib: Library,
                            settings: ProofSettings, progress: OnProgress | None) -> ProofReport:
    return prove_sequential(design.netlist, spec, seed=settings.seed)


def prove_sequential(nl: Netlist, spec: SeqSpec, seed: int = 0) -> ProofReport:
    """The logic-level proof (exhaustive over every specified transition)."""
    t0 = time.perf_counter()
    check_interface(nl, spec)
    sn = SeqNetlist(nl, spec.inputs)
    m = sn.m
    failures: list[dict] = []
    hazards: list[dict] = []
    kinds: dict[str, int] = {}

    def fail(kind: str, message: str, **extra) -> None:
        kinds[kind] = kinds.get(kind, 0) + 1
        if len(failures) < MAX_LISTED:
            failures.append({"kind": kind, "message": message, **extra})

    def mem_text(q: int) -> str:
        return f"{' '.join(sn.mem_nets)} = {bits_text(q, m)}" if m else "no memories"

    x0, s0 = initial_total_state(spec)
    q_init = sn.initial()
    st = settle_async(sn.excite(x0), q_init, m)
    if st.overlaps or st.cycle or len(st.finals) != 1:
        fail("initial", f"the circuit does not settle to one state at power-up "
                        f"({' '.join(spec.inputs)} = {bits_text(x0, spec.n)}, {mem_text(q_init)})")
        return _report(spec, t0, failures, kinds, hazards, 0, 0, m)
    states = transitions = 0
    reached: set = set()
    for (x, s, q), changes in _reachable(sn, spec, (x0, s0, st.finals[0])):
        states += 1
        reached.add(s)
        vals = sn.eval(x, q)
        want = output_values(spec, s, x)
        for o, w in want.items():
            got = vals[nl.outputs[o]]
            if w is not None and got != w:
                fail("output", f"{o}: expected {w}, got {got} at {describe_total(spec, x, s)} "
                               f"({mem_text(q)})", output=o, expected=w, got=got)
        for x2, s2, res in changes:
            transitions += 1
            moved = _moved(spec, x, x2)
            where = f"{describe_total(spec, x, s)}, {moved}"
            for qq, j in res.overlaps[:1]:
                fail("overlap", f"SET and RESET of {sn.mem_nets[j]} both on after {where} "
                                f"({mem_text(qq)})", memory=sn.mem_nets[j])
            if res.cycle:
                fail("oscillation", f"the memories may oscillate after {where}: "
                                    + " → ".join(bits_text(c, m) for c in res.cycle))
                continue
            if len(res.finals) > 1:
                fail("race", f"critical race after {where}: the memories may settle at "
                             + " or ".join(bits_text(f, m) for f in res.finals))
            before, after = want, output_values(spec, s2, x2)
            for o in spec.outputs:
                c = _max_changes(sn, nl.outputs[o], x, x2, q, res)
                hold = before[o] is not None and before[o] == after[o]
                if (hold and c > 0) or c > 1:
                    fail("glitch", f"{o} changes {c} time(s) after {where} (it must "
                                   f"{'hold' if hold else 'change once'})", output=o)
            _ternary(sn, spec, nl, x, x2, q, s, s2, before, after, where, fail, hazards,
                     res.finals[0] if res.finals else q)
    return _report(spec, t0, failures, kinds, hazards, states, transitions, m, reached)


def _reachable(sn: SeqNetlist, spec: SeqSpec, start: tuple):
    """Breadth-first over the reachable stable total states (x, spec state, memory code): per
    state, its specified single-input changes as (x2, next spec state, Settling). A change
    whose memories may oscillate leads nowhere (the proof reports it)."""
    seen, todo = {start}, deque([start])
    while todo:
        x, s, q = todo.popleft()
        changes = []
        for x2 in allowed_changes(spec, s, x):
            res = settle_async(sn.excite(x2), q, sn.m)
            s2 = next_stable(spec, s, x, x2)
            changes.append((x2, s2, res))
            if res.cycle:
                continue
            for qf in res.finals[:1]:
                if (x2, s2, qf) not in seen:
                    seen.add((x2, s2, qf))
                    todo.append((x2, s2, qf))
        yield (x, s, q), changes


def outputs_needing_snap(nl: Netlist, spec: SeqSpec) -> dict[str, str]:
    """Outputs that must hold through some specified transition but whose generator moves
    partway: steady while the input is mid-stroke with no memory moved (no static hazard), X
    once the memories the change excites are free to switch (algorithm A). A memory toggles
    before its input finishes the stroke, so such an output moves by the stroke the input had
    left; an AMPLIFIER's bistable toggle (:mod:`mechc.passes.amplify`) keeps it from the
    output. Returns output -> one transition where it happens. Empty when the circuit does not
    settle at power-up (the proof reports that)."""
    sn = SeqNetlist(nl, spec.inputs)
    x0, s0 = initial_total_state(spec)
    st = settle_async(sn.excite(x0), sn.initial(), sn.m)
    if st.overlaps or st.cycle or len(st.finals) != 1:
        return {}
    found: dict[str, str] = {}
    for (x, s, q), changes in _reachable(sn, spec, (x0, s0, st.finals[0])):
        before = output_values(spec, s, x)
        for x2, s2, _res in changes:
            after = output_values(spec, s2, x2)
            t = ternary_transition(sn, x, x2, q)
            for o in spec.outputs:
                net = nl.outputs[o]
                hold = before[o] is not None and before[o] == after[o]
                if hold and o not in found and t["start"][net] != X and t["after_a"][net] == X:
                    found[o] = f"{describe_total(spec, x, s)}, {_moved(spec, x, x2)}"
    return found


def _moved(spec: SeqSpec, x: int, x2: int) -> str:
    k = (x ^ x2).bit_length()
    name = spec.inputs[spec.n - k]
    return f"{name} {'rising' if x2 > x else 'falling'}"


def _ternary(sn, spec, nl, x, x2, q, s, s2, before, after, where, fail, hazards,
             q_end: int) -> None:
    t = ternary_transition(sn, x, x2, q)
    for o in spec.outputs:
        hold = before[o] is not None and before[o] == after[o]
        if hold and t["start"][nl.outputs[o]] == X:
            fail("glitch", f"{o} dips while the input moves ({where}): a static hazard in its "
                           "logic", output=o)
    moving = _moved(spec, x, x2).split()[0]
    for j, net in enumerate(sn.mem_nets):
        sv, rv = sn.sr(t["after_a"], j)
        if sv != 0 and rv != 0:
            hazards.append({
                "kind": "set-reset-together", "memory": net, "input": moving, "where": where,
                "requires": f"SET and RESET of {net} both move when {moving} changes: drive "
                            "them without relative delay (no AMPLIFIER on one path only), or "
                            "one may come on before the other goes off (001 Appendix B.2)"})
    unresolved = [net for net in sn.mem_nets if t["mem_b"][net] == X]
    if unresolved:
        m = sn.m
        switching = [net for j, net in enumerate(sn.mem_nets)
                     if (q ^ q_end) >> (m - 1 - j) & 1] or ["no memory"]
        hazards.append({
            "kind": "essential", "memories": unresolved, "switching": switching,
            "input": moving, "where": where,
            "requires": f"{moving} must finish its stroke before {', '.join(switching)} "
                        f"switch{'es' if len(switching) == 1 else ''}: a memory switching "
                        f"while {moving} is mid-stroke may leave {', '.join(unresolved)} in the "
                        "wrong state (essential hazard)"})


def _group(hazards: list[dict]) -> list[dict]:
    """One entry per requirement, with the transitions that need it."""
    out: dict[tuple, dict] = {}
    for h in hazards:
        key = (h["kind"], h["requires"])
        if key not in out:
            out[key] = {k: v for k, v in h.items() if k != "where"} | {"transitions": []}
        out[key]["transitions"].append(h["where"])
    for h in out.values():
        h["requires"] += f" [{len(h['transitions'])} transition(s), e.g. {h['transitions'][0]}]"
    return list(out.values())


def _report(spec, t0, failures, kinds, hazards, states, transitions, m,
            reached: set | None = None) -> ProofReport:
    count = sum(kinds.values())
    hazards = _group(hazards)
    scope: dict = {"scope": "every specified single-input change from every stable state "
                            "reachable from power-up"}
    if spec.table is not None and reached is not None:
        rows = spec.table.rows
        scope["rows_reached"] = len(reached)
        scope["rows_never_stable"] = [rows[r] for r in range(len(rows)) if r not in reached]
    if transitions == 0:
        scope["note"] = ("no specified input change from power-up: only the power-up state "
                         "was checked")
    return ProofReport(
        level="logic", kind="sequential", passed=count == 0, cases=states,
        coverage={"transitions": transitions, "exhaustive": True},
        failure_count=count, failure_kinds=dict(sorted(kinds.items())), failures=failures,
        figures={"sequential": {"form": spec.form, "stable_states": states,
                                "transitions": transitions, "memories": m, "hazards": hazards,
                                **scope},
                 **LOGIC_FIGURES},
        seconds=round(time.perf_counter() - t0, 6))


# ---- walks for the kinematic and dynamic levels -----------------------------------------------
def transition_tour(spec: SeqSpec, seed: int = 0, random_walks: int = 0,
                    length: int | None = None) -> list[list[dict[str, int]]]:
    """Input sequences from power-up. Each sequence starts with the power-up input vector and
    changes one input per step. The first sequences together take every specified transition
    from every reachable stable state at least once (greedy: an untaken transition from here,
    else the shortest way to one; a new sequence from power-up when none is reachable); then
    ``random_walks`` seeded random walks of ``length`` steps (default twice the number of
    transitions, at least 8)."""
    g = stable_graph(spec)
    x0 = g.initial[0]
    untaken = {(u, i) for u, outs in g.edges.items() for i in range(len(outs))}
    seqs: list[list[int]] = []
    while untaken:
        cur = g.initial
        seq = [x0]
        while True:
            mine = sorted(i for (u, i) in untaken if u == cur)
            if mine:
                untaken.discard((cur, mine[0]))
                x2, cur = g.edges[cur][mine[0]]
                seq.append(x2)
                continue
            path = path_to(g, cur, {u for (u, _i) in untaken})
            if path is None:
                break
            for x2, node in path:
                seq.append(x2)
                cur = node
        if len(seq) == 1:
            break  # nothing reachable is left (cannot happen: every node is reachable)
        seqs.append(seq)
    if not seqs:  # nothing to change from power-up: the power-up state alone
        seqs.append([x0])
    rng = np.random.default_rng(seed)
    steps = length if length is not None else max(8, 2 * g.transitions)
    for _ in range(random_walks):
        cur = g.initial
        seq = [x0]
        for _ in range(steps):
            outs = g.edges.get(cur, [])
            if not outs:
                break
            x2, cur = outs[int(rng.integers(len(outs)))]
            seq.append(x2)
        seqs.append(seq)
    n = spec.n
    return [[{name: (x >> (n - 1 - k)) & 1 for k, name in enumerate(spec.inputs)} for x in s]
            for s in seqs]


@dataclass(frozen=True)
class Piece:
    """Steps ``start + 1 .. end`` of walk ``walk``, run from power-up: ``sequence`` is first the
    shortest specified way from power-up to the walk's stable state at ``start`` (``prefix``
    changes, none where that is the power-up state), then the walk's own input vectors."""

    walk: int
    start: int
    end: int
    prefix: int
    sequence: list[dict[str, int]]


def split_walks(spec: SeqSpec, walks: list[list[dict[str, int]]],
                max_steps: int | None = None) -> list[Piece]:
    """Cut ``walks`` (from power-up, as :func:`transition_tour` gives them) into pieces of at
    most ``max_steps`` changes each, prefix included (default: an eighth of all the walks'
    changes, at least 4; a piece whose way there alone is that long takes one change of its
    walk), so that independent processes share them evenly. A piece may start at any stable
    state of its walk; cuts are chosen for the fewest prefix changes (a return to the power-up
    state costs none), then the fewest pieces. The pieces in order, each
    walk's in walk order; together they take every change of every walk exactly once."""
    g = stable_graph(spec)
    total = sum(len(w) - 1 for w in walks)
    cap = max_steps if max_steps is not None else max(4, -(-total // 8))
    n = spec.n

    def vec(d: dict[str, int]) -> int:
        return sum((int(d[name]) & 1) << (n - 1 - k) for k, name in enumerate(spec.inputs))

    def vectors(xs: list[int]) -> list[dict[str, int]]:
        return [{name: (x >> (n - 1 - k)) & 1 for k, name in enumerate(spec.inputs)}
                for x in xs]

    ways: dict = {g.initial: []}  # stable state -> input columns of the way from power-up
    pieces: list[Piece] = []
    for wi, walk in enumerate(walks):
        nodes = [(x, s) for x, s in _stable_walk(spec, walk)]
        for node in nodes:
            if node not in ways:
                ways[node] = [x2 for x2, _ in path_to(g, g.initial, {node})]
        m = len(walk) - 1
        # best[b]: (prefix changes, pieces) to cover the walk's changes 1..b; cut[b]: the start
        best: list[tuple[int, int]] = [(0, 0)] + [(0, 0)] * m
        cut = [0] * (m + 1)
        for b in range(1, m + 1):
            options = [(best[a][0] + len(ways[nodes[a]]), best[a][1] + 1, -a)
                       for a in range(b) if b - a + len(ways[nodes[a]]) <= cap or a == b - 1]
            c, k, a = min(options)
            best[b], cut[b] = (c, k), -a
        bounds = []
        b = m
        while b > 0:
            bounds.append((cut[b], b))
            b = cut[b]
        if not bounds:  # a walk with no change: the power-up state alone
            bounds = [(0, 0)]
        for a, b in reversed(bounds):
            way = ways[nodes[a]]
            seq = vectors([g.initial[0], *way]) + [dict(v) for v in walk[a + 1:b + 1]]
            pieces.append(Piece(wi, a, b, len(way), seq))
    return pieces


def path_to(g, cur, targets):
    """Shortest input sequence from state ``cur`` to any state of ``targets`` (breadth first
    over the transition graph ``g``), as (input column, state) steps; None if none is
    reachable."""
    has = targets
    prev = {cur: None}
    todo = deque([cur])
    while todo:
        u = todo.popleft()
        if u in has and u != cur:
            path = []
            while prev[u] is not None:
                p, x2 = prev[u]
                path.append((x2, u))
                u = p
            return path[::-1]
        for x2, v in g.edges.get(u, []):
            if v not in prev:
                prev[v] = (u, x2)
                todo.append(v)
    return None


def expected_after(spec: SeqSpec, sequence: list[dict[str, int]]) -> list[dict[str, int | None]]:
    """The spec's outputs at the stable state after each input vector of ``sequence`` (the
    first must be the power-up vector; each next one differs in one input and is specified)."""
    return [output_values(spec, s, x) for x, s in _stable_walk(spec, sequence)]


def expected_states(spec: SeqSpec, sequence: list[dict[str, int]]) -> list[str]:
    """The name of the spec's stable state after each input vector of ``sequence``: the flow
    table's row, or the memories' values ("M1=0 M2=1") of a set/reset spec."""
    out = []
    for _, s in _stable_walk(spec, sequence):
        if spec.table is not None:
            out.append(spec.table.rows[s])
        else:
            m = spec.memory_names
            out.append(" ".join(f"{nm}={(s >> (len(m) - 1 - j)) & 1}"
                                for j, nm in enumerate(m)))
    return out


def _stable_walk(spec: SeqSpec, sequence: list[dict[str, int]]):
    """(inputs, stable state) after each input vector of ``sequence``, from power-up."""
    n = spec.n

    def vec(d: dict[str, int]) -> int:
        return sum((int(d[name]) & 1) << (n - 1 - k) for k, name in enumerate(spec.inputs))

    x, s = initial_total_state(spec)
    if not sequence or vec(sequence[0]) != x:
        raise ValueError(f"a sequence must start at the power-up inputs "
                         f"{bits_text(x, n)}")
    yield x, s
    for d in sequence[1:]:
        x2 = vec(d)
        if x2 not in allowed_changes(spec, s, x):
            raise ValueError(f"{bits_text(x, n)} → {bits_text(x2, n)} is not a specified "
                             f"single-input change from {describe_total(spec, x, s)}")
        s = next_stable(spec, s, x, x2)
        x = x2
        yield x, s
