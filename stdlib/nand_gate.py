"""NAND: an AND bar driving an inverting lever on its output (001 Fig 16e)."""

from mechc.cell import Cell
from mechc.mech.build import Builder, Demand, Sig


class NandGate(Cell):
    name = "nand"
    type = "NAND"
    min_inputs = 2
    max_inputs = 4
    description = "AND bar with an inverting lever on the output (Fig 16e)"

    @classmethod
    def cost(cls, n_inputs: int) -> int:
        return 4 + n_inputs

    @classmethod
    def synthesise(cls, cid, ctx, n_inputs, params, demand):
        b = Builder(cid, ctx)
        S, w, p, f = ctx.stroke, ctx.bar, ctx.pitch, ctx.friction
        pins = cls.input_names(n_inputs)
        sigs = [b.input_slider(pin, 0.0, -i * p, 1.5 * S) for i, pin in enumerate(pins)]
        y_low = -(n_inputs - 1) * p - p
        bar, loads = b.and_bar("bar", sigs, 1.5 * S + w / 2,
                               Demand(demand.left + f, demand.right + f), y_extra=[y_low])
        out, _ = b.not_lever("lever", Sig(bar.body, bar.x, y_low), bar.x + w, y_low, demand,
                             1.2 * S)
        b.output(out, "Z")
        return b.finish(dict(zip(pins, loads)))
