"""Output slider sprung towards on, held off by any input that is off (001 Figs 5, 16b)."""

from mechc.cell import Cell


class AndGate(Cell):
    name = "and"
    type = "AND"
    min_inputs = 2
    max_inputs = 4
    description = ("output slider sprung towards on, held off by any input that is off "
                   "(001 Figs 5, 16b)")

    @classmethod
    def cost(cls, n_inputs: int) -> int:
        return 2 + n_inputs
