"""How long a dynamic proof holds each input change after its move: at least as long as the
design's own slowest chain needs.

A fixed hold calls a deep circuit unsettled when it is only slow by design: a carry rippling
through the fifty gates of a 16-bit adder outlasts 0.15 s while every gate works. So each
change is held the longer of the default hold (:class:`mechc.physics.scene.DynSettings`) and
what the design's structure asks:

- combinational: :data:`HOLD_FACTOR` times its static critical path (:func:`static_path`): the
  longest sum through the netlist of each cell's characterised lag (its timing table shipped
  with mechc, at the move's input speed and the mass its output net drives, the slower of its
  two directions, or its stated switching delay if longer) plus the settle extra of the cell
  it ends in. Static timing analysis: nothing is simulated and every structural path counts,
  sensitised by a change or not.
- sequential: :func:`settle_allowance` (a transition may pass through every memory in turn).

Every level that judges settling (dynamic, screened, timing) takes its hold from here, so they
judge one budget; ``mechc simulate --hold S`` replaces it. A longer hold costs nothing on a
change that settles early (the run stops once every body is still).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from mechc.cells.characterise import Tables, measuring
from mechc.cells.library import Library
from mechc.ir.design import Design
from mechc.ir.paths import latest
from mechc.parts.pushrod import net_loads

#: The hold is this many times the static critical path (when that is above the default): a
#: measured allowance, not a bound. The latest settle was 0.92 of the path on a 4-bit adder's
#: 11-cell chain and 1.47 of it on a 16-bit adder's 58-cell one, whose chain itself settles
#: within the path: the rest is a tremor of the solver's (docs/mechanism.md).
HOLD_FACTOR = 2.0
#: An allowance (s) for a MEMORY's lever to go from upright to its stop (the detent's throw).
MEMORY_THROW_S = 0.03
_LAGS = ("lag_s", "lag_on_s", "lag_off_s")
_EXTRAS = ("settle_extra_s", "settle_extra_on_s", "settle_extra_off_s")


@dataclass(frozen=True)
class StaticPath:
    """The longest characterised path: its seconds (lags along it and the settle extra of
    its last cell, after the input's move ends) and its cells from the input side."""

    seconds: float
    cells: tuple[str, ...]
    untabled: tuple[str, ...] = ()  # cells with no shipped table: their stated delay only

    def to_json(self) -> dict:
        return {"seconds": round(self.seconds, 5), "cells": list(self.cells),
                "untabled": list(self.untabled)}


def static_path(design: Design, lib: Library, move_time: float,
                progress: Callable[..., None] | None = None) -> StaticPath:
    """The design's static critical path at inputs moved in ``move_time`` (see the module
    docstring). A cell's table is shipped, cached or measured now, as the timing level gets
    it (:class:`mechc.cells.characterise.Tables`; a measurement is the same wherever it runs,
    so the hold does not depend on what ran before). A cell that cannot be measured (too
    broken to switch alone: the proof that follows reports it) counts its stated delay alone
    and is listed in ``untabled``. ``progress`` is told (done, total, what) while a cell's
    table is measured (the first use of a cell on this machine: seconds per cell)."""
    nl = design.netlist
    mech = design.mechanism
    if mech is None or not nl.cells:
        return StaticPath(0.0, ())
    tabs = Tables(lib, measuring(progress))
    loads = net_loads(mech)
    lag: dict[str, float] = {}
    extra: dict[str, float] = {}
    untabled = []
    for c in nl.cells.values():
        stated = float(getattr(lib[c.cell], "switching_delay_s", 0.0) or 0.0)
        tab = None  # a memory or a constant has none (Tables.get)
        try:
            tab = tabs.get(c.cell, c.type, len(c.inputs), dict(c.params), mech.ctx.stroke)
        except Exception:  # noqa: BLE001 - any failure to measure: stated delay only
            untabled.append(c.id)
        v = tab.at(move_time, loads.get(c.outputs[0], 0.0)) if tab is not None else {}
        lag[c.id] = max([stated] + [v[k] for k in _LAGS if k in v])
        extra[c.id] = max([0.0] + [v[k] for k in _EXTRAS if k in v])
    arrive, came = latest(nl.combinational_graph(), lag)
    end = max(nl.cells, key=lambda c: (arrive[c] + extra[c], c))
    cells = []
    node: str | None = end
    while node is not None:
        if node in nl.cells:
            cells.append(node)
        node = came[node]
    return StaticPath(arrive[end] + extra[end], tuple(reversed(cells)), tuple(untabled))


def settle_allowance(design: Design, lib: Library) -> float:
    """How long after an input's move a sequential circuit may still be switching: along the
    slowest path, each cell's stated switching delay (an AMPLIFIER's measured one), and a
    transition may pass through every memory in turn. Used as the hold of each change (it
    still must settle)."""
    nl = design.netlist
    delay = {c.id: float(getattr(lib[c.cell], "switching_delay_s", 0.0))
             for c in nl.cells.values()}
    arrive, _came = latest(nl.combinational_graph(), delay)
    path = max(arrive.values(), default=0.0)
    m = sum(1 for c in nl.cells.values() if getattr(lib[c.cell], "stateful", False))
    return 0.1 + (m + 1) * (path + MEMORY_THROW_S)


def design_hold(design: Design, lib: Library, move_time: float, base: float,
                progress: Callable[..., None] | None = None) -> dict:
    """The hold a dynamic proof of ``design`` uses by default: ``base`` or longer, and why
    (``{"seconds", "from", "static_path"?}``; ``from`` is ``default``, ``static path`` or
    ``memories``); ``progress`` as for :func:`static_path`."""
    if design.netlist.state_nets():
        need = settle_allowance(design, lib)
        if need > base:
            return {"seconds": need, "from": "memories"}
        return {"seconds": base, "from": "default"}
    path = static_path(design, lib, move_time, progress)
    need = HOLD_FACTOR * path.seconds
    out = {"seconds": base, "from": "default",
           "static_path": {**path.to_json(), "factor": HOLD_FACTOR}}
    if need > base:
        out.update({"seconds": need, "from": "static path"})
    return out
