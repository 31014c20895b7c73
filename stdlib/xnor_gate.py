"""XNOR (coincidence): the XOR cell's OR bar driving an inverting lever (001 §2.3.7)."""

from mechc.stdlib.xor_gate import build_xor

from mechc.cells.builder import Builder, Sig
from mechc.cells.cell import Cell
from mechc.ir.mechanism import Demand


class XnorGate(Cell):
    name = "xnor"
    type = "XNOR"
    min_inputs = 2
    max_inputs = 2
    description = "coincidence: the or-exclusive linkage with an inverting output lever (Fig 10)"

    @classmethod
    def cost(cls, n_inputs: int) -> int:
        return 15

    @classmethod
    def synthesise(cls, cid, ctx, n_inputs, params, demand):
        b = Builder(cid, ctx)
        f = ctx.friction
        bar, loads = build_xor(b, Demand(demand.left + f, demand.right + f))
        y_low = -ctx.arm - ctx.pitch
        out, _ = b.not_lever("lever", Sig(bar.body, bar.x, y_low), bar.x + ctx.bar, y_low,
                             demand, 1.0 * ctx.stroke)
        b.output(out, "Z")
        return b.finish(loads)
