"""Prove a user cell on its own: does its mechanism compute the logic type it declares?

A standard cell is proven by the test suite; a cell from a user's file is not, and a cell that
claims XOR but is built as an OR would otherwise compile cleanly and only fail in ``simulate``.
So every compile proves each user cell it uses once, alone: a one-cell netlist (input sliders,
the cell, the output) through :func:`mechc.pipeline.compile_netlist` and the kinematic proof
against the cell's logic type. A wrong output at rest, or an output that does not dwell while
one input moves, becomes a failed design check naming the cell and the input state; a cell
that passes adds one passing check. Results are cached for the process by the cell file's
content hash, its name, fan-in, parameters and the stroke.
"""

from __future__ import annotations

from mechc.cells.cell import Cell
from mechc.cells.library import Library
from mechc.ir.check import Check
from mechc.ir.design import Design
from mechc.ir.logic_types import evaluate_type, table_rows
from mechc.ir.netlist import CellInst, Netlist

#: Failures listed as checks per cell (the count is in the last one).
MAX_LISTED = 4
TOLERANCE = 0.05  # fraction of stroke, as ``mechc simulate --level kinematic`` by default
#: Logic types a cell cannot be proven alone against: stateful, or without inputs.
UNPROVABLE = frozenset({"MEMORY", "CONST"})

_PROVEN: dict[tuple, list[Check] | None] = {}


def user_cell_checks(design: Design, lib: Library) -> list[Check]:
    """One proof per distinct user cell (and fan-in, parameters) the design places."""
    out: list[Check] = []
    done: set[tuple] = set()
    stroke = design.mechanism.ctx.stroke
    for c in design.netlist.topo_cells():
        cls = lib[c.cell]
        if cls.standard or cls.stateful or c.type in UNPROVABLE:
            continue
        key = (cls.name, cls.source_sha256, c.type, len(c.inputs), repr(sorted(c.params.items())),
               stroke)
        if key not in done:
            done.add(key)
            out += prove_cell(cls, lib, c.type, len(c.inputs), dict(c.params), stroke, key)
    return out


def alone(cls: type[Cell], lib: Library, type_name: str, n: int, params: dict,
          stroke: float) -> tuple[Design, list]:
    """The one-cell design (input sliders ``i0``.., the cell, output ``z``) as a cell is
    proven and characterised alone, and the cell type's truth table over its inputs."""
    # the pipeline sits above the cell layer (it imports this package): imported when used
    from mechc.frontends.boolfile import parse_bool
    from mechc.passes.assemble import MechOptions
    from mechc.pipeline import CompileOptions, compile_netlist

    nets = [f"i{k}" for k in range(n)]
    table = evaluate_type(type_name, table_rows(n), params, 1 << n)
    on = [str(r) for r in range(1 << n) if table[r]]
    spec = parse_bool(f"inputs {' '.join(nets)}\noutputs z\n"
                      + (f"z = minterms({', '.join(on)})\n" if on else "z = 0\n"),
                      f"<cell {cls.name}>")
    nl = Netlist(nets)
    nl.add_cell(CellInst("c1", cls.name, type_name, tuple(nets), ("z",), params),
                pin_names=cls.input_names(n), out_pins=list(cls.outputs))
    nl.set_output("z", "z")
    return compile_netlist(spec, nl, CompileOptions(mech=MechOptions(stroke=stroke)), lib), table


def prove_cell(cls: type[Cell], lib: Library, type_name: str, n: int, params: dict,
               stroke: float, key: tuple | None = None) -> list[Check]:
    """The checks of one cell proven alone (cached; [] while its own proof is running, for the
    one-cell design's design checks come back here)."""
    from mechc.proofs import ProofSettings, prove  # the pipeline imports this module's users

    key = key or (cls.name, cls.source_sha256, type_name, n, repr(sorted(params.items())), stroke)
    if key in _PROVEN:
        return list(_PROVEN[key] or [])
    _PROVEN[key] = None
    pins = cls.input_names(n)
    try:
        design, _ = alone(cls, lib, type_name, n, params, stroke)
        report = prove(design, design.spec, lib, "kinematic", ProofSettings(tolerance=TOLERANCE))
    except BaseException:
        del _PROVEN[key]
        raise
    where = f"user cell {cls.name} ({cls.source})"
    name = f"computes its type {type_name} (proven alone, kinematic)"

    def state(inputs: dict) -> str:
        return " ".join(f"{pins[int(k[1:])]}={v}" for k, v in inputs.items())

    wrong = [f for f in report.failures if f["kind"] in ("rest", "dwell")]
    checks: list[Check] = []
    for f in wrong[:MAX_LISTED]:
        if f["kind"] == "rest":
            checks.append(Check(name, f"{where}, inputs {state(f['inputs'])} (output should be "
                                f"{f['expected']})", _dev(f["deviation_fraction"]), TOLERANCE, "<=",
                                "of stroke"))
        else:
            checks.append(Check(name, f"{where}, inputs {state(f['inputs'])} while "
                                f"{pins[int(f['moving'][1:])]} moves (output should stay "
                                f"{f['expected']})", _dev(f["max_deviation_fraction"]), TOLERANCE,
                                "<=", "of stroke"))
    if len(wrong) > MAX_LISTED:
        checks.append(Check(name + ": wrong states in all", where, float(len(wrong)), 0.0,
                            "<="))
    if not checks:
        checks.append(Check(name, where, report.figures["max_deviation_fraction"], TOLERANCE,
                            "<=", "of stroke"))
    _PROVEN[key] = checks
    return list(checks)


def _dev(x: float | None) -> float:
    """A deviation for a check; an unsolvable state (no number) counts as a full stroke."""
    return 1.0 if x is None else float(x)
