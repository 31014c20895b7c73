"""Logic level: the netlist's cells against the spec on every input vector.

Three methods (:func:`choose_method` picks one unless told): ``exhaustive`` evaluates every
vector (small designs: up to ``EXHAUSTIVE_MAX_INPUTS`` inputs always, up to
``MAX_TABLE_INPUTS`` while cells x vectors stays within ``EXHAUSTIVE_WORK``); ``sat`` proves
the same over all 2**n vectors with a SAT miter (:mod:`mechc.proofs.sat_equiv`), for designs
too wide to enumerate; ``sampled`` is the check of old for wide specs, kept as the fallback
when a cell has no CNF form and on request: every point of each spec cube with few free
inputs, random points inside the larger cubes, the points just outside each cube (one literal
flipped) and uniformly random vectors, all seeded, and it says so (``exhaustive: false``).
"""

from __future__ import annotations

import time

import numpy as np

from mechc.cells.library import Library
from mechc.errors import UsageError
from mechc.ir import expr as ex
from mechc.ir.design import Design
from mechc.ir.netlist import Netlist
from mechc.ir.spec import Spec
from mechc.logic.cubes import DC, MAX_TABLE_INPUTS, Cube, input_matrix
from mechc.proofs.registry import OnProgress, check_interface, engine
from mechc.proofs.report import LOGIC_FIGURES, ProofReport
from mechc.proofs.sat_equiv import (
    EXAMPLES_PER_OUTPUT,
    NotEncodable,
    check_equivalence,
    confirmed_failures,
)
from mechc.proofs.settings import LOGIC_METHODS, ProofSettings

MAX_LISTED_FAILURES = 50
#: Up to this many inputs every vector is evaluated, whatever the design's size.
EXHAUSTIVE_MAX_INPUTS = 14
#: Beyond EXHAUSTIVE_MAX_INPUTS (and up to MAX_TABLE_INPUTS), exhaustive while (cells + spec
#: nodes and cubes) x vectors stays within this (about a second of numpy, a few hundred MB of
#: nets), else SAT. Measured (docs/performance.md): t481 (16 inputs, 1300 cells) 0.19 s
#: exhaustive against 2.6 s by SAT; a 10-bit adder (20 inputs, 47 cells, its spec as
#: expressions) 4.2 s exhaustive against 0.05 s by SAT.
EXHAUSTIVE_WORK = 1 << 28
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
    return prove_logic(design.netlist, spec, method=settings.logic_method)


def choose_method(nl: Netlist, spec: Spec) -> str:
    """``exhaustive`` where enumerating every vector is cheap, else ``sat``."""
    n = spec.n
    if n <= EXHAUSTIVE_MAX_INPUTS:
        return "exhaustive"
    if n <= MAX_TABLE_INPUTS and (len(nl.cells) + spec_size(spec) + n) << n <= EXHAUSTIVE_WORK:
        return "exhaustive"
    return "sat"


def spec_size(spec: Spec) -> int:
    """Expression nodes and cubes of the spec: what building its tables costs per vector."""
    def nodes(e: ex.Expr) -> int:
        return 1 + sum(nodes(a) for a in getattr(e, "args", ())) + \
            (nodes(e.arg) if isinstance(e, ex.Not) else 0)

    if spec.network is not None:
        return sum(len(nd.cubes) + 1 for nd in spec.network.nodes)
    return sum((nodes(f.expr) if f.expr is not None else len(f.on)) + len(f.dc) + len(f.off)
               for f in spec.functions.values())


def prove_logic(nl: Netlist, spec: Spec, seed: int = 0, method: str = "auto") -> ProofReport:
    """The logic proof by ``method`` (one of ``LOGIC_METHODS``; ``auto``: :func:`choose_method`).
    A SAT proof of a netlist with a cell that has no CNF form falls back to sampling (wide
    specs) or enumeration, and the report says why (``coverage.sat_refused``)."""
    t0 = time.perf_counter()
    check_interface(nl, spec)
    if method not in LOGIC_METHODS:
        raise UsageError(f"no logic method {method!r} (methods: {', '.join(LOGIC_METHODS)})")
    if method == "auto":
        method = choose_method(nl, spec)
    if method == "exhaustive" and spec.n > MAX_TABLE_INPUTS:
        raise UsageError(f"{spec.n} inputs cannot be enumerated (at most {MAX_TABLE_INPUTS}): "
                         "prove by sat or sampled")
    refused = None
    if method == "sat":
        try:
            return _check_sat(nl, spec, t0)
        except NotEncodable as e:
            refused = str(e)
            method = "exhaustive" if spec.n <= MAX_TABLE_INPUTS else "sampled"
    if method == "sampled":
        rep = _check_sampled(nl, spec, t0, seed)
    else:
        rep = _check_exhaustive(nl, spec, t0)
    if refused:
        rep.coverage["sat_refused"] = refused
    return rep


def _check_sat(nl: Netlist, spec: Spec, t0: float) -> ProofReport:
    """Every vector at once: a miter of netlist and spec, and its counterexamples."""
    eq = check_equivalence(nl, spec)
    failures = list(confirmed_failures(nl, spec, eq))
    return ProofReport(
        level="logic", kind="combinational", passed=not failures, cases=1 << spec.n,
        coverage={"method": "sat", "exhaustive": False, "complete": True,
                  "solver": eq.solver, "variables": eq.variables, "clauses": eq.clauses,
                  # failure_count counts the counterexamples found (up to this many per
                  # output), not every failing vector
                  "counterexamples_per_output": EXAMPLES_PER_OUTPUT},
        failure_count=len(failures), failures=failures[:MAX_LISTED_FAILURES],
        figures=dict(LOGIC_FIGURES), seconds=round(time.perf_counter() - t0, 6))


def _check_exhaustive(nl: Netlist, spec: Spec, t0: float) -> ProofReport:
    n = spec.n
    m = input_matrix(n)
    env = {name: m[k] for k, name in enumerate(spec.inputs)}
    nets = nl.evaluate(env)
    wants = {o: spec.table(o) for o in spec.outputs}
    failures, total_bad, care_cases = _compare(nl, spec, nets, wants, env)
    return ProofReport(
        level="logic", kind="combinational", passed=total_bad == 0, cases=1 << n,
        coverage={"method": "exhaustive", "exhaustive": True, "care_checks": care_cases},
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
    if spec.network is not None:
        return _check_sampled_network(nl, spec, t0, seed)
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
        coverage={"method": "sampled", "exhaustive": False, "sampling": sampling,
                  "care_checks": care_cases},
        failure_count=total_bad, failures=failures, figures=dict(LOGIC_FIGURES),
        seconds=round(time.perf_counter() - t0, 6))


def _check_sampled_network(nl: Netlist, spec: Spec, t0: float, seed: int) -> ProofReport:
    """A network-valued spec against the netlist on seeded random vectors (it has no cubes to
    take corners of): the fallback where a cell has no CNF form."""
    rng = np.random.default_rng(seed)
    bits = rng.integers(0, 2, size=(spec.n, RANDOM_VECTORS)).astype(bool)
    values = {name: bits[k] for k, name in enumerate(spec.inputs)}
    nets = nl.evaluate(values)
    failures, total_bad, care_cases = _compare(nl, spec, nets, spec.values_at(bits), values)
    sampling = {"random_vectors": RANDOM_VECTORS, "seed": seed}
    return ProofReport(
        level="logic", kind="combinational", passed=total_bad == 0, cases=RANDOM_VECTORS,
        coverage={"method": "sampled", "exhaustive": False, "sampling": sampling,
                  "care_checks": care_cases},
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
