"""Shared layouts of the bar cells (001 Fig 16): the AND and OR families differ only in which
bar block they use, so each cell file names its bar and its figure (``bar_kind``).

An AND bar's hooks reach below its lowest input, so its output row sits half a pitch lower
than an OR bar's, and the inverting lever under it one pitch lower.
"""

from mechc.cells.builder import Builder, Sig
from mechc.cells.cell import Cell
from mechc.ir.mechanism import Demand


def _bar(b: Builder, kind: str):
    return b.and_bar if kind == "and" else b.or_bar


class BarGate(Cell):
    """AND / OR: one bar pushed or released by every input."""

    bar_kind = ""
    min_inputs = 2
    max_inputs = 4

    @classmethod
    def cost(cls, n_inputs: int) -> int:
        return 2 + n_inputs  # bar, spring, one input slider per input

    @classmethod
    def synthesise(cls, cid, ctx, n_inputs, params, demand):
        b = Builder(cid, ctx)
        S, w, p = ctx.stroke, ctx.bar, ctx.pitch
        pins = cls.input_names(n_inputs)
        sigs = [b.input_slider(pin, 0.0, -i * p, 1.5 * S) for i, pin in enumerate(pins)]
        bar, loads = _bar(b, cls.bar_kind)("bar", sigs, 1.5 * S + w / 2, demand)
        bar.y = -(n_inputs - 1) * p / 2 - (p / 2 if cls.bar_kind == "and" else 0.0)
        b.output(bar, "Z", reach=bar.x + 0.8 * S)
        return b.finish(dict(zip(pins, loads)))


class InvertedOutputGate(Cell):
    """NAND / NOR: the bar drives an inverting lever on the output."""

    bar_kind = ""
    min_inputs = 2
    max_inputs = 4

    @classmethod
    def cost(cls, n_inputs: int) -> int:
        return 4 + n_inputs  # bar parts + lever + output slider

    @classmethod
    def synthesise(cls, cid, ctx, n_inputs, params, demand):
        b = Builder(cid, ctx)
        S, w, p, f = ctx.stroke, ctx.bar, ctx.pitch, ctx.friction
        pins = cls.input_names(n_inputs)
        sigs = [b.input_slider(pin, 0.0, -i * p, 1.5 * S) for i, pin in enumerate(pins)]
        and_ = cls.bar_kind == "and"
        y_low = -(n_inputs - 1) * p - (p if and_ else 0.0)
        bar, loads = _bar(b, cls.bar_kind)("bar", sigs, 1.5 * S + w / 2,
                                           Demand(demand.left + f, demand.right + f),
                                           y_extra=[y_low] if and_ else ())
        out, _ = b.not_lever("lever", Sig(bar.body, bar.x, y_low), bar.x + w, y_low, demand,
                             1.2 * S)
        b.output(out, "Z")
        return b.finish(dict(zip(pins, loads)))


class InvertedSecondGate(Cell):
    """AND-NOT / OR-NOT: the second input reaches the bar through an inverting lever."""

    bar_kind = ""
    min_inputs = 2
    max_inputs = 2

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
        bar, (load_a, load_nb) = _bar(b, cls.bar_kind)("bar", [a, nb], x_lever + w + 0.6 * S,
                                                       demand)
        bar.y = -p / 2
        b.output(bar, "Z", reach=bar.x + 0.8 * S)
        load_b = Demand(load_nb.left + f, load_nb.right + f)
        return b.finish({"A": load_a, "B": load_b})
