"""The compiler as a pipeline of plain stages with explicit data between them.

    Spec --minimise--> Equations --map--> Netlist --place--> Layout
         --synthesise--> Mechanism  => Design

``compile_spec`` runs them in order and times each; every stage can also be called alone.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field

from mechc.cells.library import Library, load_library
from mechc.cells.sources import cell_sources
from mechc.errors import MechcError, UsageError
from mechc.ir.design import Design
from mechc.ir.equations import Equations
from mechc.ir.layout import Layout
from mechc.ir.mechanism import Mechanism
from mechc.ir.netlist import Netlist
from mechc.ir.spec import Spec
from mechc.logic.cubes import MAX_TABLE_INPUTS
from mechc.passes.amplify import (
    amplify_nets,
    nets_overstressed,
    nets_short_of_force,
    plan_force_amplifiers,
    snap_outputs,
)
from mechc.passes.assemble import MechOptions, assemble_mechanism
from mechc.passes.checks import run_design_checks
from mechc.passes.flowtable import SynthOptions, derive_equations, synthesise_table
from mechc.passes.map import MapOptions, Mapped, map_equations, map_sequential
from mechc.passes.minimise import MinimiseOptions, minimise
from mechc.passes.multilevel import equations_blif, map_multilevel_hazard_free
from mechc.passes.ordering import decide_ordering
from mechc.passes.place import place
from mechc.passes.route import interconnect_stats
from mechc.proofs.seq_logic import outputs_needing_snap


@dataclass
class CompileOptions:
    minimise: MinimiseOptions = field(default_factory=MinimiseOptions)
    map: MapOptions = field(default_factory=MapOptions)
    mech: MechOptions = field(default_factory=MechOptions)
    cell_dirs: tuple[str, ...] = ()
    amplify: bool = True  # insert AMPLIFIERs where forces fail or an output must snap
    # "2": sums of products; "multi": multi-level (Yosys/ABC, mapped by parts); "auto": both
    # built and assembled, the one with fewer parts kept (passes/multilevel.py)
    levels: str = "2"
    timings: bool = False  # record seconds per stage in the JSON (makes output non-reproducible)


#: Told when a stage ends: its name and its seconds (the terminal's progress, a benchmark).
OnStageDone = Callable[[str, float], None]


def compile_spec(spec: Spec, opts: CompileOptions | None = None,
                 library: Library | None = None,
                 progress: Callable[[str], None] | None = None,
                 done: OnStageDone | None = None) -> Design:
    """Every stage in order. ``progress`` is told each stage's name as it starts, ``done`` its
    name and seconds as it ends (a stage that runs more than once, as assemble may, is told
    each time; ``Design.seconds`` holds the last)."""
    opts = opts or CompileOptions()
    lib = library or load_library(opts.cell_dirs)
    seconds: dict[str, float] = {}

    def stage(name, fn, *args):
        if progress:
            progress(name)
        t0 = time.perf_counter()
        out = fn(*args)
        seconds[name] = time.perf_counter() - t0
        if done:
            done(name, seconds[name])
        return out

    if getattr(spec, "kind", "") == "fsm":
        return compile_sequential(spec, opts, lib, stage=stage, seconds=seconds)
    if network_only(spec, opts):  # multi-level from the network: no table, no minimise
        eq, mapped = None, None
    else:
        eq = stage("minimise", minimise, spec, opts.minimise)
        mapped = stage("map", map_equations, eq, lib, opts.map)
        if getattr(mapped, "equations", None) is not None:
            eq = mapped.equations  # the mapper built the alternative covers (fewer parts)
    nl, layout, mech, amps, mapped, levels = build_levels(spec, eq, mapped, lib, opts, stage)
    stats = design_stats(eq, nl, lib, layout)
    if levels:
        stats["levels"] = levels
    stats.update(interconnect_stats(mech))
    if getattr(spec, "display", None):
        stats["names"] = dict(spec.display)  # safe identifier -> the spec file's own name
    if amps:
        stats["amplified"] = amps
    equations = ({o: eq.text(o) for o in spec.outputs} if eq is not None else
                 {o: NO_EQUATIONS for o in spec.outputs})
    design = Design(spec, equations, mapped.implemented, nl, layout, stats, seconds, eq, mech)
    design.cell_sources = cell_sources(nl, lib)
    stage("check", run_design_checks, design, lib)
    return design


#: The equation text of an output built from the spec's network with no sum of products.
NO_EQUATIONS = "the spec's network (multi-level, no sum of products)"
#: Structural specs (BLIF, Verilog) with at most this many inputs (those with a truth table)
#: still get the two-level minimise before ``--levels multi``: its hazard-free covers,
#: factored, are a candidate and a hazard fallback. Measured without it: the same designs for
#: the 8-bit adder (546 parts; 45.5 s -> 7.1 s), the generated 8-bit comparator (446) and the
#: ALU (8420), but examples/multilevel/cmp8.v went from 546 parts (the factored covers won) to
#: 772, so only wider specs, which have no table, go from the network alone.
MINIMISE_BEFORE_MULTI_MAX_INPUTS = MAX_TABLE_INPUTS


def network_only(spec: Spec, opts: CompileOptions) -> bool:
    """Whether multi-level synthesis starts from the spec's network alone (no minimise, no
    two-level map). A network-valued spec has no table to minimise, so two levels cannot be
    built for it: asked for, that is an error naming the file (exit 2)."""
    if spec.network is not None:
        if opts.levels == "2" or opts.map.target != "conventional":
            what = ("--levels 2" if opts.levels == "2"
                    else f"--map {opts.map.target} (two-level only)")
            raise UsageError(f"{spec.path}: {spec.n} inputs is more than a truth table takes "
                             f"({MAX_TABLE_INPUTS}), so {what} cannot be built: the design "
                             "is synthesised multi-level from its network (--levels multi)")
        return True
    return (bool(spec.structure) and opts.levels == "multi"
            and spec.n > MINIMISE_BEFORE_MULTI_MAX_INPUTS)


def netlist_parts(nl: Netlist, lib: Library) -> int:
    """Parts of every cell of a netlist (the library cells' ``cost``), amplifiers included."""
    return sum(lib[c.cell].cost(len(c.inputs)) for c in nl.cells.values())


def build_levels(spec: Spec, eq: Equations, mapped, lib: Library, opts: CompileOptions,
                 stage) -> tuple:
    """Place and assemble the two-level mapping, the multi-level one, or (``auto``) both,
    keeping the one with fewer parts after assembly (amplifiers counted; a tie keeps two
    levels). Amplifying only adds cells, so a mapping's parts before assembly are a lower
    bound of its parts after: where the assembled multi-level design already has fewer parts
    than the two-level mapping, the two-level design is not assembled (its count is then that
    bound, and the stats say so). Returns netlist, layout, mechanism, amplified nets, the
    Mapped kept and the ``levels`` stats (which was chosen, both part counts), empty for two
    levels alone."""
    levels = opts.levels
    if levels not in ("2", "multi", "auto"):
        raise ValueError(f"levels must be 2, multi or auto, not {levels!r}")
    if mapped is None:  # network only (network_only): multi-level is the one way to build it
        levels = "multi"
    if opts.map.target != "conventional" and levels == "auto":
        levels = "2"  # threshold mapping is two-level; multi-level maps to AND/OR-family cells
    built: dict[str, tuple] = {}
    info: dict = {}
    ml = None
    if levels in ("multi", "auto"):
        source = "structure" if spec.structure else "sums of products"
        blif = spec.structure or equations_blif(eq)
        try:
            ml = stage("multi-level", map_multilevel_hazard_free, blif, list(spec.inputs),
                       list(spec.outputs), lib, opts.map, opts.minimise,
                       mapped.netlist if mapped is not None else None, opts.map.fan_in, eq)
        except MechcError as e:
            if levels == "multi":
                raise
            ml, info = None, {"failed": str(e)}  # auto: two levels, and the summary says why
    if levels in ("multi", "auto") and ml is not None:
        layout = stage("place", place, ml.netlist)
        built["multi"] = (*stage("assemble", assemble_powered, ml.netlist, lib, opts, layout),
                          Mapped(ml.netlist, ml.implemented))
        info = {"from": source, "method": ml.script, "mapped_parts": ml.parts,
                "tried": ml.tried, "two_level_outputs": ml.two_level_outputs,
                "cured_outputs": ml.cured_outputs}
    parts = {k: netlist_parts(v[0], lib) for k, v in built.items()}
    two_mapped = netlist_parts(mapped.netlist, lib) if mapped is not None else 0
    two_level = "assembled"
    if levels == "auto" and "multi" in parts and parts["multi"] < two_mapped:
        two_level = "mapped only: its parts before amplifiers, a lower bound"
        parts["2"] = two_mapped
    elif levels in ("2", "auto"):
        layout = stage("place", place, mapped.netlist)
        built["2"] = (*stage("assemble", assemble_powered, mapped.netlist, lib, opts, layout),
                      mapped)
        parts["2"] = netlist_parts(built["2"][0], lib)
    chosen = min(built, key=lambda k: (parts[k], k != "2"))
    nl, layout, mech, amps, kept = built[chosen]
    if opts.levels == "2":
        return nl, layout, mech, amps, kept, {}
    if mapped is None:
        two_level = "not built"  # a spec with no table: multi-level is the one way
    return nl, layout, mech, amps, kept, {"asked": opts.levels, "chosen": chosen,
                                           "parts": {k: parts[k] for k in sorted(parts)},
                                           "two_level": two_level, "multi": info}


#: Flow tables with at most this many state variables try every memory polarity.
MAX_POLARITY_SEARCH = 3


def compile_sequential(spec, opts: CompileOptions | None = None, library: Library | None = None,
                       mechanism: bool = True, stage=None, seconds=None) -> Design:
    """A SeqSpec (flow table or set/reset equations): SET/RESET and output equations over
    inputs + memories (flow-table synthesis when a table is given), mapped with MEMORY cells,
    then place, synthesise, check. ``mechanism=False`` stops after placement (all a logic-level
    proof needs)."""
    opts = opts or CompileOptions()
    lib = library or load_library(opts.cell_dirs)
    seconds = {} if seconds is None else seconds

    def _stage(name, fn, *args):
        t0 = time.perf_counter()
        out = fn(*args)
        seconds[name] = time.perf_counter() - t0
        return out

    stage = stage or _stage
    sopts = SynthOptions(opts.minimise, opts.minimise.time_limit)
    se = stage("equations", derive_equations, spec, sopts)

    def build(se):
        mems = [(m, se.set_names[m], se.reset_names[m], se.initial[m]) for m in se.memories]
        return map_sequential(se.eq, list(spec.inputs), mems, list(spec.outputs), lib, opts.map)

    mapped = stage("map", build, se)
    v = len(se.memories)
    if spec.form == "table" and not spec.table.assign and 0 < v <= MAX_POLARITY_SEARCH:
        # which code of a state variable is "on" is free: each choice swaps SET and RESET and
        # the sign of that variable's literals, so it changes inverters, not literals
        def parts(m):
            return sum(lib[c.cell].cost(len(c.inputs)) for c in m.netlist.cells.values())

        def cheapest(se, mapped):
            best = (parts(mapped), 0)
            for pol in range(1, 1 << v):
                se_p = synthesise_table(spec, sopts, polarity=pol)
                mapped_p = build(se_p)
                if (parts(mapped_p), pol) < best:
                    best, se, mapped = (parts(mapped_p), pol), se_p, mapped_p
            return se, mapped

        se, mapped = stage("polarity", cheapest, se, mapped)
    nl, amps = mapped.netlist, {}
    if opts.amplify:
        snaps = stage("snap", outputs_needing_snap, nl, spec)
        if snaps:
            nl = snap_outputs(nl, lib, sorted(snaps))
            amps = {o: f"snap: must hold at {w}, but a MEMORY switches before the input "
                       "ends its stroke" for o, w in snaps.items()}
    layout = stage("place", place, nl)
    equations = {o: se.text(o) for o in spec.outputs}
    for m in se.memories:
        equations[se.set_names[m]] = se.text(se.set_names[m])
        equations[se.reset_names[m]] = se.text(se.reset_names[m])

    def finish(nl: Netlist, layout: Layout | None, amps: dict[str, str]) -> Design:
        mech = None
        amps = dict(amps)
        if mechanism:
            nl, layout, mech, more = stage("assemble", assemble_powered, nl, lib, opts, layout)
            amps.update(more)
        stats = design_stats(se.eq, nl, lib, layout)
        stats["sequential"] = {"memories": len(se.memories), **se.checked}
        if mech is not None:
            stats.update(interconnect_stats(mech))
        if amps:
            stats["amplified"] = amps
        design = Design(spec, equations, mapped.implemented, nl, layout, stats, seconds,
                        se.eq, mech, se)
        design.cell_sources = cell_sources(nl, lib)
        if mechanism:
            stage("check", run_design_checks, design, lib)
        return design

    design = finish(nl, layout, amps)
    if mechanism:
        # every ordering requirement decided on the built design, cured where it is not met
        design = stage("ordering", decide_ordering, design, lib,
                       lambda nl2, why: finish(nl2, None, {**amps, **why}) if opts.amplify
                       else None)
    return design


#: Rounds of "synthesise, amplify the nets whose forces fail" before giving up.
MAX_AMPLIFY_ROUNDS = 6  # a deep chain is relieved one level of amplifiers a round


def assemble_powered(nl: Netlist, lib: Library, opts: CompileOptions,
                       layout: Layout | None = None
                       ) -> tuple[Netlist, Layout, Mechanism, dict[str, str]]:
    """Place and synthesise; where the force budget fails (an input actuator overloaded, a
    MEMORY loop whose demand grows every time round), put those nets' loads behind AMPLIFIERs
    and synthesise again. Returns the (possibly amplified) netlist, its layout and mechanism,
    and net -> reason for every net amplified."""
    amps: dict[str, str] = {}
    if opts.amplify and not nl.state_nets():
        # combinational: amplifiers where the force budget needs them, in one sweep back from
        # the outputs; the rounds below only mend what the assembled checks still find
        planned, groups = plan_force_amplifiers(nl, lib, opts.mech)
        if planned:
            amps.update(planned)
            nl = amplify_nets(nl, lib, planned, groups=groups)
            layout = None
    for attempt in range(MAX_AMPLIFY_ROUNDS + 1):
        if layout is None or attempt:
            layout = place(nl)
        mech = assemble_mechanism(nl, layout, lib, opts.mech)
        if not opts.amplify or attempt == MAX_AMPLIFY_ROUNDS:
            break
        short = nets_short_of_force(nl, mech, lib) or nets_overstressed(nl, mech)
        if not short:
            break
        amps.update(short)
        nl = amplify_nets(nl, lib, short)
    return nl, layout, mech, amps


def compile_netlist(spec: Spec, netlist: Netlist, opts: CompileOptions | None = None,
                    library: Library | None = None) -> Design:
    """The back half of the pipeline for a netlist given by hand (a single cell under test, a
    circuit drawn from a figure): place, synthesise, check."""
    opts = opts or CompileOptions()
    lib = library or load_library(opts.cell_dirs)
    netlist.check()
    layout = place(netlist)
    mech = assemble_mechanism(netlist, layout, lib, opts.mech)
    stats = {"cells": len(netlist.cells), "cells_by_type": netlist.count_by_type(),
             **interconnect_stats(mech)}
    design = Design(spec, {}, {}, netlist, layout, stats, {}, None, mech)
    design.cell_sources = cell_sources(netlist, lib)
    run_design_checks(design, lib)
    return design


def design_stats(eq: Equations | None, nl: Netlist, lib: Library,
                 layout: Layout | None) -> dict:
    parts = sum(lib[c.cell].cost(len(c.inputs)) for c in nl.cells.values())
    if eq is None:  # built from the spec's network: no sums of products to count
        return {"cells": len(nl.cells), "cells_by_type": nl.count_by_type(), "parts": parts,
                "literals": None, "depth": max(nl.depth().values(), default=0),
                "crossings": layout.crossings if layout else None,
                "minimisation": {"skipped": "multi-level synthesis from the spec's network",
                                 "proven": False, "time_limited": [], "outputs": {}}}
    per_output = {
        o: {"terms": c.terms, "literals": c.literals, "proven": c.proven, "method": c.method}
        for o, c in eq.covers.items()
    }
    return {
        "cells": len(nl.cells),
        "cells_by_type": nl.count_by_type(),
        "parts": parts,
        "terms": eq.terms,
        "products": eq.products,
        "literals": eq.literals,
        "shared_terms": eq.shared_terms,
        "depth": max(nl.depth().values(), default=0),
        "crossings": layout.crossings if layout else None,
        "minimisation": {"proven": eq.proven,
                         "verified": "exhaustive" if all(c.method != "espresso" for c in
                                                         eq.covers.values())
                         else "exact on cubes",
                         "time_limited": list(eq.time_limited),
                         "outputs": per_output},
    }
