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
    detail: str = ""  # where and how it was measured (e.g. the state of an interference)

    @property
    def passed(self) -> bool:
        v = self.value
        if v != v:  # NaN never passes
            return False
        return bool(v >= self.limit if self.sense == ">=" else v <= self.limit)

    def to_json(self) -> dict:
        d = {"name": self.name, "where": self.where, "value": round(float(self.value), 4),
             "limit": self.limit, "sense": self.sense, "unit": self.unit,
             "passed": self.passed}
        if self.detail:
            d["detail"] = self.detail
        return d

    def text(self) -> str:
        """The check with its place, for a failure list."""
        # a unit written as a word (N mm) stands apart from its number; ° and x do not
        u = f" {self.unit}" if self.unit[:1].isalpha() and self.unit != "x" else self.unit
        text = (f"{self.name} at {self.where}: {self.value:.4g}{u} "
                f"(limit {self.sense} {self.limit:g}{u})")
        return f"{text}: {self.detail}" if self.detail else text

    def __str__(self) -> str:
        """The check and its verdict without its place (the threshold toolkit's reports name
        the generator once, not per check)."""
        ok = "ok" if self.passed else "FAILED"
        return f"{self.name} = {self.value:.4g} {self.unit} ({self.sense} {self.limit:g}: {ok})"
