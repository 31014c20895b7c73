"""The map pass: minimised equations -> a netlist of library cells (``Equations -> Netlist``).

It chooses the target: sums of products onto AND/OR/NOT-family cells (:mod:`map_sop`), or
threshold generators where they cost fewer parts (:mod:`threshold_map`); a sequential spec's
SET/RESET equations are mapped the same way and closed through MEMORY cells."""

from __future__ import annotations

from mechc.cells.library import Library
from mechc.ir.equations import Equations
from mechc.ir.netlist import CellInst, Netlist
from mechc.passes.map_sop import MapOptions, Mapped, map_sop
from mechc.passes.threshold_map import map_threshold

__all__ = ["MapOptions", "Mapped", "map_equations", "map_sequential"]


def map_equations(eq: Equations, library: Library, opts: MapOptions | None = None) -> Mapped:
    opts = opts or MapOptions()
    if opts.target != "conventional":
        return map_threshold(eq, library, opts)
    return map_sop(eq, library, opts)


def map_sequential(eq: Equations, inputs: list[str], memories: list[tuple[str, str, str, int]],
                   outputs: list[str], library: Library,
                   opts: MapOptions | None = None) -> Mapped:
    """SET/RESET/output equations over inputs + memory variables -> one netlist with MEMORY
    cells. ``memories``: (name, SET function, RESET function, initial) with the functions named
    among ``eq.outputs``. The combinational mapper builds every function with the memory
    variables as if they were inputs; each variable then becomes the Q net of a MEMORY cell
    (inputs [S, R], params.initial) fed by its SET and RESET nets, which closes the feedback."""
    comb = map_equations(eq, library, opts)
    src = comb.netlist
    mem_cls = library.for_type("MEMORY", 2)
    if mem_cls is None:
        raise library.no_cell_error("MEMORY")
    nl = Netlist(inputs)
    for c in src.topo_cells():
        cls = library[c.cell]
        nl.add_cell(c, pin_names=cls.input_names(len(c.inputs)), out_pins=list(cls.outputs))
    n_cells = len(src.cells)
    for j, (name, s_fn, r_fn, initial) in enumerate(memories):
        cell = CellInst(f"c{n_cells + j + 1}", mem_cls.name, "MEMORY",
                        (src.outputs[s_fn], src.outputs[r_fn]), (name,),
                        {"initial": int(initial)})
        nl.add_cell(cell, pin_names=mem_cls.input_names(2), out_pins=list(mem_cls.outputs))
    for o in outputs:
        nl.set_output(o, src.outputs[o])
    nl.check()
    return Mapped(nl, dict(comb.implemented))
