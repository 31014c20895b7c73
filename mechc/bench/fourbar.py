"""One crank-rocker four-bar, solved by mechc's kinematic level and by pylinkage, for the peer
comparison of the speed benchmark.

mechc's path is the one every mechanism's kinematic proof takes: a :class:`Part` of two levers
(crank and rocker, on ground pivots) joined by a rod (the coupler), solved by
``mechc.physics.closed_form.solve`` with the crank's angle given — the rocker then comes from the
rod's circle meeting the rocker's circle (``_lever_from_rod``), vectorised over all crank
angles at once, with transmission angles, toggle margins and the loop-closure check computed on
the way, as in a proof; the rocker pin positions are then read with ``position`` (the same
function a proof's checks use). pylinkage (an optional benchmark dependency, never imported by mechc
itself) steps its Crank + RRRDyad linkage one position after another.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from mechc.geometry.circles import branch_of, circle_intersection
from mechc.ir.mechanism import Body, Joint, Part
from mechc.physics.closed_form import cos_sin, position, solve
from mechc.proofs.kinematic import SOLVE_CHUNK

GROUND_LEN, CRANK, COUPLER, ROCKER = 40.0, 10.0, 40.0, 30.0  # mm: Grashof crank-rocker


@lru_cache(maxsize=1)
def mechc_part() -> tuple[Part, tuple[float, float]]:
    """The four-bar at its design pose (crank at +90°), and the rocker pin there (built once:
    a proof builds its parts once and solves them for many states)."""
    o2 = (GROUND_LEN, 0.0)
    a = (0.0, CRANK)
    b = circle_intersection(o2, ROCKER, a, COUPLER, 1, "four-bar")
    if b[1] < 0:
        b = circle_intersection(o2, ROCKER, a, COUPLER, -1, "four-bar")
    b = (float(b[0]), float(b[1]))
    crank = Body("crank", "lever", [[(0.0, 0.0), a, (1.0, CRANK)]], 0.01, pivot=(0.0, 0.0))
    rocker = Body("rocker", "lever", [[o2, b, (o2[0] + 1.0, 0.0)]], 0.01, pivot=o2)
    j = Joint("coupler", "rod", "crank", "rocker", pa=a, pb=b, length=COUPLER)
    return Part([crank, rocker], [j]), b


def mechc_rocker_pins(crank_angles: np.ndarray) -> np.ndarray:
    """(N, 2) rocker pin positions for absolute crank angles (rad), by mechc's closed form."""
    part, b = mechc_part()
    poses = solve(part, {"crank": np.asarray(crank_angles) - math.pi / 2}, len(crank_angles))
    return np.stack(position(part.bodies[1], poses, b), axis=1)


def mechc_rocker_pins_reduced(crank_angles: np.ndarray) -> np.ndarray:
    """:func:`mechc_rocker_pins` and, as a proof's ``CheckStats`` does on every chunk, the
    checks reduced to their figures: each angle's smallest value in degrees and each body's
    count of unsolvable states."""
    part, b = mechc_part()
    poses = solve(part, {"crank": np.asarray(crank_angles) - math.pi / 2}, len(crank_angles))
    for figures in (poses.transmission, poses.singular_margin):
        for jid in figures:
            figures.min_deg(jid)
    for bad in poses.bad.values():
        np.count_nonzero(bad)
    return np.stack(position(part.bodies[1], poses, b), axis=1)


def pylinkage_linkage(steps_per_turn: int):
    # pylinkage is the benchmark's optional peer (the bench extra), never a dependency
    from pylinkage.actuators import Crank
    from pylinkage.components import Ground
    from pylinkage.dyads import RRRDyad
    from pylinkage.simulation import Linkage

    o1 = Ground(0.0, 0.0, name="O1")
    o2 = Ground(GROUND_LEN, 0.0, name="O2")
    crank = Crank(anchor=o1, radius=CRANK, angular_velocity=2 * math.pi / steps_per_turn)
    rocker = RRRDyad(crank.output, o2, distance1=COUPLER, distance2=ROCKER)
    return Linkage([o1, o2, crank, rocker], name="four-bar")


def _side() -> int:
    """Which of the two circle meetings is the design pose's (crank at +90°): +1 for the one
    left of the line from the rocker pivot to the crank pin."""
    part, b = mechc_part()
    return branch_of(part.bodies[1].pivot, (0.0, CRANK), b)


# The two floors below write the circle meeting out by hand on purpose instead of calling the
# geometry kernel (mechc.geometry.circles): they exist only to be timed, as the least work any
# code could do per position (one division, one square root, no checks, no conversions), and
# are checked against mechc's result in compare(). No mechc path uses them.


def bare_rocker_pins(crank_angles: np.ndarray) -> np.ndarray:
    """The same closed form with nothing but the positions (no transmission, assembly or
    closure checks, no bookkeeping): the most numpy could give on this four-bar, a floor to
    read mechc's rate against."""
    part, b = mechc_part()
    o2 = part.bodies[1].pivot
    r2, l2 = ROCKER * ROCKER, COUPLER * COUPLER
    side = _side()
    c, s = cos_sin(crank_angles)
    dx = CRANK * c - o2[0]
    dy = CRANK * s - o2[1]
    inv = 1.0 / (dx * dx + dy * dy)
    a = 0.5 * (r2 - l2) * inv + 0.5
    h = np.sqrt(r2 * inv - a * a) * side
    return np.stack((o2[0] + a * dx - h * dy, o2[1] + a * dy + h * dx), axis=1)


def _numba_kernel():
    """The same positions-only closed form as a scalar loop compiled by numba (when numba is
    installed, as the benchmark extra installs it): what compiling, rather than vectorising,
    gives on this machine."""
    # numba comes with the optional bench extra
    import numba

    part, b = mechc_part()
    ox, oy = part.bodies[1].pivot
    r2, l2 = ROCKER * ROCKER, COUPLER * COUPLER
    side = _side()

    @numba.njit(cache=False, fastmath=False)
    def pins(th, out):
        for i in range(th.shape[0]):
            dx = CRANK * math.cos(th[i]) - ox
            dy = CRANK * math.sin(th[i]) - oy
            inv = 1.0 / (dx * dx + dy * dy)
            a = 0.5 * (r2 - l2) * inv + 0.5
            h = math.sqrt(r2 * inv - a * a) * side
            out[i, 0] = ox + a * dx - h * dy
            out[i, 1] = oy + a * dy + h * dx

    return pins


@dataclass
class PeerResult:
    mechc_per_s: float
    pylinkage_step_per_s: float  # Linkage.step, its Python API
    pylinkage_fast_per_s: float | None  # Linkage.step_fast (numba-compiled if numba is there)
    pylinkage_backend: str
    max_difference_mm: float  # rocker pin, mechc against pylinkage, same crank angles
    positions: int
    bare_numpy_per_s: float = math.nan  # positions only, numpy (bare_rocker_pins)
    numba_kernel_per_s: float | None = None  # positions only, compiled scalar loop
    mechc_reduced_per_s: float = math.nan  # and the checks reduced to their figures


# states per vectorised call: the chunk a proof's sweep solves at once (at most
# ``SOLVE_CHUNK``; mechc/proofs/kinematic.py), so the figure times the path a proof runs
CHUNK = SOLVE_CHUNK


def compare(n: int = 200_000, n_step: int = 5_000, repeat: int = 3) -> PeerResult:
    """Positions (rocker pin coordinates) per second of both on the same four-bar, CPU time,
    best of ``repeat``; and how far apart their rocker pins are."""
    # the optional peer's compiled path (the bench extra)
    import pylinkage._numba_compat as nc

    th = np.linspace(0.0, 2 * math.pi, n, endpoint=False)
    mechc_rocker_pins(th[:1000])  # warm
    mechc_rate = n / _best_of(repeat, lambda: _chunks(mechc_rocker_pins, th))
    reduced_rate = n / _best_of(repeat, lambda: _chunks(mechc_rocker_pins_reduced, th))
    # pylinkage, Python API
    lk = pylinkage_linkage(n_step)
    t0 = time.process_time()
    traj = [p[3] for p in lk.step(iterations=n_step)]
    step_rate = n_step / (time.process_time() - t0)
    # the same crank angles (pylinkage starts at angle 0 and yields after each increment)
    angles = 2 * math.pi / n_step * np.arange(1, n_step + 1)
    diff = float(np.max(np.abs(np.array(traj) - mechc_rocker_pins(angles))))
    # pylinkage, compiled path
    fast_rate = None
    try:
        lk2 = pylinkage_linkage(n)
        lk2.step_fast(iterations=100)  # compile
        best = math.inf
        for _ in range(repeat):
            t0 = time.process_time()
            tr = lk2.step_fast(iterations=n)
            best = min(best, time.process_time() - t0)
        fast_rate = n / best
        if not np.isfinite(tr).all():
            fast_rate = None
    except Exception:  # an optional path of an optional peer: report it missing
        fast_rate = None
    # floors: the closed form with positions only, vectorised and compiled
    ref = mechc_rocker_pins(th[:CHUNK])
    if np.max(np.abs(bare_rocker_pins(th[:CHUNK]) - ref)) > 1e-9:
        raise AssertionError("the positions-only closed form does not match mechc's")
    bare_rate = n / _best_of(repeat, lambda: _chunks(bare_rocker_pins, th))
    kernel_rate = None
    if nc.HAS_NUMBA:
        pins = _numba_kernel()
        out = np.empty((n, 2))
        pins(th[:10], out[:10])  # compile
        kernel_rate = n / _best_of(repeat, lambda: pins(th, out))
        if np.max(np.abs(out[:CHUNK] - ref)) > 1e-9:
            raise AssertionError("the compiled closed form does not match mechc's")
    return PeerResult(mechc_rate, step_rate, fast_rate,
                      "numba" if nc.HAS_NUMBA else "python", diff, n, bare_rate, kernel_rate,
                      reduced_rate)


def _chunks(fn, th: np.ndarray) -> None:
    """``fn`` on ``th`` in chunks of CHUNK states, each result dropped at once (as a proof's
    sweep keeps only what it reduces: keeping them all would time the heap's growth too)."""
    for s in range(0, len(th), CHUNK):
        fn(th[s:s + CHUNK])


def _best_of(repeat: int, fn) -> float:
    best = math.inf
    for _ in range(repeat):
        t0 = time.process_time()
        fn()
        best = min(best, time.process_time() - t0)
    return best
