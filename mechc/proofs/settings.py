"""What a proof is asked to do (:class:`ProofSettings`) and the physics settings a dynamic
proof runs at unless told otherwise (:func:`dyn_settings`)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

from mechc.cells.library import Library
from mechc.ir.design import Design
from mechc.physics.scene import DynSettings
from mechc.proofs.hold import design_hold
from mechc.proofs.trace import TraceRecorder

#: A bilateral joint may stretch this share of the stroke before the proof calls it a solver
#: error (0.1 mm at the default 20 mm stroke).
VIOLATION_FRACTION = 0.005
#: The stretch allowed when the design has no geometry to take a stroke from.
VIOLATION_NO_GEOMETRY_MM = 0.1
#: How the combinational logic level checks every vector (mechc.proofs.logic): ``auto`` picks
#: ``exhaustive`` or ``sat`` by the design's size; ``sampled`` is a seeded sample, not a proof.
LOGIC_METHODS = ("auto", "exhaustive", "sat", "sampled")


@dataclass(frozen=True)
class ProofSettings:
    """The options of one proof; each engine reads the ones its level has."""

    tolerance: float = 0.05  # outputs within this fraction of stroke of their positions
    seed: int = 0  # for every random choice of cases
    logic_method: str = "auto"  # logic, combinational: one of LOGIC_METHODS
    cases: int = 16  # dynamic, combinational: seeded random changes after the Gray tour
    prune: bool = False  # dynamic, combinational: per-change pruned scenes requested
    accuracy: float | None = None  # dynamic, combinational: the output error to choose for
    dt: float | None = None  # dynamic: solver time step (s); None: DynSettings' default
    iterations: int | None = None  # dynamic: solver iterations per step
    move_time: float | None = None  # dynamic: seconds an input takes to move
    hold: float | None = None  # dynamic, screened, timing: seconds each change is held after
    #                            its move; None: the design's own (mechc.proofs.hold)
    # dynamic, screened: the changes failing on a joint stretch, contact overrun or late settle
    # run again at twice the iterations (mechc.proofs.dynamic.recheck_failures; a sequential
    # design: the pieces of walks holding such a step, mechc.proofs.seq_mechanism); one that
    # passes every check there is proved there and counts as passed
    recheck: bool = True
    # dynamic: processes the cases run on, or the address of a Dask scheduler to run them on
    # (mechc.proofs.parallel); neither changes what the proof reports
    jobs: int = field(default=1, compare=False)
    scheduler: str | None = field(default=None, compare=False)
    # kinematic and dynamic: receives every body's pose in every case visited (nothing is
    # recorded without one); it never changes what the proof checks or reports
    trace: TraceRecorder | None = field(default=None, compare=False, repr=False)


def dyn_settings(design: Design, lib: Library | None = None, dt: float | None = None,
                 iterations: int | None = None, move_time: float | None = None,
                 hold: float | None = None,
                 progress: Callable[..., None] | None = None) -> DynSettings:
    """The physics settings a dynamic proof of ``design`` uses: joints may stretch
    ``VIOLATION_FRACTION`` of its stroke; the solver options given replace the defaults. With
    ``lib`` each change is held at least as long as the design's structure asks
    (:func:`mechc.proofs.hold.design_hold`: a combinational design's static critical path, a
    sequential one's memories in turn), so a circuit that is slow by design is not reported
    unsettled; ``hold`` (s) replaces that. Without ``lib``: the default hold (the harnesses
    that measure the physics at fixed settings). ``progress`` is told (done, total, what)
    while a cell's timing table is measured for the hold (first use on a machine)."""
    mech = design.mechanism
    st = DynSettings(violation_limit=VIOLATION_FRACTION * mech.ctx.stroke if mech
                     else VIOLATION_NO_GEOMETRY_MM)
    for name, value in (("dt", dt), ("iterations", iterations), ("move_time", move_time)):
        if value is not None:
            setattr(st, name, value)
    if hold is not None:
        st.settle_time = hold
        st.hold_from = "--hold"
    elif lib is not None:
        why = design_hold(design, lib, st.move_time, st.settle_time, progress)
        st.settle_time = why["seconds"]
        st.hold_from = why["from"]
        st.static_path = why.get("static_path")
    return st
