"""A design check: a named number, its limit and which side of it passes. Every check,
wherever it is measured (force budget, kinematic sweep, a cell's own rules), is one of these."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass
class Check:
    """A design check with the number that decides it."""

    name: str
    where: str
    value: float
    limit: float
    sense: str  # ">=" or "<="
    unit: str = ""

    @property
    def passed(self) -> bool:
        v = self.value
        if v != v:  # NaN never passes
            return False
        return bool(v >= self.limit if self.sense == ">=" else v <= self.limit)

    def to_json(self) -> dict:
        return {"name": self.name, "where": self.where, "value": round(float(self.value), 4),
                "limit": self.limit, "sense": self.sense, "unit": self.unit,
                "passed": self.passed}

    def text(self) -> str:
        return (f"{self.name} at {self.where}: {self.value:.4g}{self.unit} "
                f"(limit {self.sense} {self.limit:g}{self.unit})")
