"""``--accuracy F``: the choice from the error model (against brute force over the model), the
step-halving estimate (against a hand-made pair of runs), and the confirmation on a real run —
including a model that lies, which the run must catch."""

from __future__ import annotations

import itertools
import math

import pytest

from mechc.cells.library import load_library
from mechc.errors import UsageError
from mechc.frontends import load_spec
from mechc.pipeline import compile_spec
from mechc.proofs.accuracy import (
    ErrorModel,
    ModelPoint,
    choose,
    confirm,
    halving_error,
    load_model,
)
from mechc.proofs.dynamic import prove_with_accuracy
from tests.helpers import EXAMPLES

LIB = load_library()


def synthetic_model() -> ErrorModel:
    """Error falls with a smaller step and more iterations; one setting's solver broke."""
    pts = []
    for dt, it, mt in itertools.product((1e-4, 2.5e-4, 1e-3), (5, 20, 60), (0.04, 0.08)):
        err = 2.0 * dt / 1e-3 * (1 + 10 / it) * (0.05 / mt) ** 0.5 * 1e-2
        ok = not (dt == 1e-3 and it == 5)
        pts.append(ModelPoint(dt, it, mt, err if ok else math.inf, ok, (mt + 0.02) / dt))
    return ErrorModel(pts, overhead_iterations=8.0)


@pytest.mark.parametrize("target", [0.005, 0.01, 0.05, 0.2])
def test_choice_is_the_cheapest_point_meeting_the_target(target):
    m = synthetic_model()
    got = choose(target, m)
    # brute force: every point, its cost written out by hand
    fits = [p for p in m.points if p.solver_ok and p.error <= 0.5 * target]
    cheapest = min(p.steps_per_change * (p.iterations + 8.0) for p in fits)
    assert got.steps_per_change * (got.iterations + 8.0) == pytest.approx(cheapest)
    assert got.error <= 0.5 * target and got.solver_ok


def test_a_tighter_target_never_costs_less():
    m = synthetic_model()
    costs = [choose(t, m).cost(m.overhead_iterations) for t in (0.2, 0.05, 0.01, 0.004)]
    assert costs == sorted(costs)


def test_an_unreachable_target_is_refused_with_the_best_figure():
    with pytest.raises(UsageError, match="best measured"):
        choose(1e-6, synthetic_model())
    with pytest.raises(UsageError):
        choose(0.7, synthetic_model())


def test_halving_estimate_is_twice_the_largest_difference():
    coarse = [{"final": {"z": 0.502, "y": 0.0}}, {"final": {"z": 1.0, "y": 0.9990}}]
    fine = [{"final": {"z": 0.500, "y": 0.0}}, {"final": {"z": 1.0, "y": 0.9995}}]
    assert halving_error(coarse, fine) == pytest.approx(2 * 0.002)
    rep = {"max_position_error_fraction": 0.001, "failure_kinds": {}}
    ok = confirm(0.005, rep, coarse, fine)
    assert ok["confirmed"] and ok["obtained_fraction"] == pytest.approx(0.004)
    assert not confirm(0.003, rep, coarse, fine)["confirmed"]
    broke = confirm(0.5, {**rep, "failure_kinds": {"solver": 1}}, coarse, fine)
    assert not broke["confirmed"]  # a solver breakdown is never an accurate run


def test_the_packaged_model_is_the_benchmarks_and_well_formed():
    m = load_model()
    assert "speed_accuracy" in m.source
    assert len(m.points) >= 12 and m.overhead_iterations >= 0
    assert any(p.solver_ok for p in m.points) and not all(p.solver_ok for p in m.points)


@pytest.fixture(scope="module")
def adder():
    return compile_spec(load_spec(EXAMPLES / "full_adder.bool"))


def test_accuracy_run_meets_and_reports_the_target(adder):
    r = prove_with_accuracy(adder, adder.spec, LIB, 0.01, extra=0)
    acc = r["accuracy"]
    assert acc["confirmed"] and r["passed"], r["failures"][:3]
    assert acc["obtained_fraction"] <= 0.01
    # what it reports is what it ran
    assert r["settings"]["dt_s"] == acc["chosen"]["dt_s"]
    assert r["settings"]["iterations"] == acc["chosen"]["iterations"]
    assert acc["obtained_fraction"] >= r["max_position_error_fraction"]


def test_a_lying_model_is_caught_on_the_run(adder):
    """A model claiming that a 4 ms step with 2 iterations is accurate: the run's own
    measurements refute it and the proof fails with an 'accuracy' failure."""
    liar = ErrorModel([ModelPoint(4e-3, 2, 0.08, 1e-5, True, 50.0)], 0.0, "test")
    r = prove_with_accuracy(adder, adder.spec, LIB, 0.01, model=liar, extra=0)
    assert not r["accuracy"]["confirmed"] and not r["passed"]
    assert r["failures"][0]["kind"] == "accuracy"
    assert r["accuracy"]["obtained_fraction"] > 0.01 or r["accuracy"]["solver_breakdown"]


def test_cli_accuracy(cli, tmp_path):
    code, out, err = cli("simulate", EXAMPLES / "full_adder.bool", "--accuracy", "0.01",
                         "--cases", "0")
    assert code == 0, out + err
    assert "confirmed" in out and "accuracy 0.01" in out
    code, out, err = cli("simulate", EXAMPLES / "full_adder.bool", "--accuracy", "0.01",
                         "--dt", "1e-4")
    assert code == 2 and "--accuracy chooses" in err
