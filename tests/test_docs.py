"""The example cell of docs/write-a-cell.md, run exactly as printed."""

from __future__ import annotations

import json
import re
from pathlib import Path

DOC = Path(__file__).resolve().parents[1] / "docs" / "write-a-cell.md"


def test_documented_cell_compiles_and_proves(cli, tmp_path):
    code = re.search(r"```python\n(# my_cells/wide_or.py\n.*?)```", DOC.read_text(), re.S)
    assert code, "example block missing from the doc"
    cells = tmp_path / "my_cells"
    cells.mkdir()
    (cells / "wide_or.py").write_text(code.group(1))
    rc, out, _ = cli("cells", "--cells", cells)
    assert rc == 0 and "wide_or" in out
    design = tmp_path / "s.json"
    sorter = Path(__file__).resolve().parents[1] / "examples" / "sorter.bool"
    rc, _, err = cli("compile", sorter, "--cells", cells, "-o", design)
    assert rc == 0, err
    d = json.loads(design.read_text())
    # every OR of the design is the user's cell (one in two levels; multi-level may use more)
    ors = [c["cell"] for c in d["cells"] if c["type"] == "OR"]
    assert ors and set(ors) == {"wide_or"}
    for level in ("kinematic", "dynamic"):
        rc, out, _ = cli("simulate", design, "--cells", cells, "--level", level, "--cases", "4")
        assert rc == 0, out


ARCH = DOC.parent / "architecture.md"


def test_architecture_names_only_real_paths_and_every_package():
    """docs/architecture.md is the map of the tree: every module it names exists, and every
    package of mechc appears in it (so a new package cannot go undocumented)."""
    text = ARCH.read_text()
    root = DOC.parents[1]
    named = set(re.findall(r"`((?:mechc|stdlib)/[\w/]+(?:\.py)?/?)`", text))
    assert named, "the architecture doc names no paths"
    missing = [p for p in named if not (root / p).exists()]
    assert not missing, f"architecture.md names paths that do not exist: {missing}"
    packages = {p.parent.relative_to(root).as_posix() for p in (root / "mechc").glob(
        "*/__init__.py")}
    undocumented = [p for p in sorted(packages) if f"`{p}/`" not in text]
    assert not undocumented, f"packages missing from architecture.md: {undocumented}"


README = DOC.parents[1] / "README.md"


def test_readme_synth_example_finds_a_healthy_gate(cli):
    """The README's dimensional-synthesis line, run as printed, must show a success (exit 0),
    not the failure path (numbers with no healthy design exit 1)."""
    line = next(ln for ln in README.read_text().splitlines() if "mechc synth three-bar" in ln)
    args = line.split("#")[0].split()[1:]
    rc, out, err = cli(*args)
    assert rc == 0, err
    assert json.loads(out)["healthy"] is True
