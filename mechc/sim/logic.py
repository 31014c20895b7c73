"""Logic level: evaluate the netlist's cells on every input vector and compare with the spec."""

from __future__ import annotations

import time

import numpy as np

from mechc.errors import UsageError
from mechc.logic.cubes import DC, MAX_TABLE_INPUTS, input_matrix
from mechc.netlist.ir import Netlist
from mechc.spec.model import Spec

MAX_LISTED_FAILURES = 50


def check_interface(nl: Netlist, spec: Spec) -> None:
    if set(nl.inputs) != set(spec.inputs):
        raise UsageError(f"design inputs ({' '.join(nl.inputs)}) differ from the spec's "
                         f"({' '.join(spec.inputs)})")
    missing = [o for o in spec.outputs if o not in nl.outputs]
    if missing:
        raise UsageError(f"spec output(s) {', '.join(missing)} not in the design (design outputs:"
                         f" {' '.join(nl.outputs)})")


def prove_logic(nl: Netlist, spec: Spec) -> dict:
    t0 = time.perf_counter()
    check_interface(nl, spec)
    if spec.n > MAX_TABLE_INPUTS:
        raise UsageError(f"{spec.n} inputs: exhaustive logic proof supports up to "
                         f"{MAX_TABLE_INPUTS}")
    n = spec.n
    m = input_matrix(n)
    env = {name: m[k] for k, name in enumerate(spec.inputs)}
    nets = nl.evaluate(env)
    failures = []
    total_bad = 0
    care_cases = 0
    for o in spec.outputs:
        want = spec.table(o)
        got = nets[nl.outputs[o]]
        care = want != DC
        care_cases += int(care.sum())
        bad = np.flatnonzero(care & (got != (want == 1)))
        total_bad += len(bad)
        for row in bad[:MAX_LISTED_FAILURES - len(failures)]:
            failures.append({
                "output": o,
                "inputs": {name: int(m[k, row]) for k, name in enumerate(spec.inputs)},
                "expected": int(want[row]),
                "got": int(got[row]),
            })
    return {
        "passed": total_bad == 0,
        "level": "logic",
        "cases": 1 << n,
        "care_checks": care_cases,
        "failure_count": total_bad,
        "failures": failures,
        "seconds": round(time.perf_counter() - t0, 6),
    }
