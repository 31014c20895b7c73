"""AND with an inverting lever on the output (001 Fig 16e)."""

from mechc.cell import Cell


class NandGate(Cell):
    name = "nand"
    type = "NAND"
    min_inputs = 2
    max_inputs = 4
    description = "AND with an inverting lever on the output (001 Fig 16e)"

    @classmethod
    def cost(cls, n_inputs: int) -> int:
        return 3 + n_inputs
