"""OR with an inverting lever on the second input: a + b̄ (001 Fig 16g)."""

from mechc.cell import Cell


class OrNotGate(Cell):
    name = "or_not"
    type = "OR_NOT"
    min_inputs = 2
    max_inputs = 2
    description = "OR with an inverting lever on the second input: a + b̄ (001 Fig 16g)"

    @classmethod
    def cost(cls, n_inputs: int) -> int:
        return 5
