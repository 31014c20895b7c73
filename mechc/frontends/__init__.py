"""Front ends: every spec format parses to a :class:`~mechc.ir.spec.Spec` (combinational)
or a :class:`~mechc.ir.seqspec.SeqSpec` (sequential: .fsm, .kiss2)."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from mechc.errors import SpecError
from mechc.ir.spec import OutputSpec, Spec

if TYPE_CHECKING:
    from mechc.ir.seqspec import SeqSpec

__all__ = ["OutputSpec", "Spec", "load_spec", "SPEC_SUFFIXES"]

SPEC_SUFFIXES = (".bool", ".pla", ".blif", ".fsm", ".kiss2", ".kiss")


def load_spec(path: str | Path) -> Spec | SeqSpec:
    """Parse a spec file, choosing the front end by suffix."""
    p = Path(path)
    suffix = p.suffix.lower()
    if suffix == ".bool":
        from mechc.frontends.boolfile import parse_bool_file

        return parse_bool_file(str(p))
    if suffix == ".pla":
        from mechc.frontends.pla import parse_pla_file

        return parse_pla_file(str(p))
    if suffix == ".blif":
        from mechc.frontends.blif import parse_blif_file

        return parse_blif_file(str(p))
    if suffix == ".fsm":
        from mechc.frontends.fsm import parse_fsm_file

        return parse_fsm_file(str(p))
    if suffix in (".kiss2", ".kiss"):
        from mechc.frontends.kiss2 import parse_kiss_file

        return parse_kiss_file(str(p))
    raise SpecError(str(p), 1, 1, f"unknown spec format '{suffix or p.name}': expected one of "
                    f"{', '.join(SPEC_SUFFIXES)}")
