"""Coincidence linkage (001 Fig 10)."""

from mechc.cell import Cell


class XnorGate(Cell):
    name = "xnor"
    type = "XNOR"
    min_inputs = 2
    max_inputs = 2
    description = "coincidence linkage (001 Fig 10)"

    @classmethod
    def cost(cls, n_inputs: int) -> int:
        return 6
