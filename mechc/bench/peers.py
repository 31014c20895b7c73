"""Peers in the same run: the kinematic level against pylinkage on one four-bar
(:mod:`mechc.bench.fourbar`), and the dynamic level against a bare pymunk scene of the same
bodies and joints.

``python -m mechc.bench.peers`` runs the four-bar figures alone (seconds, not the whole speed
benchmark) and ends in the same ``name: value`` lines.

The headline ratios come from :func:`paired`: mechc and pylinkage timed in alternating rounds
of the same process, a ratio per round, the median kept. On a shared machine a burst of load
that lands on one side of one measurement moves a best-of-each-side ratio (3.18 in one such
run); it moves one round of many here, and the median leaves it out.
"""

from __future__ import annotations

import math
import statistics
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from mechc.bench.circuits import Circuit
from mechc.bench.fourbar import (
    _chunks,
    compare,
    mechc_rocker_pins,
    mechc_rocker_pins_reduced,
    pylinkage_linkage,
)
from mechc.bench.harness import Bench, clock, scene_types
from mechc.physics.scene import Scene
from mechc.proofs.settings import dyn_settings


def peers(b: Bench, c: Circuit) -> None:
    b.say("\n== peers in the same run ==")
    fourbar_peers(b)
    dynamic_peer(b, c)


#: Alternating rounds of the paired measure, and calls of each side per round (the best kept):
#: a round is about 0.2 s on an idle machine.
ROUNDS = 11
INNER = 2


def alternate(fns: dict[str, Callable[[], object]], rounds: int, inner: int = 1,
              clock: Callable[[], float] = time.process_time) -> dict[str, list[float]]:
    """Seconds of each of ``fns`` in each of ``rounds`` rounds (the best of ``inner`` calls in
    a row: the least disturbed), one after another within a round and the order turned by
    one each round (none always first or last, where a change of load between rounds would
    land on it alone)."""
    names = list(fns)
    out: dict[str, list[float]] = {k: [] for k in names}
    for r in range(rounds):
        k = r % len(names)
        for name in names[k:] + names[:k]:
            best = math.inf
            for _ in range(inner):
                t0 = clock()
                fns[name]()
                best = min(best, clock() - t0)
            out[name].append(best)
    return out


@dataclass
class Paired:
    """Per-round ratios of pylinkage's seconds to mechc's on the same positions."""

    checked: list[float]  # kinematic_vs_pylinkage: solve and pins, checks on every state
    reduced: list[float]  # and the checks reduced to their figures on every chunk

    @staticmethod
    def of(seconds: dict[str, list[float]]) -> Paired:
        peer = seconds["pylinkage"]
        return Paired([p / m for p, m in zip(peer, seconds["mechc"])],
                      [p / m for p, m in zip(peer, seconds["mechc reduced"])])


def paired(n: int = 200_000, rounds: int = ROUNDS, inner: int = INNER) -> Paired:
    """mechc's four-bar (in chunks of ``CHUNK`` states, the chunk a proof solves at once, as
    ``compare``) and pylinkage's numba ``step_fast`` on ``n`` crank positions each, in
    alternating rounds (CPU seconds, each side's best of ``inner`` calls per round)."""
    th = np.linspace(0.0, 2 * math.pi, n, endpoint=False)
    lk = pylinkage_linkage(n)
    lk.step_fast(iterations=100)  # compile
    mechc_rocker_pins(th[:1000])  # warm

    def peer() -> None:
        if not np.isfinite(lk.step_fast(iterations=n)).all():
            raise AssertionError("pylinkage's step_fast gave non-finite positions")

    return Paired.of(alternate({"mechc": lambda: _chunks(mechc_rocker_pins, th),
                                "mechc reduced": lambda: _chunks(mechc_rocker_pins_reduced,
                                                                 th),
                                "pylinkage": peer}, rounds, inner))


def fourbar_peers(b: Bench) -> None:
    """The kinematic level against pylinkage on one four-bar, and the positions-only floors
    (``kinematic_vs_pylinkage`` and the figures beside it)."""
    try:
        r = compare()
    except ModuleNotFoundError as e:
        b.say(f"pylinkage is not installed ({e}); pip install -e '.[bench]'")
        b.summary["kinematic_vs_pylinkage"] = "n/a"
    else:
        fast = r.pylinkage_fast_per_s
        best_peer = max(r.pylinkage_step_per_s, fast or 0.0)
        b.say(f"four-bar: mechc closed form {r.mechc_per_s:,.0f} positions/s; pylinkage "
              f"Linkage.step {r.pylinkage_step_per_s:,.0f}/s, step_fast ({r.pylinkage_backend}) "
              f"{fast or float('nan'):,.0f}/s; rocker pins agree to "
              f"{r.max_difference_mm:.1e} mm")
        kernel = r.numba_kernel_per_s
        b.say(f"floors on the same four-bar, positions only (no angle, transmission, flags or "
              f"closure check): numpy {r.bare_numpy_per_s:,.0f}/s = "
              f"{r.bare_numpy_per_s / best_peer:.2f}x pylinkage's best; compiled scalar loop "
              + (f"{kernel:,.0f}/s = {kernel / best_peer:.2f}x" if kernel else "n/a (no numba)"))
        if fast:  # the compiled peer is the faster one: pair the two (see ``paired``)
            pr = paired()
            b.say(f"alternating rounds against step_fast ({len(pr.checked)}): mechc "
                  f"{min(pr.checked):.2f}-{max(pr.checked):.2f}x, with the checks reduced "
                  f"{min(pr.reduced):.2f}-{max(pr.reduced):.2f}x (medians below)")
            b.summary["kinematic_vs_pylinkage"] = round(statistics.median(pr.checked), 3)
            b.summary["kinematic_vs_pylinkage_min"] = round(min(pr.checked), 3)
            # the same with the checks reduced to their figures on every chunk, as a proof does
            b.summary["kinematic_reduced_vs_pylinkage"] = round(statistics.median(pr.reduced),
                                                                3)
            b.summary["kinematic_reduced_vs_pylinkage_min"] = round(min(pr.reduced), 3)
        else:  # only the Python API: its rate is far below, one measure of each is enough
            b.summary["kinematic_vs_pylinkage"] = round(r.mechc_per_s / best_peer, 3)
            b.summary["kinematic_reduced_vs_pylinkage"] = round(
                r.mechc_reduced_per_s / best_peer, 3)
        b.summary["positions_only_numpy_vs_pylinkage"] = round(r.bare_numpy_per_s / best_peer, 3)
        if kernel:
            b.summary["positions_only_compiled_vs_pylinkage"] = round(kernel / best_peer, 3)
        b.summary["kinematic_vs_pylinkage_step"] = round(r.mechc_per_s / r.pylinkage_step_per_s,
                                                         2)
        b.summary["pylinkage_backend"] = r.pylinkage_backend
        b.summary["fourbar_positions_per_s"] = round(r.mechc_per_s)
        for lvl, rate in (("mechc", r.mechc_per_s), ("pylinkage step", r.pylinkage_step_per_s),
                          ("pylinkage step_fast", fast),
                          ("positions only, numpy", r.bare_numpy_per_s),
                          ("positions only, compiled", kernel)):
            b.row(section="fourbar", circuit="four-bar", level=lvl, cases=r.positions,
                  seconds=(r.positions / rate) if rate else "",
                  error_fraction=r.max_difference_mm)


def dynamic_peer(b: Bench, c: Circuit) -> None:
    """The dynamic level against a bare pymunk scene of the same bodies and joints."""
    d = c.design
    st = dyn_settings(d)
    name = d.spec.inputs[0]
    sc = Scene.build(d.mechanism, b.lib, scene_types(d), st, {k: 0.0 for k in d.spec.inputs})
    t0 = clock()
    r = sc.move(name, 1.0)
    t_mechc = clock() - t0
    bare = Scene.build(d.mechanism, b.lib, scene_types(d), st, {k: 0.0 for k in d.spec.inputs})
    t0 = clock()
    for _ in range(r.steps):
        bare.space.step(st.dt)
    t_bare = clock() - t0
    joints = len(sc.space.constraints)
    per_mechc = t_mechc / (r.steps * joints)
    per_bare = t_bare / (r.steps * joints)
    b.say(f"dynamic ({c.name}, {joints} constraints, {r.steps} steps): "
          f"{per_mechc * 1e9:.0f} ns per joint-step with mechc's measuring and driving, "
          f"{per_bare * 1e9:.0f} ns bare pymunk")
    b.summary["dynamic_vs_bare_pymunk"] = round(per_mechc / per_bare, 3)
    b.row(section="joint_step", circuit=c.name, level="dynamic", variant="mechc",
          steps=r.steps, seconds=t_mechc)
    b.row(section="joint_step", circuit=c.name, level="dynamic", variant="bare pymunk",
          steps=r.steps, seconds=t_bare)



def main() -> int:
    """The four-bar peer figures alone."""
    from mechc.cells.library import load_library

    b = Bench(load_library(), quick=True)
    fourbar_peers(b)
    for k, v in b.summary.items():
        print(f"{k}: {v}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
