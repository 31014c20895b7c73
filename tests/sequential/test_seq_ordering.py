"""Ordering requirements decided at compile (issue 15): compile never hands out a design whose
essential hazard or SET/RESET ordering the mechanism does not meet. The references are
independent of the pass under test: a hand-written input sequence through the hazard, the
dynamic proof itself, and the timing inequality worked out by hand from the cells' delays."""

from __future__ import annotations

import json

import numpy as np
import pytest

from mechc.bench.circuits import random_flow_table
from mechc.cells.library import load_library
from mechc.frontends.fsm import parse_fsm_file
from mechc.ir.design import Design
from mechc.ir.netlist import CellInst
from mechc.ir.seqspec import SeqSpec
from mechc.passes.amplify import _rebuild, amplifier_cell
from mechc.passes.checks import run_design_checks
from mechc.passes.ordering import (
    CHECK_NAME,
    MARGIN_S,
    _steps_of,
    decide_ordering,
    find_requirements,
    timing_inequality,
    tour_of,
)
from mechc.physics.scene import DynSettings
from mechc.pipeline import CompileOptions, assemble_powered, compile_sequential, design_stats
from mechc.proofs.hold import MEMORY_THROW_S
from mechc.proofs.seq_logic import prove_sequential
from mechc.proofs.seq_mechanism import prove_sequential_dynamic, prove_sequential_kinematic
from tests.helpers import EXAMPLES

LIB = load_library()
SPEEDCTL = EXAMPLES / "speedctl.fsm"
#: The speed controller's essential hazard by hand: state 1 at 00, x1 up (state 2), x2 up
#: (5), x2 down (6), x1 down: state 6 at 10 with x1 falling must end in state 1.
THROUGH_HAZARD = [{"x1": a, "x2": b} for a, b in ((0, 0), (1, 0), (1, 1), (1, 0), (0, 0))]


def _delay_one_load(design: Design, net: str, consumer: str):
    """The netlist with one AMPLIFIER between ``net`` and the one cell ``consumer`` (every
    other load of the net stays direct): a skew the hazard cannot stand."""
    cells = {c.id: c for c in design.netlist.cells.values()}
    c = cells[consumer]
    cells[consumer] = CellInst(c.id, c.cell, c.type,
                               tuple("late" if n == net else n for n in c.inputs), c.outputs,
                               c.params)
    cells["late1"] = CellInst("late1", amplifier_cell(LIB).name, "AMPLIFIER", (net,),
                              ("late",), {"reason": "test"})
    return _rebuild(design.netlist, LIB, list(cells.values()), dict(design.netlist.outputs))


def _built(design: Design, nl) -> Design:
    nl, layout, mech, _ = assemble_powered(nl, LIB, CompileOptions(), None)
    d = Design(design.spec, design.equations, design.implemented, nl, layout,
               design_stats(design.eq, nl, LIB, layout), {}, design.eq, mech,
               design.sequential)
    run_design_checks(d, LIB)
    return d


@pytest.fixture(scope="module")
def speedctl():
    return compile_sequential(parse_fsm_file(str(SPEEDCTL)), library=LIB)


def _consumer_of(design: Design, net: str, memory_net: str) -> str:
    """The gate that reads both ``net`` and ``memory_net`` (x1 & y2 in y1's SET)."""
    return next(c.id for c in design.netlist.cells.values()
                if net in c.inputs and memory_net in c.inputs)


def test_speed_controller_requirements_are_found_timed_and_met(speedctl):
    o = speedctl.stats["sequential"]["ordering"]
    kinds = sorted(r["kind"] for r in o["requirements"])
    assert kinds == ["essential", "set-reset-together"]
    ess = next(r for r in o["requirements"] if r["kind"] == "essential")
    assert ess["input"] == "x1" and ess["memories"] == ["y2"]
    assert ess["transitions"] == ["state 6 at x1 x2 = 10, x1 falling"]  # Unger's hazard
    assert all(r["met"] and r["dynamic_steps"] >= 1 for r in o["requirements"])
    assert not o["cure"] and speedctl.stats["design_checks"]["passed"]
    names = [c.name for c in speedctl.mechanism.checks]
    assert names.count(CHECK_NAME) == 2


def test_inequality_by_hand(speedctl):
    # x1 reaches y1's SET generator one AMPLIFIER late; y2 (set = ~x1) switches at half the
    # move, takes its throw, and feeds back through no delay cell
    late = _delay_one_load(speedctl, "x1", _consumer_of(speedctl, "x1", "y2"))
    req = next(r for r in find_requirements(late, speedctl.spec,
                                            speedctl.sequential.essential_hazards)
               if r.kind == "essential")
    move = DynSettings().move_time
    amp = amplifier_cell(LIB).switching_delay_s
    t = timing_inequality(late, LIB, req, move)
    assert t["t_input_s"] == pytest.approx(move + amp, abs=1e-4)
    assert t["t_memory_feedback_s"] == pytest.approx(move / 2 + MEMORY_THROW_S, abs=1e-4)
    need = MARGIN_S - (move / 2 + MEMORY_THROW_S - move - amp)
    assert t["feedback_delay_needed_s"] == pytest.approx(need, abs=1e-4)
    assert not t["met"]
    direct = timing_inequality(speedctl.netlist, LIB, req, move)
    assert direct["t_input_s"] == pytest.approx(move, abs=1e-4)


def test_tour_takes_exactly_the_wanted_transitions():
    spec = parse_fsm_file(str(SPEEDCTL))
    for seed in range(4):
        rng = np.random.default_rng(seed)
        steps = list(_steps_of(spec, tour_of(spec, set())).values())
        assert steps == []
        every = set(_steps_of(spec, [[*s] for s in _all(spec)]).values())
        wanted = {tr for tr in every if rng.random() < 0.4}
        taken = set(_steps_of(spec, tour_of(spec, wanted)).values())
        assert wanted <= taken


def _all(spec: SeqSpec):
    from mechc.proofs.seq_logic import transition_tour

    return transition_tour(spec)


@pytest.mark.slow
def test_late_input_is_rejected_and_cured(speedctl):
    spec = speedctl.spec
    late = _built(speedctl, _delay_one_load(speedctl, "x1",
                                            _consumer_of(speedctl, "x1", "y2")))
    # the reference: the dynamic proof through the hazard, by a hand-written sequence
    ref = prove_sequential_dynamic(late, spec, LIB, sequences=[THROUGH_HAZARD])
    assert not ref["passed"] and ref["failures"][0]["step"] == 4
    # without a cure compile must refuse it, naming the essential requirement
    refused = decide_ordering(late, LIB, lambda nl, why: None)
    dc = refused.stats["design_checks"]
    assert not dc["passed"]
    assert any(CHECK_NAME in t and "essential" in t and "x1" in t for t in dc["failed"])
    # with one, the feedback of y2 is delayed by as many cells as the inequality asks for
    cured = decide_ordering(_built(speedctl, late.netlist), LIB,
                            lambda nl, why: _built(speedctl, nl))
    cure = cured.stats["sequential"]["ordering"]["cure"]
    assert cure["kept"] and cure["feedback_delay_on"] == {"y2": 2}
    assert cured.stats["design_checks"]["passed"]
    assert prove_sequential_dynamic(cured, spec, LIB, sequences=[THROUGH_HAZARD])["passed"]


def _random_spec(seed: int, rows: tuple[int, int]) -> SeqSpec:
    rng = np.random.default_rng(seed)
    ft = random_flow_table(rng, int(rng.integers(rows[0], rows[1] + 1)),
                           int(rng.integers(1, 4)), int(rng.integers(1, 4)), p_dc_output=0.25)
    return SeqSpec(f"<random {seed}>", ft.inputs, ft.outputs, table=ft)


def _accepted_pass_everything(spec: SeqSpec) -> bool:
    """Compile; an accepted design must pass all three proofs. Returns whether accepted."""
    d = compile_sequential(spec, library=LIB)
    if not d.stats["design_checks"]["passed"]:
        return False
    assert prove_sequential(d.netlist, spec)["passed"]
    assert prove_sequential_kinematic(d, spec, LIB)["passed"]
    dyn = prove_sequential_dynamic(d, spec, LIB)
    assert dyn["passed"], dyn["failures"][:3]
    return True


@pytest.mark.parametrize("seed", [900, 903])
def test_accepted_small_random_tables_pass_every_proof(seed):
    assert _accepted_pass_everything(_random_spec(seed, (3, 5)))


@pytest.mark.slow
@pytest.mark.parametrize("seed", range(1500, 1506))
def test_accepted_random_tables_pass_every_proof(seed):
    _accepted_pass_everything(_random_spec(seed, (3, 8)))


def test_compile_summary_and_json_show_each_requirement(cli, tmp_path):
    out = tmp_path / "s.json"
    code, stdout, err = cli("compile", SPEEDCTL, "-o", out)
    assert code == 0, err
    assert "ordering requirements (2;" in stdout
    assert stdout.count("inequality:") == 2 and stdout.count("dynamic walk (1 step(s)): met") == 2
    obj = json.loads(out.read_text())
    o = obj["stats"]["sequential"]["ordering"]
    ess = next(r for r in o["requirements"] if r["kind"] == "essential")
    assert ess["timing"]["t_input_s"] > 0 and "slack_s" in ess["timing"] and ess["met"]
