"""Placement of a netlist: mm coordinates, column (logic depth) and row of every cell and input."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Place:
    x: float
    y: float
    column: int
    row: int

    def to_json(self) -> dict:
        return {"x": round(self.x, 3), "y": round(self.y, 3), "column": self.column,
                "row": self.row}


@dataclass
class Layout:
    cells: dict[str, Place]
    inputs: dict[str, Place]
    pitch: tuple[float, float]
    crossings: int

    def to_json(self) -> dict:
        return {"pitch_mm": list(self.pitch), "crossings": self.crossings,
                "inputs": {k: v.to_json() for k, v in self.inputs.items()}}
