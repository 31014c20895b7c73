"""Proofs of a design against its spec at five levels (logic, kinematic, dynamic, timing,
screened), for combinational and sequential designs: :func:`prove` runs the engine registered
for the level and the spec's kind, with :class:`ProofSettings`, and returns a
:class:`ProofReport`."""

# each engine module registers its proof with mechc.proofs.registry when imported
from mechc.proofs import (  # noqa: F401
    dynamic,
    kinematic,
    logic,
    screen,
    seq_logic,
    seq_mechanism,
    timing,
)
from mechc.proofs.registry import KINDS, LEVELS, check_interface, prove, spec_kind
from mechc.proofs.report import ProofReport
from mechc.proofs.settings import ProofSettings, dyn_settings

__all__ = ["KINDS", "LEVELS", "ProofReport", "ProofSettings", "check_interface", "dyn_settings",
           "prove", "spec_kind"]
