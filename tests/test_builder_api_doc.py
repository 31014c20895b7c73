"""docs/builder-api.md is generated from the Builder's docstrings: it must be what the generator
gives now, list every public method with its signature, and every method must say something."""

from __future__ import annotations

import inspect

from mechc.cells import api_doc
from mechc.cells.builder import Builder


def test_builder_api_doc_is_up_to_date():
    assert api_doc.DOC.read_text(encoding="utf-8") == api_doc.render(), \
        "docs/builder-api.md is out of date: run python -m mechc.cells.api_doc"


def test_every_public_builder_method_is_documented_with_its_signature():
    text = api_doc.DOC.read_text(encoding="utf-8")
    names = [n for n, f in inspect.getmembers(Builder, inspect.isfunction)
             if not n.startswith("_")]
    assert {"or_bar", "and_bar", "not_lever", "size", "finish", "input_slider"} <= set(names)
    for n in names:
        f = getattr(Builder, n)
        doc = inspect.getdoc(f) or ""
        assert len(doc.split()) >= 5, f"Builder.{n} needs a docstring that says why"
        # the signature as Python prints it, without self
        sig = inspect.signature(f, eval_str=True)
        params = list(sig.parameters.values())[1:]
        assert f"b.{n}{sig.replace(parameters=params)}" in text, n
    # the re-sizing step is explained where a cell writer looks for it
    size_doc = text.split("### size", 1)[1].split("### ", 1)[0]
    assert "replaced" in size_doc and "Demand()" in size_doc


def test_check_mode_detects_a_stale_file(tmp_path, monkeypatch):
    stale = tmp_path / "builder-api.md"
    stale.write_text(api_doc.render().replace("or_bar", "or-bar", 1))
    monkeypatch.setattr(api_doc, "DOC", stale)
    assert api_doc.main(["--check"]) == 1
    assert api_doc.main([]) == 0 and api_doc.main(["--check"]) == 0
