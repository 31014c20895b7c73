"""OR-NOT (a + b̄): an OR bar whose second input comes through an inverting lever (Fig 16g)."""

from mechc.stdlib._bar_cells import InvertedSecondGate


class OrNotGate(InvertedSecondGate):
    name = "or_not"
    type = "OR_NOT"
    bar_kind = "or"
    description = "OR bar with an inverting lever on the second input: a + b̄ (Fig 16g)"
