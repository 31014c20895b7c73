"""Logic level: evaluate the netlist's cells on input vectors and compare with the spec.

Up to ``MAX_TABLE_INPUTS`` inputs every vector is checked. Wider specs (PLAs of up to 117
inputs) cannot be enumerated, so the check is a sample and says so (``exhaustive: false``):
every point of each spec cube with few free inputs, random points inside the larger cubes, the
points just outside each cube (one literal flipped) and uniformly random vectors, all seeded so
a report can be reproduced.
"""

from __future__ import annotations

import time

import numpy as np

from mechc.cells.library import Library
from mechc.errors import UsageError
from mechc.ir.design import Design
from mechc.ir.netlist import Netlist
from mechc.ir.spec import Spec
from mechc.logic.cubes import DC, MAX_TABLE_INPUTS, Cube, input_matrix
from mechc.proofs.registry import OnProgress, check_interface, engine
from mechc.proofs.report import LOGIC_FIGURES, ProofReport
from mechc.proofs.settings import ProofSettings

MAX_LISTED_FAILURES = 50
#: Wide specs: cubes with at most this many free inputs have every point checked.
CORNER_FREE_MAX = 8
#: Wide specs: cap on vectors taken from spec cubes; past it each cube gives a few points.
MAX_CUBE_VECTORS = 1 << 18
#: Wide specs: random points inside each cube too large to enumerate.
POINTS_PER_CUBE = 32
#: Wide specs: uniformly random vectors.
RANDOM_VECTORS = 1 << 16
#: Wide specs: corners per cube whose neighbours just outside it (one literal flipped) are
#: checked too; a netlist that lost a literal differs from the spec exactly there.
NEIGHBOUR_CORNERS = 4


@engine("logic", "combinational")
def logic_engine(design: Design, spec: Spec, lib: Library, settings: ProofSettings,
                 progress: OnProgress | None) -> ProofReport:
    # the sampled check of a wide spec keeps seed 0, as ``mechc simulate`` always has
    return prove_logic(design.netlist, spec)


def prove_logic(nl: Netlist, spec: Spec, seed: int = 0) -> ProofReport:
    t0 = time.perf_counter()
    check_interface(nl, spec)
    if spec.n > MAX_TABLE_INPUTS:
        return _check_sampled(nl, spec, t0, seed)
    n = spec.n
    m = input_matrix(n)
    env = {name: m[k] for k, name in enumerate(spec.inputs)}
    nets = nl.evaluate(env)
    wants = {o: spec.table(o) for o in spec.outputs}
    failures, total_bad, care_cases = _compare(nl, spec, nets, wants, env)
    return ProofReport(
        level="logic", kind="combinational", passed=total_bad == 0, cases=1 << n,
        coverage={"exhaustive": True, "care_checks": care_cases},
        failure_count=total_bad, failures=failures, figures=dict(LOGIC_FIGURES),
        seconds=round(time.perf_counter() - t0, 6))


def _compare(nl: Netlist, spec: Spec, nets: dict, wants: dict[str, np.ndarray],
             inputs: dict[str, np.ndarray]) -> tuple[list[dict], int, int]:
    """Netlist outputs against the spec's values on every care row: (listed failures, failure
    count, care rows checked)."""
    failures: list[dict] = []
    total_bad = care_cases = 0
    for o in spec.outputs:
        want, got = wants[o], nets[nl.outputs[o]]
        care = want != DC
        care_cases += int(care.sum())
        bad = np.flatnonzero(care & (got != (want == 1)))
        total_bad += len(bad)
        for row in bad[:MAX_LISTED_FAILURES - len(failures)]:
            failures.append({
                "output": o,
                "inputs": {name: int(inputs[name][row]) for name in spec.inputs},
                "expected": int(want[row]),
                "got": int(got[row]),
            })
    return failures, total_bad, care_cases


def _check_sampled(nl: Netlist, spec: Spec, t0: float, seed: int) -> ProofReport:
    """Compare netlist and spec on cube points and random vectors (n too large to enumerate)."""
    n = spec.n
    for o in spec.outputs:
        if spec.functions[o].expr is not None:
            raise UsageError(f"output {o}: an expression over {n} inputs cannot be checked "
                             f"(more than {MAX_TABLE_INPUTS} inputs need a cube spec)")
    rng = np.random.default_rng(seed)
    cubes = sorted({c for o in spec.outputs for f in [spec.functions[o]]
                    for c in (*f.on, *f.dc, *f.off)})
    from_cubes = _cube_vectors(cubes, n, rng)
    randoms = [rng.integers(0, 1 << 62, size=RANDOM_VECTORS, dtype=np.int64).tolist()
               for _ in range((n + 61) // 62)]
    vec = set(from_cubes)
    for parts in zip(*randoms):
        x = 0
        for k, part in enumerate(parts):
            x |= part << (62 * k)
        vec.add(x & ((1 << n) - 1))
    vectors = sorted(vec)
    X = _words(vectors, n)
    values = {name: _position(X, n - 1 - k) for k, name in enumerate(spec.inputs)}
    nets = nl.evaluate(values)
    wants = {}
    for o in spec.outputs:
        f = spec.functions[o]
        want = np.full(len(vectors), f.rest, dtype=np.int8)
        want[_member(X, f.off, n)] = 0
        want[_member(X, f.on, n)] = 1
        want[_member(X, f.dc, n)] = DC
        wants[o] = want
    failures, total_bad, care_cases = _compare(nl, spec, nets, wants, values)
    sampling = {"cube_vectors": len(from_cubes), "random_vectors": RANDOM_VECTORS,
                "corner_free_max": CORNER_FREE_MAX, "seed": seed}
    return ProofReport(
        level="logic", kind="combinational", passed=total_bad == 0, cases=len(vectors),
        coverage={"exhaustive": False, "sampling": sampling, "care_checks": care_cases},
        failure_count=total_bad, failures=failures, figures=dict(LOGIC_FIGURES),
        seconds=round(time.perf_counter() - t0, 6))


def _cube_vectors(cubes: list[Cube], n: int, rng: np.random.Generator) -> set[int]:
    """Every point of each cube with few free inputs (while the budget lasts), else samples;
    and for a few corners of every cube, its neighbours across each literal."""
    out: set[int] = set()
    full = (1 << n) - 1
    for c in cubes:
        free = [b for b in range(n) if not c.mask >> b & 1]
        if len(free) <= CORNER_FREE_MAX and len(out) + (1 << len(free)) <= MAX_CUBE_VECTORS:
            pts = [c.value]
            for b in free:
                pts += [p | 1 << b for p in pts]
            out.update(pts)
            continue
        for _ in range(POINTS_PER_CUBE if len(out) < MAX_CUBE_VECTORS else 2):
            r = int.from_bytes(rng.bytes((n + 7) // 8), "little") & full
            out.add((r & ~c.mask) | c.value)
    for c in cubes:
        if len(out) >= 2 * MAX_CUBE_VECTORS:
            break
        fixed = [1 << b for b in range(n) if c.mask >> b & 1]
        for k in range(NEIGHBOUR_CORNERS):
            if k < 2:  # free inputs all 0, all 1, then random
                corner = c.value | (0 if k == 0 else full & ~c.mask)
            else:
                corner = (int.from_bytes(rng.bytes((n + 7) // 8), "little") & full & ~c.mask) \
                    | c.value
            out.update(corner ^ bit for bit in fixed)
    return out


def _words(vectors: list[int], n: int) -> np.ndarray:
    """Vectors as (N, W) uint64 words (bit position p of the integer in word p // 64)."""
    W = max(1, (n + 63) // 64)
    mask = (1 << 64) - 1
    return np.array([[(v >> (64 * w)) & mask for w in range(W)] for v in vectors],
                    dtype=np.uint64).reshape(len(vectors), W)


def _position(X: np.ndarray, p: int) -> np.ndarray:
    return ((X[:, p // 64] >> np.uint64(p % 64)) & np.uint64(1)).astype(bool)


def _member(X: np.ndarray, cubes: list[Cube], n: int) -> np.ndarray:
    """Which rows of X lie in the union of ``cubes``."""
    out = np.zeros(len(X), dtype=bool)
    if not cubes:
        return out
    words = _words([c.mask for c in cubes], n), _words([c.value for c in cubes], n)
    for m, v in zip(*words):
        out |= ((X & m) == v).all(axis=1)
    return out
