"""Minimised equations: per output a sum of products (a cover), its complement and XOR forms."""

from __future__ import annotations

from dataclasses import dataclass, field

from mechc.ir import expr as ex
from mechc.logic.cubes import Cube, sort_cubes


@dataclass
class Cover:
    """A sum of products over the spec's inputs, with how it was obtained."""

    cubes: list[Cube]
    proven: bool  # proven minimum (terms, then literals)
    method: str  # "exact" | "greedy" | "expand"
    seconds: float = 0.0

    @property
    def terms(self) -> int:
        return len(self.cubes)

    @property
    def literals(self) -> int:
        return sum(c.literals() for c in self.cubes)


@dataclass
class XorForm:
    """f = x_a ⊕ x_b ⊕ ... ⊕ g: the peeled inputs and the residual g (a cover or a constant)."""

    vars: list[str]
    residual: Cover | None
    residual_complement: Cover | None
    constant: int | None = None  # residual is this constant

    def residual_keys(self, planner, inputs):
        """Candidate structures for g as (key, invert-result) pairs for the mapper."""
        if self.constant is not None:
            return [(None, self.constant == 1)]
        out = [(planner.sop(self.residual, inputs), False)]
        if self.residual_complement is not None:
            out.append((planner.sop(self.residual_complement, inputs, invert=True), False))
        return out


@dataclass
class Equations:
    inputs: list[str]
    outputs: list[str]
    covers: dict[str, Cover]
    complements: dict[str, Cover] = field(default_factory=dict)  # covers of the complements
    xor_forms: dict[str, XorForm] = field(default_factory=dict)
    # the covers with consensus terms added (no static-1 hazard under single-input changes);
    # the mapper builds these; ``covers`` stay the minimum the equations report
    hazard_free: dict[str, Cover] = field(default_factory=dict)
    hazard_free_complements: dict[str, Cover] = field(default_factory=dict)
    shared_terms: int = 0  # product terms used by more than one output
    time_limited: list[str] = field(default_factory=list)  # minimiser steps that ran out of time
    # the per-output covers (shared afterwards) when the covers above share products across
    # outputs: the mapper builds whichever costs fewer parts
    alternative: Equations | None = None

    def expr(self, name: str, complement: bool = False) -> ex.Expr:
        cover = (self.complements if complement else self.covers)[name]
        n = len(self.inputs)
        return ex.sop([[(self.inputs[k], pos) for k, pos in c.literal_list(n)]
                       for c in sort_cubes(cover.cubes, n)])

    def text(self, name: str) -> str:
        return ex.to_text(self.expr(name))

    @property
    def literals(self) -> int:
        return sum(c.literals for c in self.covers.values())

    @property
    def terms(self) -> int:
        return sum(c.terms for c in self.covers.values())

    @property
    def products(self) -> int:
        """Distinct product terms over all outputs (what espresso's ``.p`` counts)."""
        return len({c for cover in self.covers.values() for c in cover.cubes})

    @property
    def proven(self) -> bool:
        return all(c.proven for c in self.covers.values())
