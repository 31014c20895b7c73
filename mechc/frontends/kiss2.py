"""Front end for KISS2 state tables (``.kiss2``/``.kiss``), read as asynchronous flow tables.

KISS2 is the state-table format of the MCNC benchmarks and SIS::

    .i 1            # inputs          .ilb/.ob name them (optional; default x0.., f0..)
    .o 1            # outputs
    .r a            # reset state (optional; default the first present state)
    0 a a 0         # input cube, present state, next state, outputs
    1 a b 1
    .e

mechc's machines run in fundamental mode, so a line is read as the flow-table entry (input
column, present state) -> next state: the machine is stable where next = present, and the
outputs of those stable lines are the outputs of the state. Input cubes with ``-`` expand to
every column they cover, ``*`` as present state means every state, and ``*`` or ``-`` as next
state leaves the entry unspecified. The rules for tables that are not a valid fundamental-mode
machine (docs/spec-formats.md) are the ``.fsm`` reader's, checked by
:func:`mechc.ir.seqspec.table_problems`; every error names file, line and column.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

from mechc.errors import SpecError
from mechc.frontends.fsm import MAX_FSM_INPUTS
from mechc.frontends.lexer import Word, read_text
from mechc.ir.seqspec import FlowTable, SeqSpec, table_problems

_NAME_OK = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")
_STATE_OK = re.compile(r"^[A-Za-z0-9_]+$")
ANY = "*"
KEYWORDS = ("i", "o", "p", "s", "r", "ilb", "ob", "e", "end")


@dataclass
class _Line:
    """One transition line: input cube, present state, next state, output bits."""

    cube: Word
    present: Word
    next: Word
    outs: Word


@dataclass
class _Entry:
    """What the lines say about one (state, column): merged over every line that covers it."""

    next: str | None
    outs: list[int | None]
    next_from: _Line  # the line that gave the next state (else the first line covering it)
    out_from: list[int]  # per output bit, the line number that gave its value


def line_words(text: str, lineno: int) -> list[Word]:
    """Words of one line, a ``#`` comment removed."""
    cut = text.find("#")
    if cut >= 0:
        text = text[:cut]
    return [Word(m.group(), lineno, m.start() + 1) for m in re.finditer(r"\S+", text)]


def parse_kiss_file(path: str) -> SeqSpec:
    return parse_kiss(read_text(path), str(path))


def parse_kiss(text: str, path: str = "<string>") -> SeqSpec:
    return _Reader(text, path).read()


def gray_order(n: int) -> list[int]:
    """Input vectors in reflected Gray order, the order flow tables are written in."""
    return [i ^ (i >> 1) for i in range(1 << n)]


class _Reader:
    def __init__(self, text: str, path: str):
        self.text, self.path = text, path
        self.n: int | None = None
        self.m: int | None = None
        self.ilb: list[str] | None = None
        self.ob: list[str] | None = None
        self.reset: Word | None = None
        self.lines: list[_Line] = []

    def err(self, w: Word, msg: str) -> SpecError:
        return SpecError(self.path, w.line, w.col, msg)

    # ---- reading --------------------------------------------------------------------------
    def read(self) -> SeqSpec:
        ended: Word | None = None
        for lineno, raw in enumerate(self.text.split("\n"), start=1):
            words = line_words(raw.rstrip("\r"), lineno)
            if not words:
                continue
            if ended is not None:
                raise self.err(words[0], f"text after '{ended.text}' (end of the KISS2 table)")
            if words[0].text.startswith("."):
                if words[0].text in (".e", ".end"):
                    if len(words) > 1:
                        raise self.err(words[1], f"expected end of line after '{words[0].text}'")
                    ended = words[0]
                else:
                    self._keyword(words)
            else:
                self._transition(words)
        if self.n is None:
            raise SpecError(self.path, 1, 1, "empty KISS2 file: expected '.i' (number of "
                            "inputs)" if not self.text.strip() else "missing '.i' (number of "
                            "inputs)")
        if self.m is None:
            raise SpecError(self.path, 1, 1, "missing '.o' (number of outputs)")
        if not self.lines:
            raise SpecError(self.path, 1, 1, "no transition lines (expected lines 'INPUTS "
                            "PRESENT NEXT OUTPUTS' such as '01 a b 1')")
        return self._build()

    def _count(self, words: list[Word], kw: str, minimum: int) -> int:
        if (len(words) != 2 or not (words[1].text.isascii() and words[1].text.isdigit())
                or len(words[1].text) > 6):
            w = words[1] if len(words) > 1 else words[0]
            raise self.err(w, f"expected one whole number after '{kw}'")
        v = int(words[1].text)
        if v < minimum:
            raise self.err(words[1], f"'{kw}' must be at least {minimum}")
        return v

    def _keyword(self, words: list[Word]) -> None:
        head = words[0]
        kw = head.text
        if self.lines and kw in (".i", ".o", ".ilb", ".ob", ".r"):
            raise self.err(head, f"'{kw}' must come before the transition lines")
        if kw == ".i":
            if self.n is not None:
                raise self.err(head, "'.i' given twice")
            self.n = self._count(words, kw, 1)
            if self.n > MAX_FSM_INPUTS:
                raise self.err(words[1], f"{self.n} inputs: a sequential spec may have at most "
                               f"{MAX_FSM_INPUTS} (each input combination is a flow-table "
                               "column)")
        elif kw == ".o":
            if self.m is not None:
                raise self.err(head, "'.o' given twice")
            self.m = self._count(words, kw, 1)
        elif kw in (".p", ".s"):
            self._count(words, kw, 0)  # counts are read and not held to, as for '.p' in PLA
        elif kw in (".ilb", ".ob"):
            count = self.n if kw == ".ilb" else self.m
            if count is None:
                raise self.err(head, f"'{kw}' must come after '{'.i' if kw == '.ilb' else '.o'}'")
            names = words[1:]
            if len(names) != count:
                raise self.err(head, f"'{kw}' lists {len(names)} name(s), expected {count}")
            seen: set[str] = set()
            for w in names:
                if not _NAME_OK.match(w.text):
                    raise self.err(w, f"name '{w.text}' is not usable as a signal name "
                                   "(letters, digits and '_', not starting with a digit)")
                if w.text in seen:
                    raise self.err(w, f"duplicate name '{w.text}' in '{kw}'")
                seen.add(w.text)
            if kw == ".ilb":
                self.ilb = [w.text for w in names]
            else:
                self.ob = [w.text for w in names]
        elif kw == ".r":
            if self.reset is not None:
                raise self.err(head, "'.r' given twice")
            if len(words) != 2:
                raise self.err(words[-1] if len(words) > 2 else head,
                               "expected one state name after '.r'")
            self._state_word(words[1], "reset state")
            self.reset = words[1]
        elif kw in (".start_kiss", ".end_kiss"):
            raise self.err(head, f"'{kw}' belongs in a BLIF file; a .kiss2 file holds the "
                           "table alone")
        else:
            raise self.err(head, f"unknown keyword '{kw}' (KISS2 keywords: "
                           + " ".join("." + k for k in KEYWORDS) + ")")

    def _state_word(self, w: Word, what: str) -> None:
        if not _STATE_OK.match(w.text):
            raise self.err(w, f"{what} '{w.text}' is not a usable state name (letters, digits "
                           "and '_')")

    def _transition(self, words: list[Word]) -> None:
        if self.n is None or self.m is None:
            raise self.err(words[0], "transition line before '.i' and '.o'")
        if len(words) != 4:
            raise self.err(words[4] if len(words) > 4 else words[0],
                           f"a transition line has 4 fields (inputs, present state, next "
                           f"state, outputs), found {len(words)}")
        cube, present, nxt, outs = words
        self._plane(cube, self.n, "input", "01-")
        if present.text != ANY:
            self._state_word(present, "present state")
        if nxt.text not in (ANY, "-"):
            self._state_word(nxt, "next state")
        self._plane(outs, self.m, "output", "01-")
        self.lines.append(_Line(cube, present, nxt, outs))

    def _plane(self, w: Word, width: int, what: str, allowed: str) -> None:
        for i, ch in enumerate(w.text):
            if ch not in allowed:
                raise SpecError(self.path, w.line, w.col + i, f"bad {what} character {ch!r}: "
                                f"expected one of {' '.join(allowed)}")
        if len(w.text) != width:
            raise self.err(w, f"{what} field '{w.text}' has {len(w.text)} character(s); "
                           f"expected {width} ('.{what[0]} {width}')")

    # ---- building the flow table -----------------------------------------------------------
    def _build(self) -> SeqSpec:
        n, m = self.n, self.m
        assert n is not None and m is not None
        inputs = self.ilb or [f"x{k}" for k in range(n)]
        outputs = self.ob or [f"f{k}" for k in range(m)]
        clash = set(inputs) & set(outputs)
        if clash:
            raise SpecError(self.path, 1, 1, "name used for both an input and an output: "
                            f"{sorted(clash)[0]}")
        states, first_seen = self._states()
        entries = self._entries(states)
        used = {k for (_s, k) in entries}
        columns = [x for x in gray_order(n) if x in used]
        col_index = {x: k for k, x in enumerate(columns)}

        # One flow-table row per (state, group of stable columns with agreeing outputs).
        rows: list[str] = []
        row_state: list[str] = []
        row_out: list[list[int | None]] = []
        row_line: list[int] = []
        row_of: dict[tuple[str, int], int] = {}  # (state, stable column vector) -> row
        first_row: dict[str, int] = {}
        for s in states:
            stable = [x for x in columns if (s, x) in entries and entries[s, x].next == s]
            if not stable:
                w = first_seen[s]
                raise self.err(w, f"state {s} is never stable: no line has {s} as both present "
                               f"and next state (in fundamental mode every state must be stable "
                               f"for some input combination: add a line 'INPUTS {s} {s} "
                               "OUTPUTS' where it holds)")
            groups: list[tuple[list[int], list[int | None]]] = []
            for x in stable:
                outs = entries[s, x].outs
                for cols, merged in groups:
                    if _agree(merged, outs):
                        cols.append(x)
                        merged[:] = _merge(merged, outs)
                        break
                else:
                    groups.append(([x], list(outs)))
            first_row[s] = len(rows)
            for cols, merged in groups:
                name = s if len(groups) == 1 else f"{s}@{_bits(cols[0], n)}"
                for x in cols:
                    row_of[s, x] = len(rows)
                rows.append(name)
                row_state.append(s)
                row_out.append(merged)
                row_line.append(first_seen[s].line)

        nxt: list[list[int | None]] = []
        for s in row_state:
            line: list[int | None] = []
            for x in columns:
                e = entries.get((s, x))
                if e is None or e.next is None:
                    line.append(None)
                elif e.next == s:
                    line.append(row_of[s, x])
                else:
                    line.append(row_of.get((e.next, x), first_row[e.next]))
            nxt.append(line)

        reset = self.reset.text if self.reset is not None else states[0]
        if reset not in first_row:
            raise self.err(self.reset, f"reset state {reset} does not appear in any transition "
                           f"line (states: {' '.join(states)})")
        # Power-up: the reset state under the first line (in file order) that makes it stable.
        x0 = min((x for x in columns if (reset, x) in row_of),
                 key=lambda x: entries[reset, x].next_from.cube.line)
        ft = FlowTable(list(inputs), list(outputs), columns, rows, nxt, row_out,
                       row_of[reset, x0], col_index[x0], row_line)
        problems = table_problems(ft)
        if problems:
            p = problems[0]
            s = row_state[p.row]
            if p.column is None:
                w = first_seen[s]
            else:
                w = entries[s, columns[p.column]].next_from.next
            raise self.err(w, f"{p.message} (as a fundamental-mode flow table; see "
                           "docs/spec-formats.md)")
        return SeqSpec(self.path, list(inputs), list(outputs), table=ft)

    def _states(self) -> tuple[list[str], dict[str, Word]]:
        """State names in order of first appearance as present state (the order a table is
        written in), then those only ever named as next state; and where each first appears."""
        states: list[str] = []
        first: dict[str, Word] = {}
        for w in [ln.present for ln in self.lines] + [ln.next for ln in self.lines]:
            if w.text in (ANY, "-") or w.text in first:
                continue
            first[w.text] = w
            states.append(w.text)
        if not states:
            raise self.err(self.lines[0].present, "no state is named: every line uses '*'")
        return states, first

    def _entries(self, states: list[str]) -> dict[tuple[str, int], _Entry]:
        """(state, input vector) -> entry, every line expanded; contradictions are errors."""
        entries: dict[tuple[str, int], _Entry] = {}
        m = self.m
        assert m is not None
        for ln in self.lines:
            nxt = None if ln.next.text in (ANY, "-") else ln.next.text
            outs = [None if ch == "-" else int(ch) for ch in ln.outs.text]
            targets = states if ln.present.text == ANY else [ln.present.text]
            for x in _expand(ln.cube.text):
                for s in targets:
                    e = entries.get((s, x))
                    if e is None:
                        entries[s, x] = _Entry(nxt, list(outs), ln, [ln.cube.line] * m)
                        continue
                    where = f"state {s} at input {_bits(x, len(ln.cube.text))}"
                    if nxt is not None and e.next is not None and nxt != e.next:
                        raise self.err(ln.next, f"{where} goes to {nxt} here but to {e.next} "
                                       f"on line {e.next_from.cube.line}: a flow table has "
                                       "one next state per state and input combination")
                    if nxt is not None and e.next is None:
                        e.next, e.next_from = nxt, ln
                    for j in range(m):
                        a, b = e.outs[j], outs[j]
                        if a is not None and b is not None and a != b:
                            raise SpecError(self.path, ln.outs.line, ln.outs.col + j,
                                            f"{where}: output {j + 1} is {b} here but {a} on "
                                            f"line {e.out_from[j]}")
                        if a is None and b is not None:
                            e.outs[j], e.out_from[j] = b, ln.cube.line
        return entries


def _expand(cube: str) -> list[int]:
    """Every input vector a cube covers (input 0 is the most significant bit)."""
    out = [0]
    for ch in cube:
        if ch == "-":
            out = [v << 1 | b for v in out for b in (0, 1)]
        else:
            out = [v << 1 | int(ch) for v in out]
    return out


def _agree(a: list[int | None], b: list[int | None]) -> bool:
    return all(x is None or y is None or x == y for x, y in zip(a, b))


def _merge(a: list[int | None], b: list[int | None]) -> list[int | None]:
    return [x if x is not None else y for x, y in zip(a, b)]


def _bits(x: int, n: int) -> str:
    return format(x, f"0{n}b")
