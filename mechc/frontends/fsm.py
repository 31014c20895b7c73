"""Front end for ``.fsm`` sequential specifications (grammar and examples: docs/fsm.md).

Two forms. Set/reset equations::

    inputs x1 x2
    outputs Z1 Z2
    memory y1 set x2 reset x1 & ~x2 & y2 initial 1
    Z1 = y2

and a flow table (fundamental mode)::

    columns 00 01 11 10
    flow
    1: (1) 3 - 2 | 1 0
    initial 1

Every error names the file, line and column and says what was expected. The table's own
consistency (stable states in their rows, unstable entries that reach a stable state, no
oscillation) is checked by :func:`mechc.ir.seqspec.table_problems` and reported at the
entry concerned; a set/reset spec is explored from power-up and rejected if SET and RESET of a
memory can be on together, or the memories race or oscillate.
"""

from __future__ import annotations

from mechc.errors import SpecError
from mechc.frontends.expr_parser import parse_expr
from mechc.frontends.lexer import Token, TokenStream, read_text, tokenize
from mechc.ir import expr as ex
from mechc.ir.seqspec import (
    FlowTable,
    MemorySpec,
    SeqSpec,
    SequentialError,
    stable_graph,
    table_problems,
)

KEYWORDS = {"inputs", "outputs", "memory", "set", "reset", "initial", "columns", "flow",
            "assign", "secondary", "startup"}
#: A flow-table spec may have at most this many inputs (columns are input combinations).
MAX_FSM_INPUTS = 12


def parse_fsm_file(path: str) -> SeqSpec:
    return parse_fsm(read_text(path), str(path))


def parse_fsm(text: str, path: str = "<string>") -> SeqSpec:
    return _Parser(text, path).parse()


class _Parser:
    def __init__(self, text: str, path: str):
        self.path = path
        self.ts = TokenStream(tokenize(text, path), path)
        self.inputs: list[str] = []
        self.outputs: list[str] = []
        self.out_tokens: dict[str, Token] = {}
        self.memories: list[MemorySpec] = []
        self.mem_names = self._prescan_memories()
        self.equations: dict[str, ex.Expr] = {}
        self.eq_lines: dict[str, int] = {}
        self.columns: list[int] = []
        self.col_tokens: list[Token] = []
        self.rows: list[str] = []
        self.row_tokens: list[Token] = []
        self.entries: list[list[tuple[str | None, bool, Token]]] = []  # (name, stable, tok)
        self.row_out: list[list[int | None]] = []
        self.initial: Token | None = None
        self.initial_col: Token | None = None
        self.assign: dict[str, str] | None = None
        self.assign_tok: Token | None = None
        self.secondary: list[str] | None = None
        self.start: Token | None = None
        self.form: str | None = None
        self.form_tok: Token | None = None

    def _prescan_memories(self) -> dict[str, Token]:
        """Memory names, so an equation may use a memory declared on a later line."""
        toks = self.ts.toks
        out: dict[str, Token] = {}
        for i in range(len(toks) - 1):
            at_start = i == 0 or toks[i - 1].kind == "NEWLINE"
            if at_start and toks[i].kind == "NAME" and toks[i].text == "memory" \
                    and toks[i + 1].kind == "NAME":
                out.setdefault(toks[i + 1].text, toks[i + 1])
        return out

    # ---- statements -------------------------------------------------------------------------
    def parse(self) -> SeqSpec:
        ts = self.ts
        ts.skip_newlines()
        if ts.cur.kind == "EOF":
            raise ts.error("empty specification: expected 'inputs' followed by input names")
        while ts.cur.kind != "EOF":
            t = ts.cur
            if t.kind != "NAME":
                raise ts.error(f"expected a statement ({self._expected()}), found "
                               f"{ts.describe()}")
            kw = t.text
            if kw == "inputs":
                self._declare("inputs", self.inputs)
            elif kw == "outputs":
                if not self.inputs:
                    raise ts.error("expected 'inputs' before 'outputs'")
                self._declare("outputs", self.outputs)
            elif not (self.inputs and self.outputs):
                missing = "inputs" if not self.inputs else "outputs"
                raise ts.error(f"expected '{missing}' declaration before '{kw}'")
            elif kw == "memory":
                self._set_form("setreset", t)
                self._memory()
            elif kw == "startup":
                self._set_form("setreset", t)
                self._start()
            elif kw == "columns":
                self._set_form("table", t)
                self._columns()
            elif kw == "flow":
                self._set_form("table", t)
                self._flow()
            elif kw == "initial":
                self._set_form("table", t)
                self._initial()
            elif kw == "assign":
                self._set_form("table", t)
                self._assign()
            elif kw == "secondary":
                self._set_form("table", t)
                self._secondary()
            elif kw in ("set", "reset"):
                raise ts.error(f"'{kw}' belongs in a 'memory NAME set ... reset ...' line")
            else:
                self._set_form("setreset", t)
                self._equation()
            ts.skip_newlines()
        if not self.inputs:
            raise ts.error("no 'inputs' declaration")
        if not self.outputs:
            raise ts.error("no 'outputs' declaration")
        if self.form == "table":
            return self._finish_table()
        return self._finish_setreset()

    def _expected(self) -> str:
        if not self.inputs:
            return "'inputs'"
        if not self.outputs:
            return "'outputs'"
        return "'memory', an output equation, 'columns', 'flow' or 'initial'"

    def _set_form(self, form: str, tok: Token) -> None:
        if self.form is None:
            self.form, self.form_tok = form, tok
        elif self.form != form:
            first = "a flow table" if self.form == "table" else "set/reset equations"
            raise self.ts.error(f"'{tok.text}' mixes the two forms: this spec already gives "
                                f"{first} (line {self.form_tok.line}); a spec is either a flow "
                                "table or set/reset equations", tok)

    def _declare(self, kind: str, into: list[str]) -> None:
        ts = self.ts
        kw = ts.advance()
        if into:
            raise ts.error(f"'{kind}' declared a second time", kw)
        if ts.cur.kind != "NAME":
            raise ts.error(f"expected at least one {kind[:-1]} name after '{kind}', found "
                           f"{ts.describe()}")
        while ts.cur.kind == "NAME":
            t = ts.advance()
            self._check_new_name(t)
            into.append(t.text)
            if kind == "outputs":
                self.out_tokens[t.text] = t
        ts.expect_newline()
        if kind == "inputs" and len(into) > MAX_FSM_INPUTS:
            raise ts.error(f"{len(into)} inputs: a sequential spec may have at most "
                           f"{MAX_FSM_INPUTS}", kw)

    def _check_new_name(self, t: Token) -> None:
        if t.text in KEYWORDS:
            raise self.ts.error(f"'{t.text}' is a keyword and cannot name a signal", t)
        if t.text in self.inputs or t.text in self.outputs:
            raise self.ts.error(f"duplicate name '{t.text}'", t)

    def _resolver(self):
        ts = self.ts

        def resolve(tok: Token) -> None:
            if tok.text in self.inputs or tok.text in self.mem_names:
                return
            if tok.text in KEYWORDS:
                raise ts.error(f"expected an operator or end of expression, found keyword "
                               f"'{tok.text}'", tok)
            if tok.text in self.outputs:
                raise ts.error(f"'{tok.text}' is an output; expressions may use inputs and "
                               "memories only", tok)
            known = " ".join(self.inputs + list(self.mem_names))
            raise ts.error(f"unknown name '{tok.text}' (inputs and memories are: {known})", tok)

        return resolve

    def _memory(self) -> None:
        ts = self.ts
        ts.advance()
        name = ts.expect_name("a memory name after 'memory'")
        self._check_new_name(name)
        if name.text in [m.name for m in self.memories]:
            raise ts.error(f"memory '{name.text}' declared a second time", name)
        if ts.cur.kind != "NAME" or ts.cur.text != "set":
            raise ts.error(f"expected 'set' after 'memory {name.text}', found {ts.describe()}")
        ts.advance()
        s = parse_expr(ts, self._resolver())
        if ts.cur.kind != "NAME" or ts.cur.text != "reset":
            raise ts.error(f"expected an operator (~ & ^ |) or 'reset', found {ts.describe()}")
        ts.advance()
        r = parse_expr(ts, self._resolver())
        initial = 0
        if ts.cur.kind == "NAME" and ts.cur.text == "initial":
            ts.advance()
            if ts.cur.kind != "NUMBER" or ts.cur.text not in ("0", "1"):
                raise ts.error(f"expected 0 or 1 after 'initial', found {ts.describe()}")
            initial = int(ts.advance().text)
        if ts.cur.kind not in ("NEWLINE", "EOF"):
            raise ts.error(f"expected an operator (~ & ^ |), 'initial' or end of line, found "
                           f"{ts.describe()}")
        ts.expect_newline()
        self.memories.append(MemorySpec(name.text, s, r, initial, name.line))

    def _equation(self) -> None:
        ts = self.ts
        t = ts.advance()
        name = t.text
        if name in self.inputs:
            raise ts.error(f"'{name}' is an input; only outputs can be assigned", t)
        if name in self.mem_names:
            raise ts.error(f"'{name}' is a memory; give it with 'memory {name} set ... reset "
                           "...'", t)
        if name not in self.outputs:
            raise ts.error(f"'{name}' is not a declared output or keyword (outputs: "
                           f"{' '.join(self.outputs)})", t)
        if name in self.equations:
            raise ts.error(f"output '{name}' is defined a second time (first at line "
                           f"{self.eq_lines[name]})", t)
        ts.expect_op("=", f"'=' after output name '{name}'")
        e = parse_expr(ts, self._resolver())
        if ts.cur.kind not in ("NEWLINE", "EOF"):
            raise ts.error(f"expected an operator (~ & ^ |) or end of line, found "
                           f"{ts.describe()}")
        ts.expect_newline()
        self.equations[name] = e
        self.eq_lines[name] = t.line

    def _bits(self, tok: Token, what: str, width: int) -> int:
        if tok.kind != "NUMBER" or set(tok.text) - {"0", "1"}:
            raise self.ts.error(f"expected {what}: {width} binary digit(s), found "
                                f"{self.ts.describe(tok)}", tok)
        if len(tok.text) != width:
            raise self.ts.error(f"{what} '{tok.text}' has {len(tok.text)} digit(s); expected "
                                f"{width} (one per input: {' '.join(self.inputs)})"
                                if what.startswith("column") or what.startswith("input")
                                else f"{what} '{tok.text}' has {len(tok.text)} digit(s); "
                                f"expected {width}", tok)
        return int(tok.text, 2)

    def _start(self) -> None:
        ts = self.ts
        kw = ts.advance()
        if self.start is not None:
            raise ts.error("'startup' given a second time", kw)
        tok = ts.advance()
        self._bits(tok, "input vector", len(self.inputs))
        self.start = tok
        ts.expect_newline()

    def _columns(self) -> None:
        ts = self.ts
        kw = ts.advance()
        if self.col_tokens:
            raise ts.error("'columns' declared a second time", kw)
        if ts.cur.kind in ("NEWLINE", "EOF"):
            raise ts.error("expected column labels after 'columns' (input combinations such "
                           "as 00 01 11 10)")
        while ts.cur.kind not in ("NEWLINE", "EOF"):
            tok = ts.advance()
            v = self._bits(tok, "column label", len(self.inputs))
            if v in self.columns:
                raise ts.error(f"column {tok.text} listed twice", tok)
            self.columns.append(v)
            self.col_tokens.append(tok)
        ts.expect_newline()

    def _state_name(self, what: str) -> Token:
        ts = self.ts
        if ts.cur.kind in ("NAME", "NUMBER"):
            return ts.advance()
        raise ts.error(f"expected {what}, found {ts.describe()}")

    def _flow(self) -> None:
        ts = self.ts
        kw = ts.advance()
        if self.rows:
            raise ts.error("'flow' given a second time", kw)
        if not self.col_tokens:
            raise ts.error("expected 'columns' (the input combinations) before 'flow'", kw)
        ts.expect_newline()
        ts.skip_newlines()
        while ts.cur.kind in ("NAME", "NUMBER") and not (
                ts.cur.kind == "NAME" and ts.cur.text in KEYWORDS
                and not (ts.peek().kind == "OP" and ts.peek().text == ":")):
            self._row()
            ts.skip_newlines()
        if not self.rows:
            raise ts.error(f"expected flow table rows after 'flow' (such as '1: (1) 2 - 3 | 0'),"
                           f" found {ts.describe()}")

    def _row(self) -> None:
        ts = self.ts
        name = ts.advance()
        if name.text in self.rows:
            first = self.row_tokens[self.rows.index(name.text)]
            raise ts.error(f"row {name.text} defined a second time (first at line {first.line})",
                           name)
        ts.expect_op(":", f"':' after row name {name.text}")
        entries: list[tuple[str | None, bool, Token]] = []
        ncol = len(self.columns)
        while not ts.at_op("|"):
            tok = ts.cur
            if tok.kind in ("NEWLINE", "EOF"):
                raise ts.error(f"expected '|' and the outputs of row {name.text} after its "
                               f"{ncol} entries, found {ts.describe()}")
            if len(entries) == ncol:
                raise ts.error(f"row {name.text} has more than {ncol} entries ('columns' lists "
                               f"{ncol}); expected '|' before the outputs")
            if ts.at_op("-"):
                ts.advance()
                entries.append((None, False, tok))
            elif ts.at_op("("):
                ts.advance()
                st = self._state_name(f"a state name inside '(' in row {name.text}")
                if not ts.at_op(")"):
                    raise ts.error(f"expected ')' after stable entry ({st.text}, found "
                                   f"{ts.describe()}")
                ts.advance()
                entries.append((st.text, True, tok))
            elif tok.kind in ("NAME", "NUMBER"):
                ts.advance()
                entries.append((tok.text, False, tok))
            else:
                raise ts.error(f"expected a table entry (a state, '(state)' for a stable one, or "
                               f"'-'), found {ts.describe()}")
        bar = ts.advance()
        if len(entries) != ncol:
            raise ts.error(f"row {name.text} has {len(entries)} entries; 'columns' lists {ncol}",
                           bar)
        outs: list[int | None] = []
        nout = len(self.outputs)
        while ts.cur.kind not in ("NEWLINE", "EOF"):
            tok = ts.cur
            if ts.at_op("-"):
                outs.append(None)
            elif tok.kind == "NUMBER" and not set(tok.text) - {"0", "1"}:
                outs.extend(int(ch) for ch in tok.text)
            else:
                raise ts.error(f"expected output values (0, 1 or -) for row {name.text}, found "
                               f"{ts.describe()}")
            ts.advance()
            if len(outs) > nout:
                raise ts.error(f"row {name.text} gives more than {nout} output value(s) (outputs:"
                               f" {' '.join(self.outputs)})", tok)
        if len(outs) != nout:
            raise ts.error(f"row {name.text} gives {len(outs)} output value(s); expected {nout} "
                           f"(outputs: {' '.join(self.outputs)})", bar)
        ts.expect_newline()
        self.rows.append(name.text)
        self.row_tokens.append(name)
        self.entries.append(entries)
        self.row_out.append(outs)

    def _initial(self) -> None:
        ts = self.ts
        kw = ts.advance()
        if self.initial is not None:
            raise ts.error("'initial' given a second time", kw)
        self.initial = self._state_name("the initial state's name after 'initial'")
        if ts.cur.kind == "NUMBER":
            self.initial_col = ts.advance()
            self._bits(self.initial_col, "input vector", len(self.inputs))
        ts.expect_newline()

    def _secondary(self) -> None:
        ts = self.ts
        kw = ts.advance()
        if self.secondary is not None:
            raise ts.error("'secondary' given a second time", kw)
        names: list[str] = []
        if ts.cur.kind != "NAME":
            raise ts.error(f"expected state variable names after 'secondary', found "
                           f"{ts.describe()}")
        while ts.cur.kind == "NAME":
            t = ts.advance()
            self._check_new_name(t)
            if t.text in names:
                raise ts.error(f"duplicate name '{t.text}'", t)
            names.append(t.text)
        ts.expect_newline()
        self.secondary = names

    def _assign(self) -> None:
        ts = self.ts
        kw = ts.advance()
        if self.assign is not None:
            raise ts.error("'assign' given a second time", kw)
        self.assign, self.assign_tok = {}, kw
        self.assign_toks: dict[str, Token] = {}
        width = None
        while ts.cur.kind not in ("NEWLINE", "EOF"):
            st = self._state_name("STATE=CODE (e.g. 1=01) after 'assign'")
            ts.expect_op("=", f"'=' after state {st.text} in 'assign'")
            code = ts.cur
            if code.kind != "NUMBER" or set(code.text) - {"0", "1"}:
                raise ts.error(f"expected a binary code for state {st.text}, found "
                               f"{ts.describe()}")
            ts.advance()
            if width is None:
                width = len(code.text)
            elif len(code.text) != width:
                raise ts.error(f"code '{code.text}' has {len(code.text)} digit(s); the first "
                               f"code has {width}", code)
            if st.text in self.assign:
                raise ts.error(f"state {st.text} assigned twice", st)
            self.assign[st.text] = code.text
            self.assign_toks[st.text] = st
        if not self.assign:
            raise ts.error("expected STATE=CODE pairs after 'assign'")
        ts.expect_newline()

    # ---- completion ---------------------------------------------------------------------------
    def _finish_table(self) -> SeqSpec:
        ts = self.ts
        if not self.col_tokens:
            raise ts.error("flow table spec without 'columns'", self.form_tok)
        if not self.rows:
            raise ts.error("flow table spec without 'flow' rows", self.form_tok)
        index = {name: i for i, name in enumerate(self.rows)}
        nxt: list[list[int | None]] = []
        for r, entries in enumerate(self.entries):
            line: list[int | None] = []
            for name, stable, tok in entries:
                if name is None:
                    line.append(None)
                    continue
                if name not in index:
                    raise ts.error(f"unknown state {name} in row {self.rows[r]}: no row is "
                                   f"named {name} (rows: {' '.join(self.rows)})", tok)
                if not stable and name == self.rows[r]:
                    raise ts.error(f"entry {name} in row {name} names its own row: write "
                                   f"({name}) if the state is stable there", tok)
                if stable and name != self.rows[r]:
                    raise ts.error(f"stable entry ({name}) in row {self.rows[r]}: a stable "
                                   f"entry must name its own row (write ({self.rows[r]}) or "
                                   f"the unstable entry {name})", tok)
                line.append(index[name])
            nxt.append(line)
        initial = 0
        if self.initial is not None:
            if self.initial.text not in index:
                raise ts.error(f"initial state {self.initial.text} is not a row of the table",
                               self.initial)
            initial = index[self.initial.text]
        init_col = None
        if self.initial_col is not None:
            init_col = self.columns.index(int(self.initial_col.text, 2)) \
                if int(self.initial_col.text, 2) in self.columns else None
            if init_col is None:
                raise ts.error(f"input vector {self.initial_col.text} is not a column of the "
                               "table", self.initial_col)
        if self.assign is not None:
            for name, tok in self.assign_toks.items():
                if name not in index:
                    raise ts.error(f"'assign' names state {name}, which is not a row", tok)
            missing = [r for r in self.rows if r not in self.assign]
            if missing:
                raise ts.error(f"'assign' gives no code for state(s) {' '.join(missing)}",
                               self.assign_tok)
            width = len(next(iter(self.assign.values())))
            if self.secondary is not None and len(self.secondary) != width:
                raise ts.error(f"'secondary' names {len(self.secondary)} variable(s) but the "
                               f"codes have {width} digit(s)", self.assign_tok)
        ft = FlowTable(list(self.inputs), list(self.outputs), list(self.columns),
                       list(self.rows), nxt, self.row_out, initial, init_col,
                       [t.line for t in self.row_tokens], self.assign, self.secondary)
        problems = table_problems(ft)
        if problems:
            p = problems[0]
            tok = self.row_tokens[p.row] if p.column is None else \
                self.entries[p.row][p.column][2]
            if p.kind == "initial":
                tok = self.initial_col or self.initial
            raise SpecError(self.path, tok.line, tok.col, p.message)
        return SeqSpec(self.path, list(self.inputs), list(self.outputs), table=ft)

    def _finish_setreset(self) -> SeqSpec:
        for name in self.outputs:
            if name not in self.equations:
                tok = self.out_tokens[name]
                raise SpecError(self.path, tok.line, tok.col,
                                f"output '{name}' is declared but never defined")
        start = int(self.start.text, 2) if self.start is not None else 0
        spec = SeqSpec(self.path, list(self.inputs), list(self.outputs), list(self.memories),
                       dict(self.equations), start_inputs=start)
        try:
            stable_graph(spec)
        except SequentialError as e:
            line, col = self._locate(e)
            raise SpecError(self.path, line, col, str(e)) from None
        return spec

    def _locate(self, e: SequentialError) -> tuple[int, int]:
        for m in self.memories:
            if e.rows and m.name == e.rows[0]:
                tok = self.mem_names[m.name]
                return tok.line, tok.col
        tok = self.form_tok
        return (tok.line, tok.col) if tok else (1, 1)


def parse_expression(text: str, names: list[str], where: str) -> ex.Expr:
    """A stand-alone expression over ``names`` (reading a spec echo back from JSON)."""
    ts = TokenStream(tokenize(text, where), where)

    def resolve(tok: Token) -> None:
        if tok.text not in names:
            raise ts.error(f"unknown name '{tok.text}'", tok)

    e = parse_expr(ts, resolve)
    if ts.cur.kind not in ("NEWLINE", "EOF"):
        raise ts.error(f"unexpected {ts.describe()} after expression")
    return e
