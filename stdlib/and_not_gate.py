"""AND-NOT (a·b̄): an AND bar whose second input comes through an inverting lever (Fig 16f)."""

from mechc.cell import Cell
from mechc.mech.build import Builder, Demand


class AndNotGate(Cell):
    name = "and_not"
    type = "AND_NOT"
    min_inputs = 2
    max_inputs = 2
    description = "AND bar with an inverting lever on the second input: a·b̄ (Fig 16f)"

    @classmethod
    def cost(cls, n_inputs: int) -> int:
        return 6  # two input sliders, lever, inverted slider, bar, spring

    @classmethod
    def synthesise(cls, cid, ctx, n_inputs, params, demand):
        b = Builder(cid, ctx)
        S, w, p, f = ctx.stroke, ctx.bar, ctx.pitch, ctx.friction
        a = b.input_slider("A", 0.0, 0.0, 1.0 * S)
        bb = b.input_slider("B", 0.0, -p, 1.0 * S)
        x_lever = 1.0 * S + w
        nb, _ = b.not_lever("lever", bb, x_lever, -p, Demand(), 0.8 * S)
        bar, (load_a, load_nb) = b.and_bar("bar", [a, nb], x_lever + w + 0.6 * S, demand)
        bar.y = -p / 2
        b.output(bar, "Z", reach=bar.x + 0.8 * S)
        load_b = Demand(load_nb.left + f, load_nb.right + f)
        return b.finish({"A": load_a, "B": load_b})
