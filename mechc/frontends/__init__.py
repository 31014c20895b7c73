"""Front ends: every spec format parses to a :class:`~mechc.ir.spec.Spec` (combinational)
or a :class:`~mechc.ir.seqspec.SeqSpec` (sequential: .fsm, .kiss2)."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from mechc.errors import SpecError, UsageError
from mechc.frontends.blif import parse_blif_file
from mechc.frontends.boolfile import parse_bool_file
from mechc.frontends.fsm import parse_fsm_file
from mechc.frontends.kiss2 import parse_kiss_file
from mechc.frontends.pla import parse_pla_file
from mechc.frontends.verilog import parse_verilog_file
from mechc.ir.seqspec import SeqSpec
from mechc.ir.spec import OutputSpec, Spec

__all__ = ["FRONT_ENDS", "OutputSpec", "SPEC_SUFFIXES", "Spec", "check_spec_path", "load_spec"]

#: Spec file suffix -> the front end that parses it (a new format: a module here and a line).
FRONT_ENDS: dict[str, Callable[[str], Spec | SeqSpec]] = {
    ".bool": parse_bool_file,
    ".pla": parse_pla_file,
    ".blif": parse_blif_file,
    ".fsm": parse_fsm_file,
    ".kiss2": parse_kiss_file,
    ".kiss": parse_kiss_file,
    ".v": parse_verilog_file,
}
SPEC_SUFFIXES = tuple(FRONT_ENDS)


def check_spec_path(path: str | Path) -> Callable[[str], Spec | SeqSpec]:
    """The front end for ``path``, or the error a user should see first: a directory or an
    unknown suffix (a compiled design given where a spec belongs is named as such), before a
    command looks at its output paths (why: "refusing to overwrite the spec x.json" hid that
    x.json was a design, not a spec)."""
    p = Path(path)
    if p.is_dir():
        raise UsageError(f"{p}: is a directory, expected a spec file "
                         f"({', '.join(SPEC_SUFFIXES)})")
    suffix = p.suffix.lower()
    if suffix in FRONT_ENDS:
        return FRONT_ENDS[suffix]
    hint = ""
    if p.name.lower().endswith((".json", ".json.gz")):
        hint = " (a .json file is a compiled design, not a spec: prove it with `mechc simulate`)"
    raise SpecError(str(p), 1, 1, f"unknown spec format '{suffix or p.name}': expected one of "
                    f"{', '.join(SPEC_SUFFIXES)}{hint}")


def load_spec(path: str | Path) -> Spec | SeqSpec:
    """Parse a spec file, choosing the front end by suffix."""
    return check_spec_path(path)(str(path))
