"""The compiler as a pipeline of plain stages with explicit data between them.

    Spec --minimise--> Equations --map--> Netlist --place--> Layout  => Design

``compile_spec`` runs them in order and times each; every stage can also be called alone.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field

from mechc.layout import Layout, place
from mechc.library import Library, load_library
from mechc.logic.minimise import Equations, MinimiseOptions, minimise
from mechc.netlist.ir import Netlist
from mechc.netlist.mapping import MapOptions, map_equations
from mechc.spec.model import Spec


@dataclass
class CompileOptions:
    minimise: MinimiseOptions = field(default_factory=MinimiseOptions)
    map: MapOptions = field(default_factory=MapOptions)
    cell_dirs: tuple[str, ...] = ()
    timings: bool = False  # record seconds per stage in the JSON (makes output non-reproducible)


@dataclass
class Design:
    """Everything the compiler produced; what the JSON file holds and ``simulate`` reads."""

    spec: Spec
    equations: dict[str, str]
    implemented: dict[str, str]
    netlist: Netlist
    layout: Layout | None
    stats: dict
    seconds: dict[str, float] = field(default_factory=dict)
    eq: Equations | None = None  # the minimiser's full result (not kept in JSON)


def compile_spec(spec: Spec, opts: CompileOptions | None = None,
                 library: Library | None = None,
                 progress: Callable[[str], None] | None = None) -> Design:
    opts = opts or CompileOptions()
    lib = library or load_library(opts.cell_dirs)
    seconds: dict[str, float] = {}

    def stage(name, fn, *args):
        if progress:
            progress(name)
        t0 = time.perf_counter()
        out = fn(*args)
        seconds[name] = time.perf_counter() - t0
        return out

    eq = stage("minimise", minimise, spec, opts.minimise)
    mapped = stage("map", map_equations, eq, lib, opts.map)
    layout = stage("place", place, mapped.netlist)
    stats = design_stats(eq, mapped.netlist, lib, layout)
    return Design(spec, {o: eq.text(o) for o in spec.outputs}, mapped.implemented,
                  mapped.netlist, layout, stats, seconds, eq)


def design_stats(eq: Equations, nl: Netlist, lib: Library, layout: Layout | None) -> dict:
    parts = sum(lib[c.cell].cost(len(c.inputs)) for c in nl.cells.values())
    per_output = {
        o: {"terms": c.terms, "literals": c.literals, "proven": c.proven, "method": c.method}
        for o, c in eq.covers.items()
    }
    return {
        "cells": len(nl.cells),
        "cells_by_type": nl.count_by_type(),
        "parts": parts,
        "terms": eq.terms,
        "literals": eq.literals,
        "shared_terms": eq.shared_terms,
        "depth": max(nl.depth().values(), default=0),
        "crossings": layout.crossings if layout else None,
        "minimisation": {"proven": eq.proven, "verified": "exhaustive",
                         "outputs": per_output},
    }
