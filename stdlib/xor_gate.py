"""Or-exclusive linkage (001 Fig 11)."""

from mechc.cell import Cell


class XorGate(Cell):
    name = "xor"
    type = "XOR"
    min_inputs = 2
    max_inputs = 2
    description = "or-exclusive linkage (001 Fig 11)"

    @classmethod
    def cost(cls, n_inputs: int) -> int:
        return 6
