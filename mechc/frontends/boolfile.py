"""Front end for ``.bool`` combinational specifications (grammar: docs/spec-formats.md)."""

from __future__ import annotations

from mechc.errors import SpecError
from mechc.frontends.expr_parser import parse_expr
from mechc.frontends.lexer import Token, TokenStream, read_text, tokenize
from mechc.ir import expr as ex
from mechc.ir.spec import OutputSpec, Spec
from mechc.logic.cubes import MAX_TABLE_INPUTS, Cube

KEYWORDS = {"inputs", "outputs", "minterms", "dontcare"}


def parse_bool_file(path: str) -> Spec:
    return parse_bool(read_text(path), str(path))


def parse_bool(text: str, path: str = "<string>") -> Spec:
    ts = TokenStream(tokenize(text, path), path)
    inputs: list[str] = []
    outputs: list[str] = []
    out_tokens: dict[str, Token] = {}
    funcs: dict[str, OutputSpec] = {}
    seen_inputs = seen_outputs = False

    def declare(kind: str, into: list[str]) -> Token:
        kw = ts.advance()
        if ts.cur.kind != "NAME":
            raise ts.error(f"expected at least one {kind[:-1]} name after '{kind}', "
                           f"found {ts.describe()}")
        while ts.cur.kind == "NAME":
            t = ts.advance()
            if t.text in KEYWORDS:
                raise ts.error(f"'{t.text}' is a keyword and cannot name a signal", t)
            if t.text in inputs or t.text in outputs:
                raise ts.error(f"duplicate name '{t.text}'", t)
            into.append(t.text)
            if kind == "outputs":
                out_tokens[t.text] = t
        ts.expect_newline()
        return kw

    ts.skip_newlines()
    if ts.cur.kind == "EOF":
        raise ts.error("empty specification: expected 'inputs' followed by input names")
    while ts.cur.kind != "EOF":
        t = ts.cur
        if t.kind == "NAME" and t.text == "inputs":
            if seen_inputs:
                raise ts.error("'inputs' declared a second time")
            declare("inputs", inputs)
            seen_inputs = True
            if len(inputs) > MAX_TABLE_INPUTS:
                raise ts.error(f"{len(inputs)} inputs: a .bool spec may have at most "
                               f"{MAX_TABLE_INPUTS} (use a PLA file for larger functions)", t)
        elif t.kind == "NAME" and t.text == "outputs":
            if not seen_inputs:
                raise ts.error("expected 'inputs' before 'outputs'")
            if seen_outputs:
                raise ts.error("'outputs' declared a second time")
            declare("outputs", outputs)
            seen_outputs = True
        elif t.kind == "NAME":
            if not (seen_inputs and seen_outputs):
                missing = "inputs" if not seen_inputs else "outputs"
                raise ts.error(f"expected '{missing}' declaration before '{t.text}'")
            f = _parse_assignment(ts, inputs, outputs, funcs)
            funcs[f.name] = f
        else:
            want = "an output assignment 'NAME = ...'" if seen_outputs else (
                "'outputs'" if seen_inputs else "'inputs'")
            raise ts.error(f"expected {want}, found {ts.describe()}")
        ts.skip_newlines()

    if not seen_inputs:
        raise ts.error("no 'inputs' declaration")
    if not seen_outputs:
        raise ts.error("no 'outputs' declaration")
    for name in outputs:
        if name not in funcs:
            tok = out_tokens[name]
            raise SpecError(path, tok.line, tok.col,
                            f"output '{name}' is declared but never defined")
    return Spec(path, "bool", inputs, outputs, funcs)


def _parse_assignment(ts: TokenStream, inputs, outputs, funcs) -> OutputSpec:
    name_tok = ts.advance()
    name = name_tok.text
    if name in inputs:
        raise ts.error(f"'{name}' is an input; only outputs can be assigned", name_tok)
    if name not in outputs:
        raise ts.error(f"'{name}' is not a declared output (outputs: {' '.join(outputs)})",
                       name_tok)
    if name in funcs:
        raise ts.error(f"output '{name}' is defined a second time (first at line "
                       f"{funcs[name].line})", name_tok)
    ts.expect_op("=", f"'=' after output name '{name}'")
    n = len(inputs)
    f = OutputSpec(name, line=name_tok.line)
    if ts.cur.kind == "NAME" and ts.cur.text == "minterms":
        on = _parse_number_list(ts, n, "minterms")
        f.on = [Cube.minterm(m, n) for m in on]
        on_set = {m: tok for m, tok in on.items()}
    else:
        if ts.cur.kind == "NAME" and ts.cur.text == "dontcare":
            raise ts.error("expected an expression or minterms(...) before dontcare(...)")
        f.expr = parse_expr(ts, _resolver(ts, inputs, outputs))
        on_set = {}
    if ts.cur.kind == "NAME" and ts.cur.text == "dontcare":
        dcs = _parse_number_list(ts, n, "dontcare")
        for m, tok in dcs.items():
            if m in on_set:
                raise ts.error(f"minterm {m} is both in minterms(...) and dontcare(...)", tok)
        f.dc = [Cube.minterm(m, n) for m in dcs]
    if ts.cur.kind not in ("NEWLINE", "EOF"):
        raise ts.error(f"expected an operator (~ & ^ |), 'dontcare(...)' or end of line, "
                       f"found {ts.describe()}")
    ts.expect_newline()
    return f


def _resolver(ts: TokenStream, inputs, outputs):
    def resolve(tok: Token) -> None:
        if tok.text in inputs:
            return
        if tok.text in KEYWORDS:
            raise ts.error(f"'{tok.text}(...)' must be the whole right-hand side", tok)
        if tok.text in outputs:
            raise ts.error(f"'{tok.text}' is an output; expressions may use only inputs "
                           f"({' '.join(inputs)})", tok)
        raise ts.error(f"unknown name '{tok.text}' (inputs are: {' '.join(inputs)})", tok)

    return resolve


def _parse_number_list(ts: TokenStream, n: int, kw: str) -> dict[int, Token]:
    ts.advance()
    ts.expect_op("(", f"'(' after '{kw}'")
    out: dict[int, Token] = {}
    limit = (1 << n) - 1
    while not ts.at_op(")"):
        tok = ts.cur
        if tok.kind != "NUMBER":
            raise ts.error(f"expected a minterm number or ')' in {kw}(...), found "
                           f"{ts.describe()}")
        ts.advance()
        if len(tok.text) > 12 or int(tok.text) > limit:
            shown = tok.text if len(tok.text) <= 12 else tok.text[:12] + "..."
            raise ts.error(f"minterm {shown} is out of range: {n} inputs allow 0..{limit}", tok)
        m = int(tok.text)
        if m in out:
            raise ts.error(f"minterm {m} is listed twice in {kw}(...)", tok)
        out[m] = tok
        if ts.at_op(","):
            ts.advance()
            if ts.at_op(")"):
                raise ts.error("expected a minterm number after ',', found ')'")
        elif not ts.at_op(")"):
            raise ts.error(f"expected ',' or ')' in {kw}(...), found {ts.describe()}")
    ts.advance()
    return out


def parse_expression_text(text: str, inputs: list[str], where: str) -> ex.Expr:
    """Parse a stand-alone expression (used when reading a spec echo back from JSON)."""
    ts = TokenStream(tokenize(text, where), where)
    e = parse_expr(ts, _resolver(ts, inputs, []))
    if ts.cur.kind not in ("NEWLINE", "EOF"):
        raise ts.error(f"unexpected {ts.describe()} after expression")
    return e
