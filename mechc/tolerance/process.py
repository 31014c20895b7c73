"""Process presets: the tolerance and pin clearance a way of making parts gives
(docs/tolerance.md says where each figure comes from and why it was chosen)."""

from __future__ import annotations

from dataclasses import dataclass

from mechc.errors import UsageError


@dataclass(frozen=True)
class Process:
    name: str
    what: str
    tol: float  # mm, +- on every dimension
    clearance: float  # mm, diametral play of a pin in its hole
    spring_tol: float  # fraction, bought springs' rate and preload


PROCESSES = {p.name: p for p in (
    Process("laser", "hobby CO2 laser cutter, 3 mm acrylic, 3 mm steel dowels", 0.1, 0.1, 0.1),
    Process("fdm", "FDM 3D printer (0.4 mm nozzle), PLA, steel dowels in printed holes", 0.2,
            0.2, 0.1),
    Process("cnc", "CNC-milled aluminium plate, reamed holes, ground dowels (H7/g6 fit)", 0.05,
            0.02, 0.1),
)}


def process(name: str) -> Process:
    try:
        return PROCESSES[name]
    except KeyError:
        raise UsageError(f"unknown process '{name}' (known: {', '.join(PROCESSES)})") from None
