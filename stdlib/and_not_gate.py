"""AND-NOT (a·b̄): an AND bar whose second input comes through an inverting lever (Fig 16f)."""

from mechc.stdlib._bar_cells import InvertedSecondGate


class AndNotGate(InvertedSecondGate):
    name = "and_not"
    type = "AND_NOT"
    bar_kind = "and"
    description = "AND bar with an inverting lever on the second input: a·b̄ (Fig 16f)"
