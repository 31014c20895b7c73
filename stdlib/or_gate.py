"""OR: an output bar with a preloaded return spring; any input pushes it on (001 Figs 4, 16a)."""

from mechc.stdlib._bar_cells import BarGate


class OrGate(BarGate):
    name = "or"
    type = "OR"
    bar_kind = "or"
    description = "output bar with preloaded return spring, pushed on by any input (Figs 4, 16a)"
