"""AND with an inverting lever on the second input: a·b̄ (001 Fig 16f)."""

from mechc.cell import Cell


class AndNotGate(Cell):
    name = "and_not"
    type = "AND_NOT"
    min_inputs = 2
    max_inputs = 2
    description = "AND with an inverting lever on the second input: a·b̄ (001 Fig 16f)"

    @classmethod
    def cost(cls, n_inputs: int) -> int:
        return 5
