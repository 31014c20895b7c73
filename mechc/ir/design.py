"""The compiled design: everything the pipeline produced, what the JSON file holds and every
proof reads."""

from __future__ import annotations

from dataclasses import dataclass, field

from mechc.ir.equations import Equations
from mechc.ir.layout import Layout
from mechc.ir.mechanism import Mechanism
from mechc.ir.netlist import Netlist
from mechc.ir.spec import Spec


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
    mechanism: Mechanism | None = None
    sequential: object | None = None  # SeqEquations of a sequential spec (mechc.passes.flowtable)
    cell_sources: dict = field(default_factory=dict)  # cell -> source (mechc.cells.sources)
