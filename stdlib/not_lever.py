"""Ternary lever pivoted at its centre: input right, output left (001 Fig 16c)."""

from mechc.cell import Cell


class NotLever(Cell):
    name = "not"
    type = "NOT"
    min_inputs = 1
    max_inputs = 1
    description = "ternary lever pivoted at its centre: input right, output left (001 Fig 16c)"

    @classmethod
    def cost(cls, n_inputs: int) -> int:
        return 1
