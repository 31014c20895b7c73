"""XOR (or-exclusive): a·b̄ + ā·b from two AND-NOT bars and an OR bar (001 §2.3.8).

The dissertation's Fig. 11 linkage is not legible in the scan; this cell builds the same
function from the Chapter II blocks: each input holds back one AND bar directly and the other
through its own inverting lever, and an OR bar takes either AND bar.
"""

from mechc.cells.builder import Builder
from mechc.cells.cell import Cell
from mechc.ir.mechanism import Demand


def build_xor(b: Builder, demand: Demand):
    """XOR block on builder ``b``: returns (output bar signal, input loads)."""
    ctx = b.ctx
    S, w, p, f, r = ctx.stroke, ctx.bar, ctx.pitch, ctx.friction, ctx.arm
    a = b.input_slider("A", 0.0, 0.0, 1.0 * S)
    bb = b.input_slider("B", 0.0, -p, 1.0 * S)
    xa, xb = 1.0 * S + w, 1.0 * S + 3 * w
    na, _ = b.not_lever("lever_a", a, xa, 0.0, Demand(), 0.5 * S)
    nb, _ = b.not_lever("lever_b", bb, xb, -p, Demand(), 0.5 * S, layer=3)
    x1, x2, x3 = xb + 2 * w + 0.6 * S, xb + 4 * w + 1.6 * S, xb + 6 * w + 2.6 * S
    rows = [-r, -r - p / 2]  # where the AND bars push the OR bar
    bar1, _ = b.and_bar("bar1", [a, nb], x1, Demand(), y_extra=[rows[0]])
    bar2, _ = b.and_bar("bar2", [bb, na], x2, Demand(), y_extra=[rows[1]])
    bar1.y, bar2.y = rows
    bar3, (l1, l2) = b.or_bar("bar3", [bar1, bar2], x3, demand)
    # bar1's lug to the OR bar passes bar2: it runs on the sliders' plane, as every lug that
    # pushes a bar does (on the bars' plane it would cut through bar2)
    body1 = b.part.body(bar1.body)
    body1.poly_layers = [body1.layer] * (len(body1.outline) - 1) + [0]
    la, lnb = b.size(bar1.body, l1)  # the AND bars must push the OR bar
    lb, lna = b.size(bar2.body, l2)
    load_a = la + Demand(lna.left + f, lna.right + f)
    load_b = lb + Demand(lnb.left + f, lnb.right + f)
    return bar3, {"A": load_a, "B": load_b}


class XorGate(Cell):
    name = "xor"
    type = "XOR"
    min_inputs = 2
    max_inputs = 2
    description = "or-exclusive: two AND-NOT bars into an OR bar (function of Fig 11)"

    @classmethod
    def cost(cls, n_inputs: int) -> int:
        return 13  # 2 inputs, 2 levers, 2 inverted sliders, 3 bars, 3 springs, +1 lug

    @classmethod
    def synthesise(cls, cid, ctx, n_inputs, params, demand):
        b = Builder(cid, ctx)
        bar, loads = build_xor(b, demand)
        bar.y = -ctx.arm - ctx.pitch / 4
        b.output(bar, "Z", reach=bar.x + 0.8 * ctx.stroke)
        return b.finish(loads)
