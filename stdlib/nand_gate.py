"""NAND: an AND bar driving an inverting lever on its output (001 Fig 16e)."""

from mechc.stdlib._bar_cells import InvertedOutputGate


class NandGate(InvertedOutputGate):
    name = "nand"
    type = "NAND"
    bar_kind = "and"
    description = "AND bar with an inverting lever on the output (Fig 16e)"
