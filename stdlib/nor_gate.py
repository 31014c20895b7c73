"""NOR: an OR bar driving an inverting lever on its output (001 Fig 16d)."""

from mechc.stdlib._bar_cells import InvertedOutputGate


class NorGate(InvertedOutputGate):
    name = "nor"
    type = "NOR"
    bar_kind = "or"
    description = "OR bar with an inverting lever on the output (Fig 16d)"
