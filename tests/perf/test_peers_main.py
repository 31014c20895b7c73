"""``python -m mechc.bench.peers`` runs the four-bar peer figures alone and ends in the same
``name: value`` lines as the speed benchmark."""

from __future__ import annotations

from mechc.bench import peers
from mechc.bench.fourbar import PeerResult


def test_the_fourbar_figures_alone_end_in_name_value_lines(monkeypatch, capsys):
    r = PeerResult(mechc_per_s=30e6, pylinkage_step_per_s=0.2e6, pylinkage_fast_per_s=6e6,
                   pylinkage_backend="numba", max_difference_mm=1e-12, positions=1000,
                   bare_numpy_per_s=40e6, numba_kernel_per_s=60e6, mechc_reduced_per_s=27e6)
    monkeypatch.setattr(peers, "compare", lambda: r)
    # alternating rounds: the median ratio is the headline, a spike's round (2.0) left out
    monkeypatch.setattr(peers, "paired", lambda: peers.Paired([5.5, 2.0, 5.0, 6.0, 5.2],
                                                              [4.5, 1.9, 4.4, 5.0, 4.6]))
    assert peers.main() == 0
    lines = dict(ln.split(": ", 1) for ln in capsys.readouterr().out.splitlines()
                 if ": " in ln and " " not in ln.split(": ", 1)[0])
    assert float(lines["kinematic_vs_pylinkage"]) == 5.2  # the median of the rounds
    assert float(lines["kinematic_vs_pylinkage_min"]) == 2.0
    assert float(lines["kinematic_reduced_vs_pylinkage"]) == 4.5  # with the checks' figures
    assert float(lines["positions_only_numpy_vs_pylinkage"]) == round(40 / 6, 3)
    assert float(lines["kinematic_vs_pylinkage_step"]) == 150.0
    assert lines["pylinkage_backend"] == "numba"


def test_without_pylinkage_the_figure_is_marked_missing(monkeypatch, capsys):
    def missing():
        raise ModuleNotFoundError("No module named 'pylinkage'")

    monkeypatch.setattr(peers, "compare", missing)
    assert peers.main() == 0
    out = capsys.readouterr().out
    assert "kinematic_vs_pylinkage: n/a" in out and "pip install" in out
