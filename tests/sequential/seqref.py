"""Independent references for the sequential tests.

Nothing here calls mechc's synthesis or simulator: equations are read back from their printed
text with sympy, memories switch in every order by a plain breadth-first search, and merged-row
covers are found by trying every collection of row sets.
"""

from __future__ import annotations

import itertools

import networkx as nx
import sympy


def compile_text(text: str, names: list[str]):
    """A function env -> 0/1 from an equation printed by mechc (``~ & | ^``), via sympy."""
    syms = {n: sympy.Symbol(n) for n in names}
    e = sympy.parse_expr(text, local_dict=syms)
    memo: dict[tuple, int] = {}

    def run(env: dict[str, int]) -> int:
        key = tuple(int(env[n]) for n in names)
        if key not in memo:
            v = e.xreplace({syms[n]: sympy.true if b else sympy.false
                            for n, b in zip(names, key)})
            memo[key] = int(bool(v))  # BooleanTrue, or the constant 1
        return memo[key]

    return run


class EquationMachine:
    """SET/RESET/output equations of a compiled sequential design (from its JSON section)."""

    def __init__(self, inputs: list[str], sequential: dict):
        self.inputs = list(inputs)
        self.mem = [m["name"] for m in sequential["memories"]]
        names = self.inputs + self.mem
        self.S = [compile_text(m["set"], names) for m in sequential["memories"]]
        self.R = [compile_text(m["reset"], names) for m in sequential["memories"]]
        self.Z = {o: compile_text(t, names) for o, t in sequential["outputs"].items()}
        self.initial = tuple(m["initial"] for m in sequential["memories"])

    def env(self, x: tuple[int, ...], q: tuple[int, ...]) -> dict[str, int]:
        return dict(zip(self.inputs, x)) | dict(zip(self.mem, q))

    def outputs(self, x, q) -> dict[str, int]:
        e = self.env(x, q)
        return {o: f(e) for o, f in self.Z.items()}

    def settle(self, x, q) -> tuple[list[tuple[int, ...]], bool, bool]:
        """(stable end states, S·R overlap seen, may oscillate) over every switching order."""
        g = nx.DiGraph()
        g.add_node(q)
        todo, seen, finals, overlap = [q], {q}, [], False
        while todo:
            cur = todo.pop()
            e = self.env(x, cur)
            excited = []
            for j in range(len(self.mem)):
                s, r = self.S[j](e), self.R[j](e)
                overlap |= bool(s and r)
                nxt = 1 if s else (0 if r else cur[j])
                if nxt != cur[j]:
                    excited.append(j)
            if not excited:
                finals.append(cur)
                continue
            for k in range(1, len(excited) + 1):
                for sub in itertools.combinations(excited, k):
                    nq = tuple(1 - v if j in sub else v for j, v in enumerate(cur))
                    g.add_edge(cur, nq)
                    if nq not in seen:
                        seen.add(nq)
                        todo.append(nq)
        return sorted(set(finals)), overlap, not nx.is_directed_acyclic_graph(g)


def bits(v: int, n: int) -> tuple[int, ...]:
    return tuple((v >> (n - 1 - k)) & 1 for k in range(n))


def table_dest(ft, r: int, k: int):
    """Destination of an entry, following chains (plain loop, no mechc helper)."""
    cur = ft.next[r][k]
    for _ in range(len(ft.rows) + 1):
        if cur is None or ft.next[cur][k] == cur:
            return cur
        cur = ft.next[cur][k]
    raise AssertionError("oscillating table")


def valid_reduction(ft, classes: list[frozenset[int]]) -> bool:
    """Rows merged into these (possibly overlapping) classes behave like the table: every row
    in some class; in each class, rows stable in a column agree on their outputs; and the
    destinations of a class in a column all lie in one class."""
    if set().union(*classes) != set(range(len(ft.rows))):
        return False
    for c in classes:
        for k in range(len(ft.columns)):
            outs = [ft.out[r] for r in c if ft.next[r][k] == r]
            for a, b in itertools.combinations(outs, 2):
                if any(x is not None and y is not None and x != y for x, y in zip(a, b)):
                    return False
            dests = {d for r in c if (d := table_dest(ft, r, k)) is not None}
            if dests and not any(dests <= d for d in classes):
                return False
    return True


def min_reduction_size(ft) -> int:
    """Fewest classes of a valid reduction, by trying every collection of row sets."""
    N = len(ft.rows)
    subsets = [frozenset(s) for k in range(1, N + 1) for s in itertools.combinations(range(N), k)]
    for size in range(1, N + 1):
        for combo in itertools.combinations(subsets, size):
            if valid_reduction(ft, list(combo)):
                return size
    return N


def min_race_free_width(next_: list[list[int | None]], C: int, limit: int = 4) -> int:
    """Fewest state variables giving C merged rows codes whose transitions never share a code
    with another transition of the same column going elsewhere (single transition time)."""
    K = len(next_[0]) if next_ else 0
    for v in range(max(0, (C - 1).bit_length()), limit + 1):
        for codes in itertools.permutations(range(1 << v), C):
            ok = True
            for k in range(K):
                owner: dict[int, int] = {}
                for c in range(C):
                    d = next_[c][k]
                    if d is None:
                        continue
                    a, b = codes[c], codes[d]
                    diff = a ^ b
                    for q in range(1 << v):
                        if (q & ~diff) == (a & ~diff):
                            if owner.setdefault(q, d) != d:
                                ok = False
                                break
                    if not ok:
                        break
                if not ok:
                    break
            if ok:
                return v
    return limit + 1


def random_reduced_table(rng, C: int, inputs: int = 2, p: float = 0.9):
    """A random table of C states that are kept apart (each its own row): every column has
    some stable states, and each other state goes to one of them with probability p."""
    from mechc.ir.seqspec import FlowTable

    K = 1 << inputs
    nxt = [[None] * K for _ in range(C)]
    for k in range(K):
        stable = [int(s) for s in rng.choice(C, size=int(rng.integers(1, C)), replace=False)]
        for r in range(C):
            if r in stable:
                nxt[r][k] = r
            elif rng.random() < p:
                nxt[r][k] = int(rng.choice(stable))
    for r in range(C):  # every row needs a stable entry
        if not any(nxt[r][k] == r for k in range(K)):
            k = int(rng.integers(K))
            for s in range(C):  # others going there in column k now go to r
                if nxt[s][k] is not None and nxt[s][k] != s:
                    nxt[s][k] = r
            nxt[r][k] = r
    width = max(1, (C - 1).bit_length())
    out = [[(r >> j) & 1 for j in range(width)] for r in range(C)]
    return FlowTable([f"x{i}" for i in range(inputs)], [f"z{j}" for j in range(width)],
                     [i ^ (i >> 1) for i in range(K)], [f"s{r}" for r in range(C)], nxt, out)


def visited_rows(ft) -> set[int]:
    """Rows a table can be in from power-up (stable, or passed through on a chain of unstable
    entries), by a plain search over stable total states; the power-up column is the one the
    table names, else the initial row's first stable column."""
    n = len(ft.inputs)
    k0 = ft.initial_column if ft.initial_column is not None else next(
        k for k in range(len(ft.columns)) if ft.next[ft.initial][k] == ft.initial)
    seen, todo, rows = {(k0, ft.initial)}, [(k0, ft.initial)], {ft.initial}
    while todo:
        k, r = todo.pop()
        for i in range(n):
            x2 = ft.columns[k] ^ (1 << (n - 1 - i))
            if x2 not in ft.columns:
                continue
            k2 = ft.columns.index(x2)
            cur = ft.next[r][k2]
            while cur is not None:
                rows.add(cur)
                if ft.next[cur][k2] == cur:
                    break
                cur = ft.next[cur][k2]
            if cur is not None and (k2, cur) not in seen:
                seen.add((k2, cur))
                todo.append((k2, cur))
    return rows


def chain_rows(ft, r: int, k: int) -> list[int]:
    """Rows an entry passes through to its stable row ([] for '-')."""
    out, cur = [], ft.next[r][k]
    while cur is not None and len(out) <= len(ft.rows):
        out.append(cur)
        if ft.next[cur][k] == cur:
            break
        cur = ft.next[cur][k]
    return out
