"""Building blocks for slider-and-lever cells (001 Chapter II, Figs 4-9 and 16).

A cell is composed from three blocks on horizontal sliders whose displacement is the signal
(left = off, right = on, every terminal with the same stroke S):

- ``or_bar``: an output bar pushed right by any input through one-sided contacts; a preloaded
  spring pulls it back to its off stop (OR; Fig. 4, 16a);
- ``and_bar``: an output bar sprung towards on, held back by hooks on every input (AND; Fig. 5,
  16b);
- ``not_lever``: a lever pivoted at its centre between a slot on the signal and a slot on a new
  slider, so the new slider moves opposite (NOT; Fig. 16c).

Everything is laid out at the design pose (all signals at half stroke). Spring preloads come
from a force budget: a block is given the force its output must deliver in each direction
(``Demand``) and reports what it asks of its inputs.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from mechc.cells.springs import design_coil
from mechc.ir.mechanism import (
    GROUND,
    Body,
    Demand,
    Joint,
    Part,
    Point,
    Spring,
    SynthContext,
    Terminal,
)


def rect(x0: float, y0: float, x1: float, y1: float) -> list[Point]:
    """The axis-aligned rectangle with corners (x0, y0) and (x1, y1), in either order, as the
    counter-clockwise polygon every body outline is made of."""
    xa, xb = sorted((x0, x1))
    ya, yb = sorted((y0, y1))
    return [(xa, ya), (xb, ya), (xb, yb), (xa, yb)]


@dataclass
class Sig:
    """A signal inside a cell: a slider whose displacement is the signal, and where it reaches.

    ``body`` is the slider's id, ``x`` its right-most point (its tip) at the design pose and
    ``y`` its row. Blocks take signals and return new ones; set ``y`` on a returned bar to choose
    the row its output lug (and the output terminal) sits on."""

    body: str
    x: float  # right-most x the body reaches (its tip) at the design pose
    y: float  # its row


class Builder:
    """Accumulates the bodies, joints and springs of one cell (ids prefixed by the cell id).

    Make one per instance in ``Cell.synthesise(cid, ctx, ...)`` as ``Builder(cid, ctx)``;
    ``ctx`` holds the design rules (``stroke``, bar width ``bar``, row ``pitch``, lever ``arm``,
    ``friction``, spring ``margin`` ...). Lay everything out at the design pose (every signal at
    half stroke), then return ``finish(...)``."""

    def __init__(self, cid: str, ctx: SynthContext):
        self.cid, self.ctx, self.part = cid, ctx, Part()
        self.n = 0
        self.bars: dict[str, tuple[str, int, Point]] = {}  # bar -> (kind, inputs, spring point)

    def name(self, local: str) -> str:
        """The id of this cell's body called ``local``: ``"{cid}.{local}"`` (so two
        instances of a cell never share a body id)."""
        return f"{self.cid}.{local}"

    def _id(self, kind: str) -> str:
        self.n += 1
        return f"{self.cid}.{kind}{self.n}"

    # ---- bodies -----------------------------------------------------------------------------
    def slider(self, local: str, x0: float, x1: float, y: float, role: str,
               layer: int = 0) -> Sig:
        """A horizontal slider: a bar ``ctx.bar`` wide from ``x0`` to ``x1`` on row ``y``,
        guided along x. ``role`` labels it in drawings and reports; ``layer`` is the plane it
        moves in (bodies on different layers may cross). Returns it as a signal whose tip is
        ``x1``; it is no terminal until :meth:`terminal` (or use :meth:`input_slider`)."""
        h = self.ctx.bar
        poly = rect(x0, y - h / 2, x1, y + h / 2)
        self.part.bodies.append(Body(self.name(local), "slider", [poly], self.ctx.mass([poly]),
                                     axis=(1.0, 0.0), layer=layer, role=role))
        return Sig(self.name(local), x1, y)

    def extend(self, body: str, poly: list[Point]) -> None:
        """Add polygon ``poly`` (a lug, a hook) to the outline of ``body``; its mass follows."""
        b = self.part.body(body)
        b.outline.append(poly)
        b.mass = self.ctx.mass(b.outline)

    def reach(self, sig: Sig, x: float) -> Sig:
        """Lengthen a slider to the right so its tip is at ``x`` (a lug on its row); returns
        the signal with its new tip (the same one if it already reaches ``x``)."""
        if x > sig.x + 1e-9:
            h = self.ctx.bar
            self.extend(sig.body, rect(sig.x, sig.y - h / 2, x, sig.y + h / 2))
            return Sig(sig.body, x, sig.y)
        return sig

    def bar(self, local: str, x: float, y_lo: float, y_hi: float, role: str) -> str:
        """A vertical bar at ``x`` spanning rows ``y_lo`` to ``y_hi``, guided along x on layer
        1 (over the input sliders); returns its id. :meth:`or_bar` and :meth:`and_bar` make
        theirs with it and add its contacts, stops and spring."""
        w = self.ctx.bar
        poly = rect(x - w / 2, y_lo - w / 2, x + w / 2, y_hi + w / 2)
        self.part.bodies.append(Body(self.name(local), "slider", [poly], self.ctx.mass([poly]),
                                     axis=(1.0, 0.0), layer=1, role=role))
        return self.name(local)

    # ---- joints -----------------------------------------------------------------------------
    def contact(self, a: str, b: str, pa: Point, pb: Point, driven: str,
                normal: Point = (1.0, 0.0)) -> None:
        """A one-sided contact: point ``pa`` of body ``a`` pushes point ``pb`` of body ``b``
        along ``normal`` (they touch at the design pose when ``pa == pb``); it can push, never
        pull. ``driven`` is the body the contact moves (``b`` when ``a`` pushes it)."""
        self.part.joints.append(Joint(self._id("contact"), "contact", a, b, pa=pa, pb=pb,
                                      normal=normal, driven=driven))

    def stop_below(self, body: str, at: Point, travel: float) -> None:
        """A stop on the ground at ``at`` (a point of ``body``): the body may move left by at
        most ``travel`` from the design pose (its off position for a bar: ``S / 2``)."""
        ground = (at[0] - travel, at[1])
        self.part.joints.append(Joint(self._id("stop"), "contact", GROUND, body, pa=ground,
                                      pb=at, normal=(1.0, 0.0), driven=body))

    def stop_above(self, body: str, at: Point, travel: float) -> None:
        """A stop on the ground at ``at`` (a point of ``body``): the body may move right by at
        most ``travel`` from the design pose (its on position for a bar: ``S / 2``)."""
        ground = (at[0] + travel, at[1])
        self.part.joints.append(Joint(self._id("stop"), "contact", body, GROUND, pa=at,
                                      pb=ground, normal=(1.0, 0.0), driven=body))

    def groove(self, slot_body: str, pin_body: str, p0: Point, p1: Point, q: Point) -> None:
        """A pin at ``q`` on ``pin_body`` sliding in a straight slot from ``p0`` to ``p1`` on
        ``slot_body`` (all at the design pose)."""
        self.part.joints.append(Joint(self._id("groove"), "groove", slot_body, pin_body,
                                      p0=p0, p1=p1, q=q))

    def spring(self, body: str, at: Point, direction: int, preload: float, mass: float) -> None:
        """A tension spring to a ground anchor: ``direction`` -1 pulls the body towards off
        (lightest at off), +1 towards on (lightest at on). Preload is the force there (N);
        ``mass`` (the moving mass, :meth:`moving_mass`) sets its damping. The stiffness comes
        from ``ctx.spring_range`` (the force grows by that fraction over a stroke)."""
        S, c = self.ctx.stroke, self.ctx
        k = c.spring_range * preload / S
        rest = S  # the spring's own length at rest
        # distance at the lightest position gives the preload
        d_light = rest + preload / k
        x_light = at[0] + direction * S / 2  # the attachment point at the lightest position
        anchor = (x_light + direction * d_light, at[1])
        omega = math.sqrt(k * 1000.0 / max(mass, 1e-6))  # rad/s (k in N/m)
        damping = 2 * c.damping_ratio * mass * omega / 1000.0  # N s / mm
        # heaviest: a full stroke from the lightest position, and the over-travel past it
        f_max = preload + k * S * (1 + c.overtravel)
        self.part.springs.append(Spring(self._id("spring"), GROUND, body, anchor, at, k, rest,
                                        damping, preload, f_max, design_coil(k, f_max)))

    def terminal(self, pin: str, body: str, point: Point) -> None:
        """Make ``point`` of ``body`` the terminal ``pin``: at the design pose it is at half
        stroke, so off is ``S / 2`` to its left and on ``S / 2`` to its right."""
        S = self.ctx.stroke
        self.part.terminals[pin] = Terminal(pin, body, "translating",
                                            (point[0] - S / 2, point[1]),
                                            (point[0] + S / 2, point[1]))

    # ---- blocks -----------------------------------------------------------------------------
    def input_slider(self, pin: str, x0: float, y: float, length: float) -> Sig:
        """Input ``pin``: a slider from ``x0`` to ``x0 + length`` on row ``y`` whose left end
        is the input terminal (put inputs at ``x0 = 0``, rows going down from ``y = 0``)."""
        sig = self.slider(f"in_{pin}", x0, x0 + length, y, f"input {pin}")
        self.terminal(pin, sig.body, (x0, y))
        return sig

    def moving_mass(self, bodies: list[str]) -> float:
        """The summed mass of ``bodies`` (for a spring's damping)."""
        return sum(self.part.body(b).mass for b in bodies)

    def or_bar(self, local: str, sigs: list[Sig], x: float, demand: Demand,
               y_extra: list[float] = ()) -> tuple[Sig, list[Demand]]:
        """OR: a bar at ``x`` pushed on (right) by every signal in ``sigs`` through one-sided
        contacts, stopped at off and after over-travel, with a preloaded spring pulling it
        back to off. Its spring is sized by :meth:`size` for ``demand``, what the bar's output
        must move each way. ``y_extra``: more rows the bar must span (where it drives
        something). Returns the bar as a signal (tip on its right face; set ``.y`` to choose the
        output row) and what each input must then deliver, in the order of ``sigs``."""
        c, S, w = self.ctx, self.ctx.stroke, self.ctx.bar
        ys = [s.y for s in sigs] + list(y_extra)
        y_spring = self.spring_row(ys)
        bar = self.bar(local, x, min(ys), y_spring, "OR bar")
        for s in sigs:
            s2 = self.reach(s, x - w / 2)
            self.contact(s2.body, bar, (x - w / 2, s.y), (x - w / 2, s.y), driven=bar)
        y_top = max(ys) + w / 2
        self.stop_below(bar, (x, y_top), S / 2)  # off position
        self.stop_above(bar, (x, y_top), S / 2 + c.overtravel * S)  # over-travel
        self.bars[bar] = ("or", len(sigs), (x - w / 2, y_spring))
        return Sig(bar, x + w / 2, y_top), self.size(bar, demand)

    def and_bar(self, local: str, sigs: list[Sig], x: float, demand: Demand,
                y_extra: list[float] = ()) -> tuple[Sig, list[Demand]]:
        """AND: a bar at ``x`` sprung towards on, held back by a hook on every signal in
        ``sigs`` (it moves on only when all are on), stopped at on and after over-travel. The
        arguments and the result are those of :meth:`or_bar`."""
        c, S, w = self.ctx, self.ctx.stroke, self.ctx.bar
        ys = [s.y for s in sigs] + list(y_extra)
        y_spring = self.spring_row(ys)
        bar = self.bar(local, x, min(ys), y_spring, "AND bar")
        for s in sigs:
            s2 = self.reach(s, x + w / 2 + w)  # hook beyond the bar's right face
            hook = (x + w / 2, s.y)
            self.extend(s2.body, rect(x + w / 2, s.y - w, x + w / 2 + w, s.y + w))
            self.contact(bar, s2.body, hook, hook, driven=bar)
        y_top = max(ys) + w / 2
        self.stop_above(bar, (x, y_top), S / 2)  # on position
        self.stop_below(bar, (x, y_top), S / 2 + c.overtravel * S)  # over-travel
        self.bars[bar] = ("and", len(sigs), (x + w / 2, y_spring))
        return Sig(bar, x + w / 2, y_top), self.size(bar, demand)

    def spring_row(self, ys: list[float]) -> float:
        """A row above the inputs for the next bar's spring: springs lie on the base plate,
        each on its own row, so they never cross one another. Returns that row's y."""
        self.spring_rows = getattr(self, "spring_rows", 0) + 1
        return max(ys) + self.ctx.bar * (0.5 + 1.2 * self.spring_rows)

    def size(self, bar: str, demand: Demand) -> list[Demand]:
        """(Re)size a bar's spring for the force its output must deliver; returns what each of
        its inputs must then deliver. OR springs pull towards off, AND springs towards on.

        The forces are budgeted from the output back, but a cell is built from its inputs
        forward: a bar that drives another block inside the cell is made first with
        ``Demand()`` (nothing known yet). Once the block it drives is made and has returned
        its input loads, call ``size(bar.body, load)``: the bar's old spring is replaced (never
        added to) and the loads returned are the ones to pass on to :meth:`finish`. Example,
        two AND bars feeding an OR bar (the standard XOR)::

            bar1, _ = b.and_bar("bar1", [a, nb], x1, Demand())
            bar2, _ = b.and_bar("bar2", [bb, na], x2, Demand())
            bar3, (l1, l2) = b.or_bar("bar3", [bar1, bar2], x3, demand)
            la, lnb = b.size(bar1.body, l1)  # now bar1 knows what it must push
            lb, lna = b.size(bar2.body, l2)
        """
        c = self.ctx
        kind, n, at = self.bars[bar]
        self.part.springs[:] = [s for s in self.part.springs if s.b != bar]
        need = self.part.data.setdefault("spring_required_N", {})
        if kind == "or":
            preload = max(c.min_preload, c.margin * (demand.left + c.friction))
            self.spring(bar, at, -1, preload, self.moving_mass([bar]))
            need[self.part.springs[-1].id] = round(demand.left + c.friction, 6)
            peak = preload * (1 + c.spring_range)
            return [Demand(peak + demand.right + c.friction, 0.0) for _ in range(n)]
        preload = max(c.min_preload, c.margin * (demand.right + c.friction))
        self.spring(bar, at, +1, preload, self.moving_mass([bar]))
        need[self.part.springs[-1].id] = round(demand.right + c.friction, 6)
        peak = preload * (1 + c.spring_range)
        return [Demand(0.0, peak + demand.left + c.friction) for _ in range(n)]

    def rod(self, a: str, b: str, pa: Point, pb: Point) -> None:
        """A rigid rod pinned to point ``pa`` of body ``a`` and ``pb`` of body ``b``; its
        length is their distance at the design pose."""
        length = math.hypot(pb[0] - pa[0], pb[1] - pa[1])
        self.part.joints.append(Joint(self._id("rod"), "rod", a, b, pa=pa, pb=pb,
                                      length=length))

    def not_lever(self, local: str, sig: Sig, x: float, y_top: float, demand: Demand,
                  out_length: float, layer: int = 2) -> tuple[Sig, Demand]:
        """NOT: a lever pivoted at its centre, linked by a short rod at its top to ``sig``
        (at row ``y_top``) and by another at its bottom to a new slider two arms lower, which
        therefore moves opposite (Fig. 16c: a ternary link with binary links to the sliders).

        ``x`` is the lever's axis, ``out_length`` the new slider's length and ``layer`` the
        lever's plane (use another for a second lever that crosses the first). Returns the new
        slider as a signal (its row is ``y_top - 2 * ctx.arm``) and what ``sig`` must deliver:
        ``demand`` mirrored (right and left swap) plus friction."""
        c, S, w, r = self.ctx, self.ctx.stroke, self.ctx.bar, self.ctx.arm
        link = 0.8 * S
        pivot = (x, y_top - r)
        y_out = y_top - 2 * r
        pin_in = (x - link, y_top)
        sig2 = self.reach(sig, pin_in[0] + w / 2)
        lever_poly = rect(x - w / 2, y_top + w / 2, x + w / 2, y_out - w / 2)
        lever = self.name(local)
        self.part.bodies.append(Body(lever, "lever", [lever_poly], c.mass([lever_poly]),
                                     pivot=pivot, layer=layer, role="NOT lever"))
        self.rod(sig2.body, lever, pin_in, (x, y_top))
        x_out = x + link
        out = self.slider(f"{local}_out", x_out - w / 2, x_out - w / 2 + out_length, y_out,
                          "NOT output")
        self.rod(lever, out.body, (x, y_out), (x_out, y_out))
        return out, Demand(demand.left + c.friction, demand.right + c.friction)

    def output(self, sig: Sig, pin: str = "Z", reach: float | None = None) -> Sig:
        """Put the output terminal at the right end of ``sig`` (lengthened to ``reach``)."""
        if reach is not None:
            sig = self.reach(sig, reach)
        self.terminal(pin, sig.body, (sig.x, sig.y))
        return sig

    def finish(self, demands: dict[str, Demand]) -> Part:
        """The cell's part, with what each input pin must deliver (``{pin: Demand}``)
        recorded in ``data["input_loads"]`` for the compiler's force budget; return it from
        ``synthesise``."""
        self.part.data["input_loads"] = {k: v.to_json() for k, v in demands.items()}
        return self.part
