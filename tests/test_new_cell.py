"""``mechc new-cell``: the template cell and its test work as written, and nothing is ever
overwritten."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

from tests.helpers import EXAMPLES


@pytest.mark.parametrize("type_name", ["OR", "AND", "MAJ2"])
def test_template_compiles_and_its_test_passes(cli, tmp_path, type_name):
    cells = tmp_path / "cells"
    rc, out, err = cli("new-cell", "my_cell", "--type", type_name, "--dir", cells)
    assert rc == 0, err
    assert (cells / "my_cell.py").exists() and (cells / "test_my_cell.py").exists()
    rc, out, err = cli("cells", "--cells", cells)
    assert rc == 0 and "my_cell" in out and not err  # the test file is not read as a cell
    # the written test compiles the cell alone and proves it at the kinematic level
    r = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider",
                        str(cells / "test_my_cell.py")], capture_output=True, text=True,
                       cwd=tmp_path)
    assert r.returncode == 0 and "1 passed" in r.stdout, r.stdout + r.stderr
    if type_name == "OR":  # and through the CLI, asked for by name
        design = tmp_path / "s.json"
        rc, out, err = cli("compile", EXAMPLES / "sorter.bool", "--cells", cells,
                           "--use-cell", "my_cell", "-o", design)
        assert rc == 0, err
        assert "my_cell" in {c["cell"] for c in json.loads(design.read_text())["cells"]}


def test_new_cell_refuses_to_overwrite_and_bad_names(cli, tmp_path):
    cells = tmp_path / "cells"
    cells.mkdir()
    (cells / "test_mine.py").write_text("keep me")
    rc, _, err = cli("new-cell", "mine", "--dir", cells)
    assert rc == 2 and "test_mine.py: already exists" in err
    assert not (cells / "mine.py").exists()  # neither file written
    assert (cells / "test_mine.py").read_text() == "keep me"
    for args, why in [(["Mine"], "lower case"), (["mine", "--type", "maj"], "capitals"),
                      (["mine", "--type", "XOR"], "stdlib/xor_gate.py")]:
        rc, _, err = cli("new-cell", *args, "--dir", cells)
        assert rc == 2 and why in err
