"""Flow-table synthesis: a fundamental-mode flow table becomes SET/RESET equations of MEMORY
elements and output equations. Being split into one module per step."""

from mechc.passes.flowtable.compatibles import (
    SynthOptions,
    assign_states,
    brute_force_min_cover,
    closed_cover,
    compatibility,
    derive_equations,
    reduce_table,
    synthesise_table,
)

__all__ = [
    "SynthOptions",
    "assign_states",
    "brute_force_min_cover",
    "closed_cover",
    "compatibility",
    "derive_equations",
    "reduce_table",
    "synthesise_table",
]
