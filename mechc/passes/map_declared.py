"""Mapping onto logic types that cell files declare (a ``function`` or ``truth`` in the cell).

The SOP mapper knows the built-in types only. For a declared type (3-input majority, say) the
check is cheap and exact: an output whose cover depends on exactly as many inputs as the type
has, and equals the type's table for some order of those inputs, can be one cell of that type.
That structure is then one more candidate for the output: it wins by cost like any other, or
always when the cell is named with ``--use-cell`` (``MapOptions.prefer``).
"""

from __future__ import annotations

from itertools import permutations

import numpy as np

from mechc.ir import expr as ex
from mechc.ir.equations import Cover
from mechc.ir.logic_types import TYPES, table_rows
from mechc.logic.cubes import cube_table

#: Declared types with more inputs than this are not tried (n! orders of the support).
MAX_DECLARED_INPUTS = 6


def declared_candidates(cover: Cover, inputs: list[str], type_names: list[str]
                        ) -> list[tuple]:
    """Planner keys ``(TYPE, (("in", v), ...))`` computing ``cover`` with one declared-type
    cell (one per type that fits, in the first input order that matches)."""
    n = len(inputs)
    mask = 0
    for c in cover.cubes:
        mask |= c.mask
    support = [k for k in range(n) if mask >> (n - 1 - k) & 1]
    k = len(support)
    types = [t for t in type_names if TYPES[t].table is not None
             and len(TYPES[t].table) == 1 << k and k <= MAX_DECLARED_INPUTS]
    if not types or k == 0:
        return []
    full = cube_table(cover.cubes, n)
    # the function on its support: other inputs at 0
    rows = table_rows(k)
    idx = sum(r.astype(np.int64) << (n - 1 - support[i]) for i, r in enumerate(rows))
    f = tuple(int(v) for v in full[idx])
    out = []
    for t in types:
        table = TYPES[t].table
        for perm in permutations(range(k)):
            # input j of the cell is support[perm[j]]
            idx_p = sum(rows[perm[j]].astype(np.int64) << (k - 1 - j) for j in range(k))
            if all(table[int(idx_p[r])] == f[r] for r in range(1 << k)):
                out.append((t, tuple(("in", inputs[support[p]]) for p in perm)))
                break
    return out


def declared_expr(type_name: str, args: list[ex.Expr]) -> ex.Expr:
    """The expression a declared-type cell computes (its table as a sum of minterms), for the
    design's 'implemented' line."""
    table = TYPES[type_name].table
    n = len(args)
    terms = []
    for r, v in enumerate(table):
        if v:
            lits = [a if r >> (n - 1 - i) & 1 else ex.Not(a) for i, a in enumerate(args)]
            terms.append(lits[0] if n == 1 else ex.And(tuple(lits)))
    if not terms:
        return ex.Const(False)
    return terms[0] if len(terms) == 1 else ex.Or(tuple(terms))
