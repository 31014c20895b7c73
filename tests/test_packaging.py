"""The package list in pyproject.toml matches the tree, and the cell library installs under
mechc's own namespace (never as a generic top-level ``stdlib``)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def test_every_package_is_listed():
    tomllib = pytest.importorskip("tomllib", reason="tomllib is in the standard library from 3.11")
    conf = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]
    listed = set(conf["packages"])
    tree = {".".join(p.parent.relative_to(ROOT).parts) for p in (ROOT / "mechc").rglob(
        "__init__.py")}
    assert tree <= listed, f"packages missing from pyproject.toml: {sorted(tree - listed)}"
    assert "stdlib" not in listed
    assert conf["package-dir"]["mechc.stdlib"] == "stdlib"


def test_cell_library_is_mechc_stdlib(tmp_path):
    code = ("import importlib.util, mechc.stdlib.and_gate as m; "
            "print(importlib.util.find_spec('stdlib') is None, m.AndGate.name)")
    out = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True,
                         text=True, check=True).stdout.split()
    assert out == ["True", "and"]
