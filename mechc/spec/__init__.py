"""Front ends: every spec format parses to a :class:`~mechc.spec.model.Spec`."""

from __future__ import annotations

from pathlib import Path

from mechc.errors import SpecError
from mechc.spec.model import OutputSpec, Spec

__all__ = ["OutputSpec", "Spec", "load_spec", "SPEC_SUFFIXES"]

SPEC_SUFFIXES = (".bool", ".pla")


def load_spec(path: str | Path) -> Spec:
    """Parse a spec file, choosing the front end by suffix."""
    p = Path(path)
    suffix = p.suffix.lower()
    if suffix == ".bool":
        from mechc.spec.boolfile import parse_bool_file

        return parse_bool_file(str(p))
    if suffix == ".pla":
        from mechc.spec.pla import parse_pla_file

        return parse_pla_file(str(p))
    raise SpecError(str(p), 1, 1, f"unknown spec format '{suffix or p.name}': expected one of "
                    f"{', '.join(SPEC_SUFFIXES)}")
