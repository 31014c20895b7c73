"""CONST: a terminal held at off or on by a spring against a fixed stop (a constant signal)."""

from mechc.cells.builder import Builder
from mechc.cells.cell import Cell


class ConstStop(Cell):
    name = "const"
    type = "CONST"
    min_inputs = 0
    max_inputs = 0
    description = "a terminal held at off or on by a spring against fixed stops"

    @classmethod
    def cost(cls, n_inputs: int) -> int:
        return 2

    @classmethod
    def synthesise(cls, cid, ctx, n_inputs, params, demand):
        b = Builder(cid, ctx)
        S = ctx.stroke
        on = bool(params.get("value", 0))
        sig = b.slider("out", 0.0, 1.5 * S, 0.0, "constant")
        at = (0.75 * S, 0.0)
        # both stops at the constant's position: it cannot move either way
        if on:
            b.stop_above(sig.body, at, S / 2)
            b.stop_below(sig.body, at, -S / 2)
        else:
            b.stop_below(sig.body, at, S / 2)
            b.stop_above(sig.body, at, -S / 2)
        force = max(ctx.min_preload, ctx.margin * (demand.left + demand.right + ctx.friction))
        b.spring(sig.body, at, 1 if on else -1, force, b.moving_mass([sig.body]))
        b.part.data["spring_required_N"] = {b.part.springs[-1].id: ctx.friction}
        b.output(sig, "Z")
        return b.finish({})
