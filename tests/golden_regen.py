"""Regenerate tests/golden/*.netlist (run deliberately, then review the diff)."""

from pathlib import Path

from mechc.frontends import load_spec
from mechc.pipeline import compile_spec

ROOT = Path(__file__).resolve().parents[1]
for name in ["sorter", "full_adder", "comparator2", "sevenseg"]:
    text = compile_spec(load_spec(ROOT / "examples" / f"{name}.bool")).netlist.to_text()
    (ROOT / "tests" / "golden" / f"{name}.netlist").write_text(text)
    print(name)
