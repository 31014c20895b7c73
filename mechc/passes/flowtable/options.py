"""Options shared by the flow-table steps: the cover and assignment solvers take the time
limit, the equations step the minimiser's options."""

from __future__ import annotations

from dataclasses import dataclass, field

from mechc.passes.minimise import MinimiseOptions

#: Inputs + state variables: the equations are minimised on full truth tables.
MAX_TOTAL_VARIABLES = 20


@dataclass
class SynthOptions:
    """How hard each step may work (one object so the pipeline passes a single value)."""

    minimise: MinimiseOptions = field(default_factory=MinimiseOptions)
    time_limit: float = 20.0  # seconds per integer program (cover, assignment)
