"""Logic level beyond truth tables: the netlist proved equivalent to its spec by a SAT miter.

A design too wide to enumerate (see :func:`mechc.proofs.logic.choose_method`) is proved here
instead of sampled. Netlist and spec are written as one CNF formula (Tseitin variables for
every net and every sub-expression or cube of the spec, or every node of a spec valued by its
network); per output, a selector variable is
true exactly when the output is cared for and the netlist's value differs from the spec's
(a miter). The solver (CaDiCaL through python-sat, a maintained SAT library) either finds no
such input vector, a proof over all 2**n vectors, or returns one, which is checked again by
plain evaluation (``Netlist.evaluate`` and ``Spec.values_at``) before it is reported, so an
encoding slip can never show as a false counterexample.

Each cell's clauses (:mod:`mechc.ir.cnf`) come from its truth table computed by
:func:`mechc.ir.logic_types.evaluate_type`, the same function the exhaustive check evaluates
with, so there is one definition of what a cell does. Only cells wider than
``TABLE_MAX_INPUTS`` are written by their structure (AND, OR, NAND, NOR: built-in types a cell
file cannot redefine); a wide cell of another type cannot be encoded
(:class:`NotEncodable`), and the caller falls back to sampling.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np

from mechc.ir import expr as ex
from mechc.ir.cnf import TABLE_MAX_INPUTS, Cnf, NotEncodable, encode_netlist, encode_network
from mechc.ir.netlist import Netlist
from mechc.ir.spec import OutputSpec, Spec
from mechc.logic.cubes import DC, Cube

# the CNF writer lives in mechc.ir.cnf (the hazard check shares it); its names stay here too
__all__ = ["EXAMPLES_PER_OUTPUT", "SOLVER", "TABLE_MAX_INPUTS", "Cnf", "Equivalence",
           "NotEncodable", "check_equivalence", "confirmed_failures", "encode_cubes",
           "encode_expr", "encode_netlist", "encode_network", "encode_output", "vector_columns"]

#: The solver python-sat runs: CaDiCaL 1.9.5, incremental with assumptions, the fastest of
#: python-sat's solvers on the t481 miter (2.6 s; glucose 4 5.1 s, minisat 16 s).
SOLVER = "cadical195"
#: Counterexamples looked for per failing output (each a distinct input vector).
EXAMPLES_PER_OUTPUT = 5


def encode_expr(e: ex.Expr, cnf: Cnf, inputs: dict[str, int],
                memo: dict[int, tuple[ex.Expr, int]]) -> int:
    """``e`` as a literal; a sub-expression shared by object identity is encoded once (a
    network written as an expression DAG stays linear)."""
    hit = memo.get(id(e))
    if hit is not None:
        return hit[1]
    if isinstance(e, ex.Var):
        lit = inputs[e.name]
    elif isinstance(e, ex.Const):
        lit = cnf.true if e.value else -cnf.true
    elif isinstance(e, ex.Not):
        lit = -encode_expr(e.arg, cnf, inputs, memo)
    else:
        args = [encode_expr(a, cnf, inputs, memo) for a in e.args]
        if isinstance(e, ex.And):
            lit = cnf.and_(args)
        elif isinstance(e, ex.Or):
            lit = cnf.or_(args)
        else:
            lit = args[0]
            for a in args[1:]:
                lit = cnf.xor2(lit, a)
    memo[id(e)] = (e, lit)  # the object is kept so its id is not reused
    return lit


def encode_cubes(cubes: list[Cube], n: int, cnf: Cnf, names: list[str],
                 inputs: dict[str, int]) -> int:
    """The union of ``cubes`` as a literal."""
    terms = [cnf.and_([inputs[names[k]] if pos else -inputs[names[k]]
                       for k, pos in c.literal_list(n)]) for c in cubes]
    return cnf.or_(terms)


def encode_output(f: OutputSpec, spec: Spec, cnf: Cnf, inputs: dict[str, int],
                  memo: dict) -> tuple[int, int]:
    """(care, want) literals of one spec output: ``care`` true where the spec asks a value,
    ``want`` that value there. Precedence as :meth:`Spec.values_at`: dc, on, off, rest."""
    n = spec.n
    if f.expr is not None:
        on = encode_expr(f.expr, cnf, inputs, memo)
    else:
        on = encode_cubes(f.on, n, cnf, spec.inputs, inputs)
    dc = encode_cubes(f.dc, n, cnf, spec.inputs, inputs) if f.dc else -cnf.true
    off = encode_cubes(f.off, n, cnf, spec.inputs, inputs) if f.off else -cnf.true
    rest_care = f.rest != DC
    # care = ~dc & (on | off | rest cared); want = on | (~off & rest == 1)
    care = cnf.and_([-dc, cnf.or_([on, off, cnf.true if rest_care else -cnf.true])])
    want = cnf.or_([on, cnf.and_([-off, cnf.true if f.rest == 1 else -cnf.true])])
    return care, want


@dataclass
class Equivalence:
    """What the SAT check found: per output, counterexample input vectors (bit k of the integer
    is input k counted from the most significant, as the truth tables order them)."""

    counterexamples: dict[str, list[int]]
    variables: int
    clauses: int
    solver: str = SOLVER

    @property
    def equivalent(self) -> bool:
        return not any(self.counterexamples.values())


def check_equivalence(nl: Netlist, spec: Spec,
                      per_output: int = EXAMPLES_PER_OUTPUT) -> Equivalence:
    """Prove ``nl`` equal to ``spec`` on every cared-for input vector, or find up to
    ``per_output`` counterexamples per output (each confirmed by evaluation)."""
    # python-sat's solvers are compiled extensions: loaded when a wide design needs them
    from pysat.solvers import Solver

    cnf = Cnf()
    inputs = {name: cnf.new() for name in spec.inputs}
    nets = encode_netlist(nl, cnf, inputs)
    memo: dict = {}
    miters: dict[str, int] = {}
    by_net = encode_network(spec.network, cnf, inputs) if spec.network is not None else {}
    for o in spec.outputs:
        if spec.network is not None:  # every vector is cared for, the network's value
            care, want = cnf.true, by_net[o]
        else:
            care, want = encode_output(spec.functions[o], spec, cnf, inputs, memo)
        got = nets[nl.outputs[o]]
        miters[o] = cnf.and_([care, cnf.xor2(got, want)])
    found: dict[str, list[int]] = {o: [] for o in spec.outputs}
    names = list(spec.inputs)
    with Solver(name=SOLVER, bootstrap_with=cnf.clauses) as s:
        for o in spec.outputs:
            # the vectors found for this output are excluded under a literal of its own: the
            # miter variables are defined both ways, so excluding a vector under one would
            # also hide it from every other output that fails there
            only = cnf.new()
            for _ in range(per_output):
                if not s.solve(assumptions=[miters[o], only]):
                    break
                model = set(lit for lit in s.get_model() if lit > 0)
                vec = sum(1 << (len(names) - 1 - k) for k, nm in enumerate(names)
                          if inputs[nm] in model)
                found[o].append(vec)
                s.add_clause([-only] + [-inputs[nm] if inputs[nm] in model else inputs[nm]
                                        for nm in names])
    return Equivalence(found, cnf.top, len(cnf.clauses))


def vector_columns(vectors: list[int], n: int) -> np.ndarray:
    """Integer input vectors (input 0 the MSB) as a boolean (n, len) matrix; any n."""
    return np.array([[(v >> (n - 1 - k)) & 1 for v in vectors] for k in range(n)],
                    dtype=bool).reshape(n, len(vectors))


def confirmed_failures(nl: Netlist, spec: Spec, eq: Equivalence) -> Iterator[dict]:
    """Each counterexample as a failure record, re-evaluated by the netlist's and the spec's
    own evaluators; a vector on which they agree is an encoding error, never a failure."""
    for o, vecs in eq.counterexamples.items():
        if not vecs:
            continue
        cols = vector_columns(vecs, spec.n)
        env = {name: cols[k] for k, name in enumerate(spec.inputs)}
        got = nl.evaluate(env)[nl.outputs[o]]
        want = spec.values_at(cols)[o]
        for i in range(len(vecs)):
            if want[i] == DC or bool(got[i]) == bool(want[i]):
                raise AssertionError(f"SAT counterexample for {o} not confirmed by evaluation "
                                     "(CNF encoding error)")
            yield {"output": o, "inputs": {name: int(cols[k, i])
                                           for k, name in enumerate(spec.inputs)},
                   "expected": int(want[i]), "got": int(got[i])}
