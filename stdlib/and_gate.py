"""AND: an output bar sprung towards on, held back by every input that is off (001 Figs 5, 16b)."""

from mechc.stdlib._bar_cells import BarGate


class AndGate(BarGate):
    name = "and"
    type = "AND"
    bar_kind = "and"
    description = "output bar sprung towards on, held off by any input that is off (Figs 5, 16b)"
