"""A terminal held at off or on by a fixed stop."""

from mechc.cell import Cell


class ConstStop(Cell):
    name = "const"
    type = "CONST"
    min_inputs = 0
    max_inputs = 0
    description = "a terminal held at off or on by a fixed stop"

    @classmethod
    def cost(cls, n_inputs: int) -> int:
        return 1
