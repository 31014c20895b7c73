"""Algebraic factoring of the hazard-free sums of products (``Equations -> Netlist``).

Where a multi-level network glitches (a static hazard ABC's restructuring introduced), the
output is rebuilt from its hazard-free cover. Built flat, that cover is a wide OR of wide ANDs;
factored by the distributive law alone (``a·b + a·c = a·(b + c)``), it keeps its hazard
freedom — the associative, distributive and De Morgan laws preserve static hazards, Boolean
simplifications such as ``x·x̄ = 0`` do not — and needs far fewer parts. The factoring is the
quick one: take out the literal shared by the most cubes, factor what it multiplies and what
is left, repeat. Structures are hash-consed with the two-level mapper's planner, so equal
factors of different outputs are built once.
"""

from __future__ import annotations

from collections import Counter

from mechc.cells.library import Library
from mechc.ir.equations import Cover, Equations
from mechc.ir.netlist import Netlist
from mechc.passes.map_sop import Key, MapOptions, Planner, _materialise

Lit = tuple[int, int]  # (input index, value)


def factored_netlist(eq: Equations, library: Library, opts: MapOptions) -> Netlist:
    """Every output from its hazard-free cover (or that of its complement, inverted, where it
    costs fewer parts), factored."""
    pl = Planner(library, opts.fan_in, tuple(opts.prefer))
    built: set = set()
    roots: dict[str, Key] = {}
    for name in eq.outputs:
        cover = eq.hazard_free.get(name, eq.covers[name])
        cands = [_factor_cover(pl, cover, eq.inputs, False)]
        comp = eq.hazard_free_complements.get(name, eq.complements.get(name))
        if comp is not None:
            cands.append(_factor_cover(pl, comp, eq.inputs, True))
        best = min(cands, key=lambda k: pl.cost(k, set(built)))
        pl.cost(best, built)
        roots[name] = best
    return _materialise(roots, eq, library, tuple(opts.prefer))


def _factor_cover(pl: Planner, cover: Cover, inputs: list[str], invert: bool) -> Key:
    n = len(inputs)
    cubes = [frozenset(c.literal_list(n)) for c in cover.cubes]
    key = factored_sum(pl, cubes, inputs)
    if invert:
        if key[0] == "CONST":
            return ("CONST", 1 - key[1])
        return pl.gate("NOT", [key])
    return key


def factored_sum(pl: Planner, cubes: list[frozenset[Lit]], inputs: list[str]) -> Key:
    """The OR of the cubes, factored."""
    if not cubes:
        return ("CONST", 0)
    if any(not c for c in cubes):
        return ("CONST", 1)
    P: list[Key] = []
    N: list[Key] = []
    rest = list(cubes)
    while rest:
        counts = Counter(lit for c in rest for lit in c)
        lit, count = max(counts.items(), key=lambda kv: (kv[1], -kv[0][0], kv[0][1]))
        if count < 2:
            for c in rest:
                if len(c) == 1 and not next(iter(c))[1]:
                    N.append(("in", inputs[next(iter(c))[0]]))
                else:
                    P.append(_product(pl, c, inputs))
            break
        inner = [c - {lit} for c in rest if lit in c]
        rest = [c for c in rest if lit not in c]
        q = factored_sum(pl, inner, inputs)
        var = ("in", inputs[lit[0]])
        if q == ("CONST", 1):
            if lit[1]:
                P.append(var)
            else:
                N.append(var)
        elif lit[1]:
            P.append(pl.and_([var, q], []))
        else:
            P.append(pl.and_([q], [var]))
    return pl.or_(P, N)


def _product(pl: Planner, cube: frozenset[Lit], inputs: list[str]) -> Key:
    pos = [("in", inputs[k]) for k, v in sorted(cube) if v]
    neg = [("in", inputs[k]) for k, v in sorted(cube) if not v]
    return pl.and_(pos, neg)
