"""Tokeniser shared by the text front ends (.bool, .fsm).

Every token carries its 1-based line and column so every error can point at the text.
Newlines are tokens (statements end at a newline) except inside parentheses.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

from mechc.errors import SpecError, read_input

MAX_SPEC_BYTES = 50_000_000
#: Longest name or number: real ones are a few characters (a column label has one digit per
#: input, at most 20); a longer token is a mistake, and would be echoed whole in messages.
MAX_TOKEN_CHARS = 100
#: Characters other notations use for the operators, with what to write instead.
_OPERATOR_HINTS = {"+": "'|' for OR", "*": "'&' for AND", ".": "'&' for AND",
                   "!": "'~' for NOT", "'": "'~' before the name for NOT",
                   "¬": "'~' for NOT", "∧": "'&' for AND", "∨": "'|' for OR",
                   "⊕": "'^' for XOR", "·": "'&' for AND"}


@dataclass(frozen=True)
class Word:
    """A whitespace-separated word of a line-oriented format (KISS2, BLIF) and where it starts
    (1-based), for error messages."""

    text: str
    line: int
    col: int


@dataclass(frozen=True)
class Token:
    kind: str  # NAME NUMBER OP NEWLINE EOF
    text: str
    line: int
    col: int


_TOKEN_RE = re.compile(
    r"(?P<ws>[ \t\r\f]+)|(?P<comment>#[^\n]*)|(?P<nl>\n)"
    r"|(?P<name>[A-Za-z_][A-Za-z0-9_]*)|(?P<number>[0-9]+)"
    r"|(?P<op>[~&|^()=,:\-\[\]])"
)


def read_text(path: str | Path) -> str:
    """Read a spec file as UTF-8 text: an encoding problem is a located SpecError, an I/O one a
    UsageError naming the file."""
    data = read_input(path, "a spec file")
    if len(data) > MAX_SPEC_BYTES:
        raise SpecError(str(path), 1, 1, f"file is {len(data)} bytes; the limit is "
                        f"{MAX_SPEC_BYTES}")
    if data[:2] in (b"\xff\xfe", b"\xfe\xff"):  # UTF-16 with its BOM (e.g. Windows PowerShell)
        try:
            data = data.decode("utf-16").encode("utf-8")
        except UnicodeDecodeError as e:
            raise SpecError(str(path), 1, 1, f"invalid UTF-16 text ({e.reason}): expected a "
                            "text spec in UTF-8 or UTF-16") from None
    nul = data.find(b"\0")
    if nul >= 0:
        line, col = _position(data, nul)
        raise SpecError(str(path), line, col, "binary data (NUL byte): expected a text spec")
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as e:
        line, col = _position(data, e.start)
        raise SpecError(str(path), line, col,
                        f"invalid UTF-8 byte 0x{data[e.start]:02x}: expected a text spec") from None
    # every line ending as "\n", so line numbers match an editor's for old-Mac files too
    return text.lstrip("\ufeff").replace("\r\n", "\n").replace("\r", "\n")


def shorten(text: str, limit: int = 40) -> str:
    """``text`` quoted for a message, cut to ``limit`` characters so one bad token cannot fill
    the terminal."""
    return repr(text) if len(text) <= limit else repr(text[:limit]) + "..."


def _position(data: bytes, offset: int) -> tuple[int, int]:
    line = data.count(b"\n", 0, offset) + 1
    col = offset - (data.rfind(b"\n", 0, offset) + 1) + 1
    return line, col


def tokenize(text: str, path: str) -> list[Token]:
    tokens: list[Token] = []
    line, line_start, pos, depth = 1, 0, 0, 0
    while pos < len(text):
        m = _TOKEN_RE.match(text, pos)
        col = pos - line_start + 1
        if not m:
            ch = text[pos]
            shown = repr(ch) if ch.isprintable() else f"U+{ord(ch):04X}"
            hint = _OPERATOR_HINTS.get(ch)
            raise SpecError(path, line, col, f"unexpected character {shown}: expected a name, a "
                            "number or one of ~ & ^ | ( ) = , : - [ ]"
                            + (f" (write {hint})" if hint else ""))
        kind = m.lastgroup
        s = m.group()
        if kind in ("name", "number") and len(s) > MAX_TOKEN_CHARS:
            raise SpecError(path, line, col, f"{kind} {shorten(s)} has {len(s)} characters; "
                            f"expected at most {MAX_TOKEN_CHARS}")
        if kind == "nl":
            if depth == 0:
                tokens.append(Token("NEWLINE", "\n", line, col))
            line += 1
            line_start = m.end()
        elif kind == "name":
            tokens.append(Token("NAME", s, line, col))
        elif kind == "number":
            tokens.append(Token("NUMBER", s, line, col))
        elif kind == "op":
            if s == "(":
                depth += 1
            elif s == ")":
                depth = max(0, depth - 1)
            tokens.append(Token("OP", s, line, col))
        pos = m.end()
    tokens.append(Token("NEWLINE", "", line, pos - line_start + 1))  # "" marks end of file
    tokens.append(Token("EOF", "", line, pos - line_start + 1))
    return tokens


class TokenStream:
    """Cursor over tokens with helpers that raise located errors."""

    def __init__(self, tokens: list[Token], path: str):
        self.toks, self.i, self.path = tokens, 0, path

    @property
    def cur(self) -> Token:
        return self.toks[self.i]

    def peek(self, k: int = 1) -> Token:
        return self.toks[min(self.i + k, len(self.toks) - 1)]

    def advance(self) -> Token:
        t = self.toks[self.i]
        if t.kind != "EOF":
            self.i += 1
        return t

    def error(self, message: str, tok: Token | None = None) -> SpecError:
        t = tok or self.cur
        return SpecError(self.path, t.line, t.col, message)

    def describe(self, tok: Token | None = None) -> str:
        t = tok or self.cur
        if t.kind == "NEWLINE":
            return "end of line" if t.text else "end of file"
        if t.kind == "EOF":
            return "end of file"
        return shorten(t.text)

    def expect_op(self, op: str, what: str | None = None) -> Token:
        if self.cur.kind == "OP" and self.cur.text == op:
            return self.advance()
        raise self.error(f"expected {what or repr(op)}, found {self.describe()}")

    def expect_name(self, what: str = "a name") -> Token:
        if self.cur.kind == "NAME":
            return self.advance()
        raise self.error(f"expected {what}, found {self.describe()}")

    def expect_newline(self) -> None:
        if self.cur.kind in ("NEWLINE", "EOF"):
            if self.cur.kind == "NEWLINE":
                self.advance()
            return
        raise self.error(f"expected end of line, found {self.describe()}")

    def at_op(self, op: str) -> bool:
        return self.cur.kind == "OP" and self.cur.text == op

    def skip_newlines(self) -> None:
        while self.cur.kind == "NEWLINE":
            self.advance()
