"""NOT: a ternary lever pivoted at its centre; the input moves right, the output left (Fig 16c)."""

from mechc.cells.builder import Builder
from mechc.cells.cell import Cell
from mechc.ir.mechanism import Demand


class NotLever(Cell):
    name = "not"
    type = "NOT"
    min_inputs = 1
    max_inputs = 1
    description = "lever pivoted at its centre: input right, output left (Fig 16c)"

    @classmethod
    def cost(cls, n_inputs: int) -> int:
        return 3  # input slider, lever, output slider

    @classmethod
    def synthesise(cls, cid, ctx, n_inputs, params, demand):
        b = Builder(cid, ctx)
        S, w = ctx.stroke, ctx.bar
        a = b.input_slider("A", 0.0, 0.0, 1.0 * S)
        out, load = b.not_lever("lever", a, 1.0 * S + w, 0.0, demand, 1.2 * S)
        b.output(out, "Z")
        return b.finish({"A": load})


def inverse(demand: Demand, ctx) -> Demand:
    """What a NOT lever asks of its input when its output must deliver ``demand``."""
    return Demand(demand.left + ctx.friction, demand.right + ctx.friction)
