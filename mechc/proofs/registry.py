"""Proof engines by (level, kind), and the one entry that runs the right one: :func:`prove`.

Each proof module registers its engine with :func:`engine`; ``mechc.proofs`` imports them all,
so the table is full whenever this module is reachable.
"""

from __future__ import annotations

from collections.abc import Callable

from mechc.cells.library import Library
from mechc.errors import UsageError
from mechc.ir.design import Design
from mechc.ir.netlist import Netlist
from mechc.ir.seqspec import SeqSpec
from mechc.ir.spec import Spec
from mechc.proofs.report import ProofReport
from mechc.proofs.settings import ProofSettings

LEVELS = ("logic", "kinematic", "dynamic", "timing", "screened")
KINDS = ("combinational", "sequential")
#: Called as (done, total) while a long proof runs, in the level's own unit (input changes,
#: states); as (done, total, what) for other work on the way that takes a while, ``what``
#: naming it (a cell's timing table measured on first use).
OnProgress = Callable[..., None]
Engine = Callable[[Design, Spec | SeqSpec, Library, ProofSettings, OnProgress | None], ProofReport]

_ENGINES: dict[tuple[str, str], Engine] = {}


def engine(level: str, kind: str) -> Callable[[Engine], Engine]:
    """Register the decorated function as the proof at ``level`` for ``kind`` specs."""
    if level not in LEVELS or kind not in KINDS:
        raise ValueError(f"no proof level {level!r} for {kind!r} specs")

    def register(fn: Engine) -> Engine:
        if (level, kind) in _ENGINES:
            raise ValueError(f"two engines for the {kind} {level} proof")
        _ENGINES[level, kind] = fn
        return fn

    return register


def check_interface(nl: Netlist, spec: Spec | SeqSpec) -> None:
    """The design's pins must be the spec's: every level assumes so."""
    if set(nl.inputs) != set(spec.inputs):
        raise UsageError(f"design inputs ({' '.join(nl.inputs)}) differ from the spec's "
                         f"({' '.join(spec.inputs)})")
    missing = [o for o in spec.outputs if o not in nl.outputs]
    if missing:
        raise UsageError(f"spec output(s) {', '.join(missing)} not in the design (design outputs:"
                         f" {' '.join(nl.outputs)})")


def spec_kind(spec: Spec | SeqSpec) -> str:
    """Which engines prove against ``spec``: a flow table or set/reset spec is sequential."""
    return "sequential" if getattr(spec, "kind", "") == "fsm" else "combinational"


def prove(design: Design, spec: Spec | SeqSpec, lib: Library, level: str,
          settings: ProofSettings | None = None,
          progress: OnProgress | None = None) -> ProofReport:
    """The proof of ``design`` against ``spec`` at ``level``. Refuses, before any work, a
    design whose pins differ from the spec's and a sequential design proved against a
    combinational spec (its memories would be read as logic)."""
    kind = spec_kind(spec)
    if level not in LEVELS:
        raise UsageError(f"no proof level {level!r} (levels: {', '.join(LEVELS)})")
    if kind == "combinational" and any(c.type == "MEMORY"
                                       for c in design.netlist.cells.values()):
        raise UsageError("a sequential design (with MEMORY cells) is proved against a .fsm spec, "
                         "not a combinational one")
    check_interface(design.netlist, spec)
    if level != "logic" and design.mechanism is None:
        raise UsageError("the design has no geometry (compile it with this mechc version)")
    return _ENGINES[level, kind](design, spec, lib, settings or ProofSettings(), progress)
