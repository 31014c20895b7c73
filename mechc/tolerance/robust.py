"""Robust design: compile, measure the yield, and change what the failing checks point at
until the yield is met (``mechc compile --tol MM --yield F``).

What each failing check asks for:

- *spring force margin* (a spring weak by its tolerance in rate and preload): design the
  springs with more margin, enough that one at the bottom of both tolerances still holds 1.15 x
  what it must move: 1.15 / (1 - spring_tol)^2, 3 % over;
- *unsolvable states* (a bar jammed between a lug and its over-travel stop, which sits only a
  little beyond the working range): move the over-travel stops out, 2 % of the stroke a round;
- *output at rest / dwell* in samples where nothing binds (positions scattered beyond the
  proof's allowance, which is a fraction of the stroke while the tolerances are millimetres),
  in more than half the samples the target lets fail: a longer stroke, 25 % a round (every
  part scales with it);
- *SET and RESET together* (a MEMORY binds: its two faces overlap by the tolerances): a
  longer stroke too;
- *transmission angle* at a threshold generator (its separator designed to meet 45 deg
  exactly, which half the samples then miss): ask the generators' synthesis for the angle the
  samples lost beyond the limit, plus a degree, as margin (``angle_margin``: the separator's
  proportions change);
- *transmission angle* elsewhere, *distance from toggle*: angles do not change with scale,
  and other cells' proportions are their own design: reported, not cured.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np

from mechc.cells.library import Library
from mechc.ir.design import Design
from mechc.ir.spec import Spec
from mechc.pipeline import CompileOptions, compile_spec
from mechc.tolerance.batch import DWELL, REST
from mechc.tolerance.montecarlo import Failing, ToleranceResult, ToleranceSettings, run
from mechc.tolerance.sequential import JAM as MEMORY_BINDS

MAX_ROUNDS = 6
MAX_OVERTRAVEL = 0.12
MAX_STROKE_FACTOR = 3.0
MAX_ANGLE_MARGIN = 15.0  # degrees beyond the 45 degree limit a generator is asked for
SPRING_CHECK = 1.15  # the spring force margin design check (mechc.physics.measures)
JAM = "unsolvable states (binding or cannot assemble)"


@dataclass
class Round:
    stroke: float
    spring_margin: float
    overtravel: float
    angle_margin: float
    result: ToleranceResult
    change: str  # what the next round changes, and why ("" on the last)


def robust_compile(spec: Spec, opts: CompileOptions, lib: Library, s: ToleranceSettings,
                   progress: Callable[[str], None] | None = None
                   ) -> tuple[Design, list[Round], bool]:
    """The design that meets ``s.yield_level`` (or the last tried), every round, and whether
    the target was met."""
    mech = opts.mech
    stroke, margin, over = mech.stroke, mech.spring_margin, mech.overtravel
    angle = mech.angle_margin
    rounds: list[Round] = []
    for _ in range(MAX_ROUNDS):
        o = replace(opts, mech=replace(mech, stroke=stroke, spring_margin=margin,
                                       overtravel=over, angle_margin=angle))
        design = compile_spec(spec, o, lib)
        r = run(design, lib, s)
        rounds.append(Round(stroke, margin, over, angle, r, ""))
        if progress is not None:
            progress(f"stroke {stroke:g} mm, spring margin {margin:.3g}, over-travel "
                     f"{over:.0%}, angle margin {angle:g} deg: yield {r.yield_:.2%}")
        if r.yield_ >= s.yield_level:
            return design, rounds, True
        names: dict[str, Failing] = {}
        for f in r.failing:  # the most frequent place of each check
            names.setdefault(f.key.name, f)
        none = np.zeros(r.samples, dtype=bool)
        jammed = r.fails.get(JAM, none)
        why = []
        if "spring force margin" in names:
            need = round(SPRING_CHECK / (1 - s.spring_tol) ** 2 * 1.03, 3)
            new = max(need, margin + 0.05)
            why.append(f"spring margin {margin:.3g} -> {new:.3g} (springs weak by "
                       f"{s.spring_tol:.0%} fail in {names['spring force margin'].count} "
                       "samples)")
            margin = new
        if jammed.any() and over < MAX_OVERTRAVEL:
            why.append(f"over-travel stops {over:.0%} -> {over + 0.02:.0%} of stroke (parts "
                       f"bind in {int(jammed.sum())} samples)")
            over = round(over + 0.02, 4)
        # outputs off where nothing binds: scattered beyond the allowance; a longer stroke
        # when that alone would spend half the yield the target leaves
        off = (r.fails.get(REST, none) | r.fails.get(DWELL, none)) & ~jammed
        # a MEMORY whose SET and RESET faces overlap by the tolerances: the faces' errors
        # shrink against a longer stroke
        off |= r.fails.get(MEMORY_BINDS, none)
        if off.sum() > (1 - s.yield_level) * r.samples / 2 \
                and stroke < mech.stroke * MAX_STROKE_FACTOR:
            why.append(f"stroke {stroke:g} -> {stroke * 1.25:g} mm (outputs off where "
                       f"nothing binds, or a MEMORY's SET and RESET overlap, in "
                       f"{int(off.sum())} samples)")
            stroke = round(stroke * 1.25, 3)
        generators = {c.id for c in design.netlist.cells.values() if c.cell == "threshold"}
        low = [f for f in r.failing if f.key.name == "transmission angle"
               and f.key.where in generators and np.isfinite(f.worst)]
        if low and angle < MAX_ANGLE_MARGIN:
            short = max(f.key.limit - f.worst for f in low)
            new = min(MAX_ANGLE_MARGIN, float(np.ceil(angle + short + 1.0)))
            why.append(f"angle margin {angle:g} -> {new:g} deg (threshold generators' "
                       f"transmission angle down to {min(f.worst for f in low):.3g} deg "
                       f"in {max(f.count for f in low)} samples)")
            angle = new
        if not why:  # nothing this loop can change (other angles) or every limit reached
            return design, rounds, False
        rounds[-1].change = "; ".join(why)
    return design, rounds, False
