"""``mechc bench`` runs minutes: it names each study as it starts, with the time so far."""

from __future__ import annotations

from types import SimpleNamespace

from mechc.bench import speed_accuracy as sa


def test_each_study_is_announced_before_it_runs(monkeypatch, tmp_path, capsys):
    ran: list[str] = []

    def study(name, result=None):
        def fn(*args, **kwargs):
            ran.append(name)
            print(f"RUN {name}")
            return result
        return fn

    design = SimpleNamespace(spec=SimpleNamespace(inputs=["a"]))
    fa = SimpleNamespace(name="full_adder", design=design, note="")
    r30 = SimpleNamespace(name="random30", design=design, note="")
    monkeypatch.setattr(sa, "bench_circuits", study("circuits", [fa, r30]))
    monkeypatch.setattr(sa, "cell_count", lambda d: 0)
    monkeypatch.setattr(sa, "levels", study("levels"))
    monkeypatch.setattr(sa, "pruning", study("pruning"))
    monkeypatch.setattr(sa, "grid", study("grid", []))
    monkeypatch.setattr(sa, "step_overhead", study("overhead", 1.0))
    monkeypatch.setattr(sa, "error_model", lambda *a: SimpleNamespace(to_json=lambda: {}))
    monkeypatch.setattr(sa, "stability_study", study("stability"))
    monkeypatch.setattr(sa, "peers", study("peers"))
    for name in ("write_csv", "chart", "stability_chart"):
        monkeypatch.setattr(sa, name, lambda *a, **k: None)
    sa.run(True, tmp_path, None)
    lines = capsys.readouterr().out.splitlines()
    announced = [ln for ln in lines if ln.startswith("[")]
    assert len(announced) == 7 and announced[0].startswith("[1/7] compile the circuits")
    assert all("s so far)" in ln for ln in announced)
    # every study's own output comes after its announcement and before the next one
    order = [ln for ln in lines if ln.startswith("[") or ln.startswith("RUN ")]
    assert [ln.split()[0] for ln in order if ln.startswith("[")] == [f"[{k}/7]" for k in
                                                                      range(1, 8)]
    for k, ln in enumerate(order):
        if ln.startswith("RUN "):
            assert order[k - 1].startswith("["), order
    assert ran == ["circuits", "levels", "pruning", "grid", "overhead", "stability", "peers"]
