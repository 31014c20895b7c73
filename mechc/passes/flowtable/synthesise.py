"""The driver: runs the steps in order on a flow table (``synthesise_table``), or minimises and
checks the expressions of a set/reset spec (``setreset_equations``)."""

from __future__ import annotations

import time
from dataclasses import replace

import numpy as np

from mechc.errors import DesignError
from mechc.ir.seqspec import FlowTable, SeqSpec, bits_text
from mechc.passes.flowtable.assign import (
    Assignment,
    assign_states,
    drop_constant_bits,
    given_assignment,
)
from mechc.passes.flowtable.check import check_equations
from mechc.passes.flowtable.compatibles import (
    CoverResult,
    closed_cover,
    compatibility,
    implied_set,
)
from mechc.passes.flowtable.equations import (
    SeqEquations,
    excitation_equations,
    merge_equations,
    spec_of_tables,
    unique_names,
)
from mechc.passes.flowtable.excite import excitation, next_state_map
from mechc.passes.flowtable.hazards import double_changes, essential_hazards
from mechc.passes.flowtable.options import MAX_TOTAL_VARIABLES, SynthOptions
from mechc.passes.flowtable.reach import prune_table, reach_warnings, reachable
from mechc.passes.flowtable.reduce import ReducedTable, reduce_table
from mechc.passes.minimise import minimise


def synthesise_table(spec: SeqSpec, opts: SynthOptions | None = None,
                     polarity: int = 0) -> SeqEquations:
    """Flow table -> SET/RESET and output equations (the steps of the package docstring).

    ``polarity``: state variables to complement (bit j for variable j, MSB first). The literal
    count is the same for every polarity (complementing a variable swaps its SET and RESET and
    the sign of its literals); the mapper's inverter count is not, so the pipeline tries them."""
    opts = opts or SynthOptions()
    t0 = time.perf_counter()
    full = spec.table
    reach = reachable(full)
    ft = prune_table(full, reach)
    sspec = replace(spec, table=ft, _tables=None) if reach.dropped else spec
    warnings = reach_warnings(spec.path, full, reach)
    comp = compatibility(ft)
    if ft.assign:
        classes, codes, width = given_assignment(ft, comp)
        cover = CoverResult(classes, False, 0, "given by 'assign'")
        rt = reduce_table(ft, classes)
        _check_given_closed(ft, rt)
        asg = Assignment(codes, width, False, "given")
    else:
        cover = closed_cover(ft, comp, opts.time_limit)
        rt = reduce_table(ft, cover.classes)
        asg = assign_states(rt, opts.time_limit)
    if ft.secondary is not None and len(ft.secondary) != asg.width:
        raise DesignError(f"'secondary' names {len(ft.secondary)} state variable(s); the "
                          f"assignment needs {asg.width}")
    names_given = list(ft.secondary) if ft.secondary else None
    asg, constant = drop_constant_bits(asg)
    if constant:
        where = ", ".join(names_given[j] if names_given else f"bit {j + 1}" for j in constant)
        warnings.append(f"state variable(s) {where} have one value in every reachable row "
                        "(never set or reset): not built")
        if names_given:
            names_given = [nm for j, nm in enumerate(names_given) if j not in constant]
    if polarity:
        asg = replace(asg, codes=[c ^ polarity for c in asg.codes])
    v = asg.width
    taken = set(ft.inputs) | set(ft.outputs)
    mem = names_given if names_given else unique_names(
        [f"y{j + 1}" for j in range(v)], taken)
    if ft.n + v > MAX_TOTAL_VARIABLES:
        raise DesignError(f"{ft.n} inputs and {v} state variables: at most "
                          f"{MAX_TOTAL_VARIABLES} together")
    maps = next_state_map(rt, asg)
    names = list(ft.inputs) + mem
    # power-up: a merged row holding the initial state and stable in its column
    init_code = asg.codes[rt.next[rt.rep[ft.initial]][ft.start_column()]]
    fix: set[tuple[int, int, int]] = set()
    for _ in range(8):
        exc = excitation(rt, asg, names, maps, fix)
        se = excitation_equations(sspec, exc, mem, opts,
                                  {m: (init_code >> (v - 1 - j)) & 1 for j, m in enumerate(mem)})
        bad = double_changes(rt, asg, exc, se)
        if not bad:
            break
        fix |= bad
    else:
        raise DesignError("outputs still change twice in some transitions after 8 repairs")
    se.form = "table"
    se.classes = [[ft.rows[s] for s in sorted(c)] for c in rt.classes]
    se.codes = {rt.name(c): bits_text(asg.codes[c], v) for c in range(len(rt.classes))}
    se.state_codes = {ft.rows[r]: bits_text(asg.codes[_holding(rt, r)], v)
                      for r in range(len(ft.rows))}
    se.cover = {"rows": len(full.rows), "unreachable_rows": [full.rows[r] for r in reach.dropped],
                "merged": len(rt.classes), "proven_minimum": cover.proven,
                "candidates": cover.candidates, "method": cover.method}
    se.warnings = warnings
    se.assignment = {"width": v, "proven_minimum": asg.proven, "method": asg.method}
    se.essential_hazards = essential_hazards(rt, asg, mem)
    se.checked = check_equations(spec, se)  # against the table as written
    se.seconds = time.perf_counter() - t0
    return se


def _holding(rt: ReducedTable, r: int) -> int:
    """The merged row the circuit sits in while in state r (stable in r's first stable
    column)."""
    k = next(k for k in range(len(rt.ft.columns)) if rt.ft.stable(r, k))
    return rt.next[rt.rep[r]][k]


def _check_given_closed(ft: FlowTable, rt: ReducedTable) -> None:
    """Rows a given ``assign`` merges must still go to merged rows together (closed cover)."""
    for c, cls in enumerate(rt.classes):
        for k in range(len(ft.columns)):
            I = implied_set(ft, cls, k)
            if len(I) >= 2 and not any(I <= d for d in rt.classes):
                raise DesignError(f"rows {rt.name(c)} share a code but in column {ft.label(k)} "
                                  f"they go to states {', '.join(ft.rows[s] for s in sorted(I))}"
                                  ", which have different codes")


def setreset_equations(spec: SeqSpec, opts: SynthOptions | None = None) -> SeqEquations:
    """The given SET/RESET/output expressions minimised exactly (no don't-cares: the
    expressions are the spec) with consensus terms; then the same reachability check."""
    opts = opts or SynthOptions()
    t0 = time.perf_counter()
    mem = spec.memory_names
    names = list(spec.inputs) + mem
    if len(names) > MAX_TOTAL_VARIABLES:
        raise DesignError(f"{len(names)} inputs and memories: at most {MAX_TOTAL_VARIABLES}")
    t = spec.sr_tables()
    taken = set(names) | set(spec.outputs)
    set_names = dict(zip(mem, unique_names([f"set_{m}" for m in mem], taken)))
    reset_names = dict(zip(mem, unique_names([f"reset_{m}" for m in mem], taken)))
    sr = {}
    for m in mem:
        sr[set_names[m]] = t["S:" + m].astype(np.int8)
        sr[reset_names[m]] = t["R:" + m].astype(np.int8)
    mopts = replace(opts.minimise, complements=False)
    eq_sr = minimise(spec_of_tables(names, sr, spec.path), mopts) if sr else None
    eq_z = minimise(spec_of_tables(names, {o: t["Z:" + o].astype(np.int8)
                                           for o in spec.outputs}, spec.path), opts.minimise)
    eq = merge_equations(names, [eq_sr] if eq_sr else [], eq_z, set_names, reset_names, mem,
                         spec.outputs)
    se = SeqEquations(list(spec.inputs), list(spec.outputs), mem,
                      {m.name: m.initial for m in spec.memories}, set_names, reset_names, eq,
                      "setreset")
    se.checked = check_equations(spec, se)
    se.seconds = time.perf_counter() - t0
    return se


def derive_equations(spec: SeqSpec, opts: SynthOptions | None = None) -> SeqEquations:
    """The ``SeqSpec -> equations`` stage for either form."""
    if spec.table is not None:
        return synthesise_table(spec, opts)
    return setreset_equations(spec, opts)
