"""AMPLIFIER figures: switching delay, largest fan-out, seconds per dynamic switch.

    python benchmarks/amplifier.py [--kmax 6]

Delay: from the input reaching 95 % of its stroke to the output within 5 % of its new end,
standalone cell, default context (stroke 20 mm) and DynSettings. Fan-out: the largest k for
which an amplifier driving k OR inputs (the other input of each OR tied to a CONST 0) passes
prove_dynamic (tour + 5 random changes). Speed: wall seconds per switch of the amplifier scene,
as a ratio to a switch of a lone OR cell measured in the same run.
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from scipy.optimize import brentq

from mechc.cells.library import load_library
from mechc.frontends.boolfile import parse_bool
from mechc.ir.netlist import CellInst, Netlist
from mechc.physics.scene import DynSettings, Scene, min_jerk
from mechc.pipeline import compile_netlist
from mechc.proofs.dynamic import prove_dynamic

LIB = load_library()


def alone(cell: str, type_: str, pins: list[str], text: str):
    nl = Netlist(["a", "b"][: len(pins)])
    nl.add_cell(CellInst("c1", cell, type_, tuple(nl.inputs), ("z",)), pin_names=pins)
    nl.set_output("z", "z")
    spec = parse_bool(f"inputs {' '.join(nl.inputs)}\noutputs z\n{text}\n")
    return compile_netlist(spec, nl, library=LIB)


def fanout(k: int):
    nl = Netlist(["a"])
    nl.add_cell(CellInst("amp", "amplifier", "AMPLIFIER", ("a",), ("y",)), pin_names=["A"])
    nl.add_cell(CellInst("k0", "const", "CONST", (), ("zero",), {"value": 0}), pin_names=[])
    outs = []
    for i in range(k):
        nl.add_cell(CellInst(f"or{i}", "or", "OR", ("y", "zero"), (f"z{i}",)),
                    pin_names=["A", "B"])
        nl.set_output(f"z{i}", f"z{i}")
        outs.append(f"z{i}")
    spec = parse_bool("inputs a\noutputs " + " ".join(outs) + "\n"
                      + "".join(f"{o} = a\n" for o in outs))
    return compile_netlist(spec, nl, library=LIB)


def switch_delays(design, moves=(1, 0, 1, 0)) -> tuple[list[float], float]:
    st = DynSettings()
    types = {c.id: c.cell for c in design.netlist.cells.values()}
    sc = Scene.build(design.mechanism, LIB, types, st, {n: 0.0 for n in design.netlist.inputs})
    t_in = st.move_time * brentq(lambda x: float(min_jerk(x)) - 0.95, 0.0, 1.0)
    delays, t0 = [], time.perf_counter()
    for target in moves:
        r = sc.move("a", float(target))
        z = r.outputs["z"]
        near = np.flatnonzero(np.abs(z - target) <= 0.05)
        delays.append(float(r.t[near[0]] - t_in) if len(near) else float("inf"))
    return delays, (time.perf_counter() - t0) / len(moves)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--kmax", type=int, default=6)
    args = ap.parse_args()
    amp = alone("amplifier", "AMPLIFIER", ["A"], "z = a")
    delays, per_amp = switch_delays(amp)
    _, per_or = switch_delays(alone("or", "OR", ["A", "B"], "z = a | b"))
    print(f"switching delay on  (s): {max(delays[0::2]):.4f}")
    print(f"switching delay off (s): {max(delays[1::2]):.4f}")
    print(f"seconds per dynamic switch: amplifier {per_amp:.3f}, lone OR {per_or:.3f}, "
          f"ratio {per_amp / per_or:.2f}")
    best = 0
    for k in range(1, args.kmax + 1):
        t0 = time.perf_counter()
        d = fanout(k)
        r = prove_dynamic(d, d.spec, LIB, extra=5)
        print(f"fan-out {k}: {'pass' if r['passed'] else 'FAIL'} {r['failure_kinds']} "
              f"max settle {r['max_settle_time_s']} s, {time.perf_counter() - t0:.1f} s")
        if r["passed"] and best == k - 1:
            best = k
    print(f"fanout_max: {best}")


if __name__ == "__main__":
    main()
