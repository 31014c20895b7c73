"""The final check: the equations run through every specified transition from every reachable
stable state, every memory switching order included, so a wrong synthesis stops with an error."""

from __future__ import annotations

import numpy as np

from mechc.errors import DesignError
from mechc.ir.seqspec import (
    SeqSpec,
    allowed_changes,
    bits_text,
    describe_total,
    initial_total_state,
    memory_targets,
    next_stable,
    output_values,
    settle_async,
)
from mechc.logic.cubes import eval_cover
from mechc.passes.flowtable.equations import SeqEquations


def check_equations(spec: SeqSpec, se: SeqEquations) -> dict:
    """Run the equations (the covers the mapper builds) through every specified transition
    from every reachable stable state, every memory switching order included: the result must
    be unique, S·R = 0 at every total state passed, outputs as the spec says. Raises."""
    nv = len(se.eq.inputs)
    v = len(se.memories)
    rows = np.arange(1 << nv, dtype=np.int64)
    S = [eval_cover(se.cover_of(se.set_names[m]), rows) for m in se.memories]
    R = [eval_cover(se.cover_of(se.reset_names[m]), rows) for m in se.memories]
    Z = {o: eval_cover(se.cover_of(o), rows) for o in spec.outputs}
    overlap_anywhere = int(sum(int((s & r).sum()) for s, r in zip(S, R)))

    def excite_at(x):
        def f(q):
            i = (x << v) | q
            return memory_targets(((S[j][i], R[j][i]) for j in range(v)), q, v)
        return f

    x0, st0 = initial_total_state(spec)
    q0 = sum(se.initial[m] << (v - 1 - j) for j, m in enumerate(se.memories))
    first = settle_async(excite_at(x0), q0, v)
    if first.finals != [q0]:
        raise DesignError(f"internal error: the initial state is not stable in the equations "
                          f"({bits_text(q0, v)} → {[bits_text(f, v) for f in first.finals]})")
    seen = {(x0, st0, q0)}
    todo = [(x0, st0, q0)]
    transitions = 0
    while todo:
        x, st, q = todo.pop()
        want = output_values(spec, st, x)
        for o, w in want.items():
            got = int(Z[o][(x << v) | q])
            if w is not None and got != w:
                raise DesignError(f"internal error: output {o} is {got} at "
                                  f"{describe_total(spec, x, st)}, spec says {w}")
        for x2 in allowed_changes(spec, st, x):
            transitions += 1
            st2 = next_stable(spec, st, x, x2)
            res = settle_async(excite_at(x2), q, v)
            if res.overlaps:
                qq, j = res.overlaps[0]
                raise DesignError(f"SET and RESET of {se.memories[j]} both on at "
                                  f"{' '.join(spec.inputs)} = {bits_text(x2, spec.n)}, "
                                  f"{' '.join(se.memories)} = {bits_text(qq, v)}")
            if res.cycle or len(res.finals) != 1:
                raise DesignError(f"internal error: race after {describe_total(spec, x, st)} → "
                                  f"{bits_text(x2, spec.n)}")
            node = (x2, st2, res.finals[0])
            if node not in seen:
                seen.add(node)
                todo.append(node)
    return {"stable_states": len(seen), "transitions": transitions,
            "sr_overlap_total_states": overlap_anywhere}
