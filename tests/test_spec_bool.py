"""The .bool front end: the core syntax, precedence, and located errors."""

from __future__ import annotations

import numpy as np
import pytest

from mechc.errors import SpecError
from mechc.frontends.boolfile import parse_bool
from mechc.logic.cubes import DC

CORE = """\
# soap-box sorter
inputs A B C D
outputs Z Y
Z = C & D | A & ~B & D | ~A & B & C
Y = minterms(0, 3, 5) dontcare(7, 9)
"""


def bits(m, n):
    return [(m >> (n - 1 - k)) & 1 for k in range(n)]


def test_core_example_accepted_exactly_as_written():
    s = parse_bool(CORE, "core.bool")
    assert s.inputs == ["A", "B", "C", "D"] and s.outputs == ["Z", "Y"]
    for m in range(16):
        a, b, c, d = bits(m, 4)
        assert s.table("Z")[m] == int((c and d) or (a and not b and d) or (not a and b and c))
    y = s.table("Y")
    assert [int(m) for m in np.flatnonzero(y == 1)] == [0, 3, 5]
    assert [int(m) for m in np.flatnonzero(y == DC)] == [7, 9]


def test_first_input_is_most_significant_bit():
    s = parse_bool("inputs P Q R\noutputs F\nF = minterms(4)\n")
    # minterm 4 = 100: P=1, Q=0, R=0
    t = s.table("F")
    assert t[4] == 1 and t.sum() == 1
    s2 = parse_bool("inputs P Q R\noutputs F\nF = P & ~Q & ~R\n")
    assert (s2.table("F") == t).all()


@pytest.mark.parametrize("expr, fn", [
    ("a | b & c", lambda a, b, c: a or (b and c)),        # & binds tighter than |
    ("a ^ b & c", lambda a, b, c: a ^ (b and c)),          # & tighter than ^
    ("a | b ^ c", lambda a, b, c: a or (b ^ c)),           # ^ tighter than |
    ("~a & b", lambda a, b, c: (not a) and b),             # ~ tightest
    ("~(a & b)", lambda a, b, c: not (a and b)),
    ("a ^ b ^ c", lambda a, b, c: a ^ b ^ c),
    ("~~a", lambda a, b, c: a),
    ("(a | b) & c", lambda a, b, c: (a or b) and c),
    ("1 & a | 0", lambda a, b, c: a),
])
def test_precedence(expr, fn):
    s = parse_bool(f"inputs a b c\noutputs f\nf = {expr}\n")
    for m in range(8):
        assert s.table("f")[m] == int(bool(fn(*bits(m, 3)))), (expr, m)


def test_comments_blank_lines_and_continuation():
    s = parse_bool("# c\n\ninputs a b # two\n\noutputs f\nf = a |\n  b # cont\n")
    assert list(s.table("f")) == [0, 1, 1, 1]


def test_expression_with_dontcare_extension():
    s = parse_bool("inputs a b\noutputs f\nf = a & b dontcare(1)\n")
    assert list(s.table("f")) == [0, DC, 0, 1]


# ---- errors: file, line, column and what was expected ------------------------------------------
ERRORS = [
    # (text, line, col, words expected in the message)
    ("", 1, 1, "empty"),
    ("   \n# only a comment\n", 3, 1, "empty"),
    ("outputs Z\n", 1, 1, "'inputs'"),
    ("inputs A B\nZ = A\n", 2, 1, "'outputs'"),
    # an operator at the end of a line continues the expression: the error is at end of file
    ("inputs A B\noutputs Z\nZ = A & \n", 4, 1, "found end of file"),
    ("inputs A B\noutputs Z\nZ = (A & B\n", 4, 1, "')' to close the '(' at line 3 column 5"),
    ("inputs A B\noutputs Z\nZ = A & B)\n", 3, 10, "expected an operator"),
    ("inputs A B\noutputs Z\nZ = A $ B\n", 3, 7, "unexpected character"),
    ("inputs A B\noutputs Z\nZ = A & Q\n", 3, 9, "unknown name 'Q'"),
    ("inputs A A\noutputs Z\nZ = A\n", 1, 10, "duplicate name 'A'"),
    ("inputs A B\noutputs Z Z\nZ = A\n", 2, 11, "duplicate name 'Z'"),
    ("inputs A B\noutputs A\n", 2, 9, "duplicate name 'A'"),
    ("inputs A B\noutputs Z Y\nZ = A\n", 2, 11, "never defined"),
    ("inputs A B\noutputs Z\nZ = A\nZ = B\n", 4, 1, "second time"),
    ("inputs A B\noutputs Z\nW = A\n", 3, 1, "not a declared output"),
    ("inputs A B\noutputs Z\nA = B\n", 3, 1, "is an input"),
    ("inputs A B\noutputs Z\nZ = minterms(4)\n", 3, 14, "out of range"),
    ("inputs A B\noutputs Z\nZ = minterms(1) dontcare(1)\n", 3, 26, "both"),
    ("inputs A B\noutputs Z\nZ = minterms(1, 1)\n", 3, 17, "twice"),
    ("inputs A B\noutputs Z\nZ = minterms(99999999999999999999999)\n", 3, 14, "out of range"),
    ("inputs A B\noutputs Z\nZ = minterms(1 2)\n", 3, 16, "expected ',' or ')'"),
    ("inputs A B\noutputs Z\nZ = minterms(1,)\n", 3, 16, "after ','"),
    ("inputs A B\noutputs Z\nZ = minterms 1\n", 3, 14, "'('"),
    ("inputs A B\noutputs Z\nZ = minterms(a)\n", 3, 14, "minterm number"),
    ("inputs A B\noutputs Z\nZ A\n", 3, 3, "'='"),
    ("inputs A B\noutputs Z\nZ = dontcare(1)\n", 3, 5, "before dontcare"),
    ("inputs A B\noutputs Z\nZ = Z\n", 3, 5, "is an output"),
    ("inputs\noutputs Z\n", 1, 7, "at least one input"),
    ("inputs A B\noutputs\n", 2, 8, "at least one output"),
    ("inputs A B\ninputs C\n", 2, 1, "second time"),
    ("inputs A B\noutputs Z\nZ = A & 2\n", 3, 9, "constant 0/1"),
    ("inputs A B\noutputs Z\nZ = ~\n", 3, 6, "expected a name"),
    ("inputs A minterms\noutputs Z\n", 1, 10, "keyword"),
    ("inputs A B\noutputs Z\nZ = A & minterms(1)\n", 3, 9, "whole right-hand side"),
    ("inputs A B\noutputs Z\nZ = A\n\u00e9\n", 4, 1, "unexpected character"),
    ("inputs A B\noutputs Z\n= A\n", 3, 1, "expected an output assignment"),
    ("inputs " + " ".join(f"x{i}" for i in range(21)) + "\n", 1, 1, "at most 20"),
]


@pytest.mark.parametrize("text, line, col, words", ERRORS)
def test_error_locations(text, line, col, words):
    with pytest.raises(SpecError) as ei:
        parse_bool(text, "bad.bool")
    e = ei.value
    assert (e.line, e.col) == (line, col), str(e)
    assert words in e.message, str(e)
    assert str(e).startswith(f"bad.bool:{line}:{col}: error: ")
    assert "\n" not in str(e)
