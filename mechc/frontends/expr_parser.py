"""The expression grammar shared by the ``.bool`` and ``.fsm`` front ends.

Grammar (loosest first): ``or := xor ('|' xor)*``, ``xor := and ('^' and)*``,
``and := unary ('&' unary)*``, ``unary := '~' unary | NAME | '0' | '1' | '(' or ')'``.
"""

from __future__ import annotations

from collections.abc import Callable

from mechc.frontends.lexer import Token, TokenStream
from mechc.ir.expr import MAX_NESTING, And, Const, Expr, Not, Or, Var, Xor


def parse_expr(ts: TokenStream, resolve: Callable[[Token], None]) -> Expr:
    """Parse an expression; ``resolve`` is called on every name (it raises for unknown ones)."""
    return _parse_or(ts, resolve, 0)


def _parse_binary(ts, resolve, depth, op, node, sub):
    args = [sub(ts, resolve, depth)]
    while ts.at_op(op):
        ts.advance()
        while ts.cur.kind == "NEWLINE":  # an operator at line end continues the expression
            ts.advance()
        args.append(sub(ts, resolve, depth))
    return args[0] if len(args) == 1 else node(tuple(args))


def _parse_or(ts, resolve, depth):
    return _parse_binary(ts, resolve, depth, "|", Or, _parse_xor)


def _parse_xor(ts, resolve, depth):
    return _parse_binary(ts, resolve, depth, "^", Xor, _parse_and)


def _parse_and(ts, resolve, depth):
    return _parse_binary(ts, resolve, depth, "&", And, _parse_unary)


def _parse_unary(ts: TokenStream, resolve, depth: int) -> Expr:
    t = ts.cur
    if t.kind == "OP" and t.text in ("~", "(") and depth >= MAX_NESTING:
        raise ts.error(f"expression nested more than {MAX_NESTING} levels deep ('(' and '~'); "
                       "expected a flatter expression")
    if t.kind == "OP" and t.text == "~":
        ts.advance()
        return Not(_parse_unary(ts, resolve, depth + 1))
    if t.kind == "OP" and t.text == "(":
        ts.advance()
        e = _parse_or(ts, resolve, depth + 1)
        if not ts.at_op(")"):
            raise ts.error(f"expected ')' to close the '(' at line {t.line} column {t.col}, "
                           f"found {ts.describe()}")
        ts.advance()
        return e
    if t.kind == "NAME":
        resolve(t)
        ts.advance()
        return Var(t.text)
    if t.kind == "NUMBER" and t.text in ("0", "1"):
        ts.advance()
        return Const(t.text == "1")
    raise ts.error(f"expected a name, '~', '(' or a constant 0/1, found {ts.describe()}")
