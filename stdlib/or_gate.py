"""Output slider with a preloaded return spring; any input pushes it on (001 Figs 4, 16a)."""

from mechc.cell import Cell


class OrGate(Cell):
    name = "or"
    type = "OR"
    min_inputs = 2
    max_inputs = 4
    description = ("output slider with a preloaded return spring; any input pushes it on "
                   "(001 Figs 4, 16a)")

    @classmethod
    def cost(cls, n_inputs: int) -> int:
        return 2 + n_inputs
