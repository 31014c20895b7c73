"""``mechc synth`` from the command line, and the positions file format."""

from __future__ import annotations

import json

import numpy as np
import pytest

from mechc.errors import SpecError
from mechc.linkage_synthesis.examples import EXAMPLES
from mechc.linkage_synthesis.positions import format_positions, parse_positions

FIG4 = """\
# Figure 4 of Mather & Erdman (2023)
x     y     alpha   beta
0     0     0       0
1.75  1     -50     -110
3.5   2     -90     ?
5.5   1     -110    ?
"""


def test_positions_file_parses_like_the_example():
    pr = parse_positions(FIG4, "fig4.pos")
    ex = EXAMPLES["fig4"].problem
    assert np.allclose(pr.points, ex.points)
    assert np.allclose(pr.angles, ex.angles, equal_nan=True)
    again = parse_positions(format_positions(pr, "round trip"))
    assert np.allclose(again.angles, pr.angles, equal_nan=True) and again.free_link == 0


@pytest.mark.parametrize("text,line,col,msg", [
    ("x y alpha delta\n0 0 0 0\n", 1, 11, "unknown column 'delta'"),
    ("x y alpha beta\n0 0 0 0\n1 1 x 3\n", 3, 5, "alpha: expected degrees"),
    ("x y alpha beta\n0 0 0 0\n1 2 3\n", 3, 1, "expected 4 values"),
    ("# nothing\n", 1, 1, "empty positions file"),
    ("x y alpha beta\n0 0 0 0\n1 1 ? ?\n2 2 1 ?\n", 2, 1, "only one link"),
    ("free delta\n", 1, 1, "expected 'free beta'"),
])
def test_positions_errors_point_at_the_place(text, line, col, msg):
    with pytest.raises(SpecError) as ei:
        parse_positions(text, "p.pos")
    e = ei.value
    assert (e.line, e.col) == (line, col) and msg in e.message


def test_dyad_file_json(cli, tmp_path):
    f = tmp_path / "fig4.pos"
    f.write_text(FIG4)
    png = tmp_path / "fig4.png"
    code, out, err = cli("synth", "dyad", f, "--json", "--plot", png, "--defects")
    assert code == 0, err
    ans = json.loads(out)
    assert ans["mode"] == "intersection" and len(ans["solutions"]) == 2
    assert all(s["residual"] < 1e-12 for s in ans["solutions"])
    assert len(ans["fourbars"]) == 2
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]  # no temp left


def test_free_choice_option_overrides(cli, tmp_path):
    f = tmp_path / "fig4.pos"
    f.write_text(FIG4)
    code, out, _ = cli("synth", "dyad", f, "--free", "beta2=-100", "--json")
    ans = json.loads(out)
    assert code == 0 and ans["solutions"]
    assert all(abs(s["angles_deg"]["beta"][1] + 100) < 1e-9 for s in ans["solutions"])


def test_triad_example_and_errors(cli, tmp_path):
    code, out, _ = cli("synth", "triad", "--example", "figA5", "--json")
    assert code == 0 and json.loads(out)["solutions"]
    code, _, err = cli("synth", "triad", "--example", "fig9")
    assert code == 2 and "unknown example" in err
    code, _, err = cli("synth", "triad", "--example", "fig4")
    assert code == 2 and "dyad" in err
    f = tmp_path / "fig4.pos"
    f.write_text(FIG4)
    code, _, err = cli("synth", "triad", f)
    assert code == 2 and "describe a dyad" in err
    code, _, err = cli("synth", "dyad", tmp_path / "missing.pos")
    assert code == 2 and "no such positions file" in err
    code, _, err = cli("synth", "dyad", f, "--free", "alpha2=3")
    assert code == 2 and "beta" in err


def test_dyad_without_solution_exits_1(cli, tmp_path):
    # five positions that no dyad reaches: the circles are never concurrent
    f = tmp_path / "none.pos"
    f.write_text("x y alpha beta\n0 0 0 0\n1 0 0 ?\n2 0 0 ?\n3 0 0 ?\n4 0.5 0 ?\n")
    code, out, _ = cli("synth", "dyad", f, "--json")
    ans = json.loads(out)
    assert code == 1 and ans["solutions"] == []


def test_three_bar_text_and_plot(cli, tmp_path):
    png = tmp_path / "tb.svg"
    code, out, _ = cli("synth", "three-bar", "--sep", "50", "--stroke", "40", "--output", "150",
                       "--plot", png, "--no-alternatives")
    assert code == 0 and out.startswith("healthy 3-bar gate")
    assert png.read_text().lstrip().startswith("<?xml")


def test_three_bar_bad_input(cli, capsys):
    with pytest.raises(SystemExit) as ei:  # argparse rejects it before mechc runs
        cli("synth", "three-bar", "--sep", "-5", "--stroke", "40")
    assert ei.value.code == 2 and "must be positive" in capsys.readouterr().err


def test_adder_json(cli):
    code, out, _ = cli("synth", "adder", "--weights", "1,2", "--lever", "60", "--bars",
                       "300,300", "--range1", "0:20", "--range2", "0:20", "--json",
                       "--samples", "11")
    ans = json.loads(out)
    assert code == 0
    assert abs(ans["weights"][0] - 1 / 3) < 1e-12
    assert 0 < ans["max_abs_error"] <= ans["bound_eq15"]
