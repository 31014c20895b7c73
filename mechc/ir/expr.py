"""Boolean expressions: the small AST shared by specs, equations and printing (parsed by
:mod:`mechc.frontends.expr_parser`)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

#: Deepest nesting of '(' and '~' an expression may have. Parsing, evaluation, printing and
#: minimisation all recurse on the tree; a bound here keeps a pathological spec a located error
#: instead of a RecursionError deep in the pipeline.
MAX_NESTING = 64


@dataclass(frozen=True)
class Var:
    name: str


@dataclass(frozen=True)
class Const:
    value: bool


@dataclass(frozen=True)
class Not:
    arg: Expr


@dataclass(frozen=True)
class And:
    args: tuple[Expr, ...]


@dataclass(frozen=True)
class Or:
    args: tuple[Expr, ...]


@dataclass(frozen=True)
class Xor:
    args: tuple[Expr, ...]


Expr = Var | Const | Not | And | Or | Xor


def evaluate(e: Expr, env: Mapping[str, np.ndarray], size: int) -> np.ndarray:
    """Vectorised evaluation: ``env`` maps names to boolean arrays of length ``size``."""
    if isinstance(e, Var):
        return env[e.name]
    if isinstance(e, Const):
        return np.full(size, e.value, dtype=bool)
    if isinstance(e, Not):
        return ~evaluate(e.arg, env, size)
    vals = [evaluate(a, env, size) for a in e.args]
    out = vals[0].copy()
    for v in vals[1:]:
        if isinstance(e, And):
            out &= v
        elif isinstance(e, Or):
            out |= v
        else:
            out ^= v
    return out


_PREC = {Or: 1, Xor: 2, And: 3}
_SYM = {Or: " | ", Xor: " ^ ", And: " & "}


def to_text(e: Expr, parent: int = 0) -> str:
    """Print in the .bool syntax with the fewest parentheses (the text re-parses to ``e``)."""
    if isinstance(e, Var):
        return e.name
    if isinstance(e, Const):
        return "1" if e.value else "0"
    if isinstance(e, Not):
        return "~" + to_text(e.arg, 4)
    prec = _PREC[type(e)]
    s = _SYM[type(e)].join(to_text(a, prec) for a in e.args)
    return f"({s})" if prec < parent else s


def names(e: Expr) -> set[str]:
    if isinstance(e, Var):
        return {e.name}
    if isinstance(e, Const):
        return set()
    if isinstance(e, Not):
        return names(e.arg)
    return set().union(*(names(a) for a in e.args))


def to_sympy(e: Expr, symbols: Mapping[str, object]):
    """The same expression in sympy (for equivalence checks and pretty printing)."""
    # sympy takes half a second to load; only equivalence checks need it (start-up time)
    import sympy

    if isinstance(e, Var):
        return symbols[e.name]
    if isinstance(e, Const):
        return sympy.true if e.value else sympy.false
    if isinstance(e, Not):
        return sympy.Not(to_sympy(e.arg, symbols))
    args = [to_sympy(a, symbols) for a in e.args]
    return {And: sympy.And, Or: sympy.Or, Xor: sympy.Xor}[type(e)](*args)


def sop(terms: Sequence[Sequence[tuple[str, bool]]]) -> Expr:
    """Sum of products from ``[[(name, positive), ...], ...]``; empty sum is 0, empty term 1."""
    prods: list[Expr] = []
    for term in terms:
        lits = [Var(n) if pos else Not(Var(n)) for n, pos in term]
        prods.append(Const(True) if not lits else lits[0] if len(lits) == 1 else And(tuple(lits)))
    if not prods:
        return Const(False)
    return prods[0] if len(prods) == 1 else Or(tuple(prods))
