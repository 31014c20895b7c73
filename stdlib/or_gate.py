"""OR: an output bar with a preloaded return spring; any input pushes it on (001 Figs 4, 16a)."""

from mechc.cell import Cell
from mechc.mech.build import Builder


class OrGate(Cell):
    name = "or"
    type = "OR"
    min_inputs = 2
    max_inputs = 4
    description = "output bar with preloaded return spring, pushed on by any input (Figs 4, 16a)"

    @classmethod
    def cost(cls, n_inputs: int) -> int:
        return 2 + n_inputs  # bar, spring, one input slider per input

    @classmethod
    def synthesise(cls, cid, ctx, n_inputs, params, demand):
        b = Builder(cid, ctx)
        S, w, p = ctx.stroke, ctx.bar, ctx.pitch
        pins = cls.input_names(n_inputs)
        sigs = [b.input_slider(pin, 0.0, -i * p, 1.5 * S) for i, pin in enumerate(pins)]
        bar, loads = b.or_bar("bar", sigs, 1.5 * S + w / 2, demand)
        bar.y = -(n_inputs - 1) * p / 2
        b.output(bar, "Z", reach=bar.x + 0.8 * S)
        return b.finish(dict(zip(pins, loads)))
