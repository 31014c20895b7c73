"""The espresso PLA front end: characters and types as espresso reads them, and errors."""

from __future__ import annotations

import numpy as np
import pytest

from mechc.errors import SpecError
from mechc.frontends.pla import parse_pla
from mechc.logic.cubes import DC


def table(text, out=0):
    s = parse_pla(text, "t.pla")
    return s, s.table(s.outputs[out])


def test_f_type_and_labels():
    s, t = table(".i 2\n.o 1\n.ilb a b\n.ob z\n.type f\n1- 1\n01 1\n.e\n")
    assert s.inputs == ["a", "b"] and s.outputs == ["z"]
    assert list(t) == [0, 1, 1, 1]


def test_default_type_is_fd_and_dash_is_dontcare():
    _, t = table(".i 2\n.o 1\n11 1\n0- -\n.e\n")
    assert list(t) == [DC, DC, 0, 1]


def test_fd_on_and_dc_overlap_is_dontcare():
    _, t = table(".i 2\n.o 1\n1- 1\n11 -\n")
    assert list(t) == [0, 0, 1, DC]


def test_fr_type_rest_is_dontcare_and_zero_is_offset():
    _, t = table(".i 2\n.o 1\n.type fr\n11 1\n00 0\n")
    assert list(t) == [0, DC, DC, 1]


def test_fdr_type():
    _, t = table(".i 2\n.o 1\n.type fdr\n11 1\n00 0\n01 -\n")
    assert list(t) == [0, DC, DC, 1]


def test_r_and_dr_types_complement_the_offset():
    _, t = table(".i 2\n.o 1\n.type r\n00 0\n")
    assert list(t) == [0, 1, 1, 1]
    _, t = table(".i 2\n.o 1\n.type dr\n00 0\n01 -\n")
    assert list(t) == [0, DC, 1, 1]


def test_espresso_alternative_characters():
    # input '2' = '-'; output '4' = '1', '3' = '0', '2' = '-', '~' = nothing
    _, t1 = table(".i 3\n.o 2\n.type fdr\n2-1 43\n000 2~\n")
    _, t2 = table(".i 3\n.o 2\n.type fdr\n--1 10\n000 -~\n")
    assert (t1 == t2).all()
    s, t = table(".i 3\n.o 2\n.type fdr\n2-1 43\n000 2~\n", out=1)
    assert t[1] == 0 and t[0] == DC  # '~' put minterm 0 in no set of output 2: rest (dc)


def test_question_mark_is_an_empty_term_and_separators_are_ignored():
    _, t = table(".i 2\n.o 1\n.type f\n?1 1\n1 | 1   1\n")
    assert list(t) == [0, 0, 0, 1]


def test_f_type_ignores_dash_and_zero_in_output():
    _, t = table(".i 2\n.o 2\n.type f\n11 1-\n00 01\n")
    assert list(t) == [0, 0, 0, 1]


def test_comments_and_p_are_ignored():
    _, t = table("# hi\n.i 1\n.o 1\n.p 99\n# more\n1 1\n.end\n")
    assert list(t) == [0, 1]


ERRORS = [
    ("", 1, 1, "empty PLA"),
    (".o 1\n", 1, 1, "'.o' must come after '.i'"),
    (".i 2\n1- 1\n", 2, 1, "before '.i' and '.o'"),
    (".i x\n", 1, 4, "whole number"),
    (".i 2\n.o 1\n1-- 1\n", 3, 1, "expected 2 inputs + 1 outputs = 3"),
    (".i 2\n.o 1\n1x 1\n", 3, 2, "bad input-plane character"),
    (".i 2\n.o 1\n11 x\n", 3, 4, "bad output-plane character"),
    (".i 2\n.o 1\n.type q\n", 3, 1, "after '.type'"),
    (".i 2\n.o 1\n.ilb a\n", 3, 1, "expected 2"),
    (".i 2\n.o 1\n.ilb a a\n", 3, 1, "duplicate"),
    (".i 2\n.o 1\n.ilb a b\u00e9\n", 3, 8, "does not accept"),
    (".i 2\n.o 1\n.mv 3 2\n", 3, 1, "not supported"),
    (".i 2\n.o 1\n.foo\n", 3, 1, "unknown keyword"),
    (".i 2\n.o 1\n.e\n11 1\n", 4, 1, "after '.e'"),
    (".i 2\n.o 1\n.type fr\n1- 1\n11 0\n", 4, 4, "meets the off-set term of line 5"),
    (".i 2\n.o 1\n11 1\n.type fr\n", 4, 1, "before the product terms"),
    (".i 2\n.i 2\n", 2, 1, "given twice"),
]


@pytest.mark.parametrize("text, line, col, words", ERRORS)
def test_errors(text, line, col, words):
    with pytest.raises(SpecError) as ei:
        parse_pla(text, "bad.pla")
    assert (ei.value.line, ei.value.col) == (line, col), str(ei.value)
    assert words in ei.value.message, str(ei.value)


def test_default_names_when_no_labels():
    s = parse_pla(".i 3\n.o 2\n111 11\n")
    assert s.inputs == ["x0", "x1", "x2"] and s.outputs == ["f0", "f1"]
    assert np.flatnonzero(s.table("f1") == 1).tolist() == [7]


def test_bus_style_names_become_identifiers_with_the_originals_kept():
    s = parse_pla(".i 3\n.o 2\n.ilb di<11> x[3] a.b\n.ob z<0> 3y\n11- 10\n-11 01\n.e\n", "t.pla")
    assert s.inputs == ["di_11", "x_3", "a_b"] and s.outputs == ["z_0", "s3y"]
    assert s.display == {"di_11": "di<11>", "x_3": "x[3]", "a_b": "a.b", "z_0": "z<0>",
                         "s3y": "3y"}
    assert list(s.table("z_0")) == [0, 0, 0, 0, 0, 0, 1, 1]


def test_safe_names_stay_unique():
    # x[1] would become x_1, which is already a name of its own
    s = parse_pla(".i 2\n.o 1\n.ilb x_1 x[1]\n11 1\n.e\n", "t.pla")
    assert s.inputs == ["x_1", "x_1_2"] and s.display == {"x_1_2": "x[1]"}


def test_name_with_a_character_espresso_refuses_names_line_and_column():
    with pytest.raises(SpecError) as e:
        parse_pla(".i 2\n.o 1\n.ilb a b\u00e9\n11 1\n", "t.pla")
    assert "t.pla:3:8" in str(e.value)


def test_bracket_names_compile_and_round_trip_through_the_json(tmp_path):
    """The design JSON keeps the spec's own names (stats.names), the summary shows them, and
    the file passes the checks every reader makes."""
    import json

    from mechc.backends.design_json import check_design
    from tests.helpers import run_subprocess

    pla = tmp_path / "bus.pla"
    pla.write_text(".i 3\n.o 2\n.ilb di<11> x[3] a.b\n.ob z<0> 3y\n11- 10\n-11 01\n1-1 11\n.e\n")
    out = tmp_path / "bus.json"
    r = run_subprocess("compile", pla, "-o", out)
    assert r.returncode == 0, r.stderr
    assert "di<11> as di_11" in r.stdout and "z<0> as z_0" in r.stdout
    obj = json.loads(out.read_text())
    check_design(obj, str(out))
    names = obj["stats"]["names"]
    assert {names[k] for k in obj["inputs"]} == {"di<11>", "x[3]", "a.b"}
    assert sorted(names[k] for k in obj["outputs"]) == ["3y", "z<0>"]
    assert obj["stats"]["products"] == 3
