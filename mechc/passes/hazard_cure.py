"""Local cures for static hazards of a multi-level network (``Netlist -> Netlist``).

ABC's networks are small but not hazard-free: where one input reaches an output along paths
that meet again (the ALU's select lines reach every bit's propagate, generate and carry at
once), the output can move partway and back while that input travels. Rebuilding such an
output from its whole hazard-free cover costs thousands of parts on the ALU. Here the network
is kept and only its hazardous changes are cured, each by a cube that holds the output through
the change:

    F' = N · ¬(T0_1 + T0_2 + ...) + (T1_1 + T1_2 + ...)

where N is the network's output, every T1 an implicant of F that contains both ends of a
static-1 change N glitches on (it is 1 throughout, its literals do not move), and every T0 an
implicant of ¬F likewise for a static-0 change. F' is F. In ternary logic a product of stable
literals is stable, AND and OR with a stable controlling value are stable, and the factored
sums of the cubes behave as the sums (Kleene's algebra is distributive), so F' is free of
static hazards on every single-input change: on a change N glitches on, a cube holds the
output; on any other, N holds it and the cubes do not disturb it (a T1 is 0 where F stays 0,
a T0 is 0 where F stays 1). The cubes are chosen greedily, each expanded to a prime implicant
dropping first the literal whose removal covers most of the changes still uncured. The result
is checked by the ternary simulation (:mod:`ternary`) by the caller, as every candidate is.
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np

from mechc.cells.library import Library
from mechc.ir.netlist import Netlist
from mechc.logic.cubes import Cube, input_matrix
from mechc.passes.factor import factored_sum
from mechc.passes.hazard_sat import Implicants, MovingInput, prime_around
from mechc.passes.map_sop import Key, MapOptions, Planner, _materialise
from mechc.passes.ternary import MAX_EXHAUSTIVE_INPUTS, hazard_transitions

#: A cure by SAT gives up (None) past this many cubes for one output.
MAX_SAT_CUBES = 4096
#: From this many inputs the cure finds its changes and cubes by SAT instead of enumerating.
#: Measured on ABC's mappings: 8-bit adder (16 inputs) 20.4 s enumerated against 0.93 s by
#: SAT, the same 323 cells; ALU (14 inputs) 4.5 s and 1227 cells enumerated against 5.0 s and
#: 1424 cells by SAT (the enumeration's greedy cubes see every change at once).
SAT_CURE_MIN_INPUTS = 15


def netlist_keys(nl: Netlist) -> dict[str, Key]:
    """Net -> the mapper's structural key of the cells driving it (inputs ``("in", name)``),
    so a netlist can be extended with the mapper's planner and built again."""
    keys: dict[str, Key] = {x: ("in", x) for x in nl.inputs}
    for c in nl.topo_cells():
        key = (("CONST", int(c.params["value"])) if c.type == "CONST"
               else (c.type, tuple(keys[n] for n in c.inputs)))
        for net in c.outputs:
            keys[net] = key
    return keys


def cover_changes(on: np.ndarray, moves: np.ndarray, starts: np.ndarray, n: int) -> list[Cube]:
    """Cubes inside the on-set ``on`` (a truth table over minterms, input 0 the most
    significant bit) such that each change (bit ``moves[i]`` rising from minterm ``starts[i]``)
    lies inside one of them with its moving input free; greedy, each cube a prime."""
    rows = np.arange(1 << n, dtype=np.int64)
    full = (1 << n) - 1
    todo = np.ones(len(starts), dtype=bool)
    cubes: list[tuple[Cube, np.ndarray]] = []
    while todo.any():
        i = int(np.flatnonzero(todo)[0])
        mask = full & ~int(moves[i])
        value = int(starts[i]) & mask
        while True:
            best = None
            for b in range(n):
                bit = 1 << b
                if not mask & bit:
                    continue
                m2, v2 = mask & ~bit, value & ~bit
                if not on[(rows & m2) == v2].all():
                    continue
                gain = int(np.count_nonzero(todo & ((moves & m2) == 0)
                                            & ((starts & m2) == v2)))
                if best is None or gain > best[0]:
                    best = (gain, m2, v2)
            if best is None:
                break
            _, mask, value = best
        covered = ((moves & mask) == 0) & ((starts & mask) == value)
        cubes.append((Cube(mask, value), covered))
        todo &= ~covered
    # irredundant: drop a cube whose changes the others all cover (last chosen first)
    keep = list(range(len(cubes)))
    for j in reversed(range(len(cubes))):
        rest = np.zeros(len(starts), dtype=bool)
        for k in keep:
            if k != j:
                rest |= cubes[k][1]
        if rest.all():
            keep.remove(j)
    return [cubes[k][0] for k in keep]


def cure_hazards(nl: Netlist, outputs: list[str], library: Library,
                 opts: MapOptions, method: str = "auto") -> Netlist | None:
    """``nl`` with each named output's static hazards cured by cubes (module docstring); None
    where a cure would need more than :data:`MAX_SAT_CUBES` cubes for one output. The changes
    and cubes come from the enumeration of every vector (``method`` "enumerate") or from SAT
    ("sat": :mod:`hazard_sat`, no enumeration, any width); "auto" enumerates below
    :data:`SAT_CURE_MIN_INPUTS` inputs. The outputs are cured in the order of their depth, and
    a cured output also replaces its net wherever the network uses it (by SAT: in the outputs
    not cured themselves, the network built once): an equivalent net that is X on fewer
    changes (ternary simulation is monotone, so what depends on it can only glitch less, and
    the AND of cured bits needs fewer cubes)."""
    n = len(nl.inputs)
    if method == "auto":
        method = "enumerate" if n < SAT_CURE_MIN_INPUTS else "sat"
    if method == "enumerate" and n > MAX_EXHAUSTIVE_INPUTS:
        return None
    bits = input_matrix(n) if method == "enumerate" else None
    pl = Planner(library, opts.fan_in, tuple(opts.prefer))
    depth = nl.depth()
    order = sorted((o for o in outputs if nl.outputs[o] in nl.driver
                    and nl.driver[nl.outputs[o]][0] in nl.cells),
                   key=lambda o: (depth[nl.driver[nl.outputs[o]][0]], o))
    if bits is None:
        return _cure_all_by_sat(nl, order, pl, library, opts)
    for o in order:
        keys = netlist_keys(nl)
        old = keys[nl.outputs[o]]
        if old[0] in ("in", "CONST"):
            continue
        found = hazard_transitions(nl).get(o)
        if not found:
            continue
        f = nl.evaluate({x: bits[i] for i, x in enumerate(nl.inputs)})[nl.outputs[o]]
        new = _cured(pl, old, f, found, list(nl.inputs))
        memo: dict[Key, Key] = {old: new}
        roots = {p: (new if p == o else _subst(keys[net], memo))
                 for p, net in nl.outputs.items()}
        nl = _materialise(roots, SimpleNamespace(inputs=list(nl.inputs)), library,
                          tuple(opts.prefer))
    return nl


def _cure_all_by_sat(nl: Netlist, order: list[str], pl: Planner, library: Library,
                     opts: MapOptions) -> Netlist | None:
    """Every named output's cubes found by SAT on the network as given, and the network built
    once: a cured output keeps its own cone, every other output has the cured nets put in
    for the old ones (equivalent, X on fewer changes, so it glitches no more than before).
    Rebuilding after each output, as the enumerated cure does, was most of the 32-bit adder's
    time."""
    keys = netlist_keys(nl)
    cured: dict[str, Key] = {}
    memo: dict[Key, Key] = {}
    for o in order:
        old = keys[nl.outputs[o]]
        if old[0] in ("in", "CONST"):
            continue
        cubes = sat_cubes(nl, o)
        if cubes is None:
            return None
        if cubes[0] or cubes[1]:
            cured[o] = memo[old] = _cured_by_cubes(pl, old, cubes, list(nl.inputs))
    if not cured:
        return nl
    roots = {p: cured.get(p) or _subst(keys[net], memo) for p, net in nl.outputs.items()}
    return _materialise(roots, SimpleNamespace(inputs=list(nl.inputs)), library,
                        tuple(opts.prefer))


def sat_cubes(nl: Netlist, output: str) -> dict[int, list[list[tuple[int, int]]]] | None:
    """The cubes that cure one output's static hazards, found by SAT with no enumeration: for
    each moving input, ask for a hazardous change no cube holds yet, take a prime implicant of
    the output (of its complement for a static-0 change) around it, exclude the changes that
    cube holds, repeat until the solver finds none. Value (0 or 1) -> cubes as literals
    (input, value); None past :data:`MAX_SAT_CUBES` cubes."""
    imp = Implicants(nl, output)
    cubes: dict[int, list[list[tuple[int, int]]]] = {0: [], 1: []}
    try:
        for k in range(len(nl.inputs)):
            finder = MovingInput(nl, k, [output])
            try:
                for cube in cubes[0] + cubes[1]:
                    finder.exclude_cube(cube)
                while (ch := finder.next(output)) is not None:
                    if len(cubes[0]) + len(cubes[1]) >= MAX_SAT_CUBES:
                        return None
                    cube = prime_around(imp, ch)
                    cubes[ch.value].append(cube)
                    finder.exclude_cube(cube)
            finally:
                finder.close()
    finally:
        imp.close()
    return cubes


def _cured_by_cubes(pl: Planner, key: Key, cubes: dict[int, list[list[tuple[int, int]]]],
                    inputs: list[str]) -> Key:
    """``key`` AND-NOT the static-0 cubes, OR the static-1 cubes (factored)."""
    for want in (0, 1):
        if not cubes[want]:
            continue
        term = factored_sum(pl, [frozenset(c) for c in cubes[want]], inputs)
        key = pl.or_([key, term], []) if want else pl.gate("AND_NOT", [key, term])
    return key


def _cured(pl: Planner, key: Key, f: np.ndarray, found: list[tuple[int, np.ndarray]],
           inputs: list[str]) -> Key:
    """``key`` (truth table ``f``) with the changes ``found`` cured: AND-NOT the cubes of
    the static-0 ones, OR the cubes of the static-1 ones."""
    n = len(inputs)
    minterm = (1 << np.arange(n - 1, -1, -1, dtype=np.int64))
    moves, starts = [], []
    for k, vecs in found:
        m = minterm @ vecs.astype(np.int64)
        moves.append(np.full(len(m), 1 << (n - 1 - k), dtype=np.int64))
        starts.append(m)
    mv, st = np.concatenate(moves), np.concatenate(starts)
    high = f[st]
    for want, on in ((False, ~f), (True, f)):
        sel = high == want
        if not sel.any():
            continue
        cubes = cover_changes(on, mv[sel], st[sel], n)
        term = factored_sum(pl, [frozenset(c.literal_list(n)) for c in cubes], inputs)
        key = pl.or_([key, term], []) if want else pl.gate("AND_NOT", [key, term])
    return key


def _subst(key: Key, memo: dict[Key, Key]) -> Key:
    """``key`` with every sub-structure in ``memo`` replaced (iteratively: chains are deep)."""
    stack = [key]
    while stack:
        k = stack[-1]
        if k in memo:
            stack.pop()
            continue
        if k[0] in ("in", "CONST"):
            memo[k] = k
            stack.pop()
            continue
        todo = [c for c in k[1] if c not in memo]
        if todo:
            stack.extend(todo)
            continue
        stack.pop()
        memo[k] = (k[0], tuple(memo[c] for c in k[1]))
    return memo[key]
