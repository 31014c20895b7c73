"""OR with an inverting lever on the output (001 Fig 16d)."""

from mechc.cell import Cell


class NorGate(Cell):
    name = "nor"
    type = "NOR"
    min_inputs = 2
    max_inputs = 4
    description = "OR with an inverting lever on the output (001 Fig 16d)"

    @classmethod
    def cost(cls, n_inputs: int) -> int:
        return 3 + n_inputs
