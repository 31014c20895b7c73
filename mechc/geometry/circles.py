"""The circle meeting that closes a dyad, and the small plane helpers around it: one kernel for
the threshold toolkit, the linkage-synthesis toolkit and the benchmarks.

Points are arrays of shape (..., 2) or complex numbers (x + iy, scalars or arrays); the result
comes back in the form the centres came in. A dyad (two links meeting at a joint) is closed by
intersecting two circles; of the two solutions, ``branch`` = +1 takes the one to the left of the
directed line from the first centre to the second, -1 the one to the right. A linkage keeps the
branch it was assembled in, so each caller fixes it once from the reference position
(:func:`branch_of`).

Where the circles do not meet a caller chooses (``miss``): ``"raise"`` (a
:class:`LoopClosureError` naming the linkage), ``"nan"`` (NaN points there, for a sweep that
masks them) or ``"clamp"`` (the half-chord clamped at 0, i.e. where the radical line crosses the
line of centres, for a search that scores feasibility from the returned h^2 instead).
"""

from __future__ import annotations

from contextlib import nullcontext
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike

Miss = Literal["raise", "nan", "clamp"]


class LoopClosureError(ValueError):
    """The two circles do not meet: the linkage cannot reach this position (count and the worst
    shortfall in the message)."""


def quarter_turn(v: np.ndarray) -> np.ndarray:
    """Vectors (..., 2) turned a quarter turn counter-clockwise (the left normal)."""
    return np.stack([-v[..., 1], v[..., 0]], axis=-1)


def _xy(c: ArrayLike) -> np.ndarray:
    """Complex points as (..., 2) float arrays; anything else as a float array."""
    if np.iscomplexobj(c):
        c = np.asarray(c, complex)
        return np.stack([c.real, c.imag], axis=-1)
    return np.asarray(c, dtype=float)


def circle_meeting(c1: ArrayLike, r1: ArrayLike, c2: ArrayLike, r2: ArrayLike, branch: ArrayLike,
                   *, miss: Miss = "raise", what: str = "dyad") -> tuple[np.ndarray, np.ndarray]:
    """(joint, h^2): where circle (c1, r1) meets circle (c2, r2) on ``branch``, and the squared
    half-chord (> 0 where the circles cross, 0 at a toggle, < 0 or NaN where they miss), so a
    caller that scores or flags closure needs no second pass. Radii and ``branch`` broadcast
    against the points' leading axes."""
    as_complex = np.iscomplexobj(c1) or np.iscomplexobj(c2)
    c1 = _xy(c1)
    c2 = _xy(c2)
    # a caller that tolerates misses gets no warnings for them; "raise" leaves the caller's
    # error state alone
    quiet = np.errstate(invalid="ignore", divide="ignore") if miss != "raise" else nullcontext()
    with quiet:
        d_vec = c2 - c1
        d = np.hypot(d_vec[..., 0], d_vec[..., 1])
        a = (d * d + r1 * r1 - r2 * r2) / (2 * d)
        h2 = r1 * r1 - a * a
        if miss == "raise":
            miss_at = ~(h2 >= 0)
            if np.any(miss_at):
                short = h2[miss_at & ~np.isnan(h2)]
                worst = (f"worst h^2 = {float(short.min()):.3g}" if short.size
                         else "coincident centres")
                raise LoopClosureError(f"{what}: circles do not meet at "
                                       f"{np.count_nonzero(miss_at)} position(s) ({worst})")
            h = np.sqrt(h2)
        elif miss == "nan":
            h = np.sqrt(h2)
        elif miss == "clamp":
            h = np.sqrt(np.maximum(h2, 0))
        else:
            raise ValueError(f"miss must be 'raise', 'nan' or 'clamp', not {miss!r}")
        ex = d_vec / d[..., None]
        p = c1 + a[..., None] * ex + (branch * h)[..., None] * quarter_turn(ex)
    if as_complex:
        p = np.ascontiguousarray(p).view(complex)[..., 0]
        if p.ndim == 0:
            p = p[()]
    return p, h2


def circle_intersection(c1: ArrayLike, r1: ArrayLike, c2: ArrayLike, r2: ArrayLike,
                        branch: ArrayLike, what: str = "dyad", *,
                        miss: Miss = "raise") -> np.ndarray:
    """The joint where the two circles meet on ``branch`` (see :func:`circle_meeting`)."""
    return circle_meeting(c1, r1, c2, r2, branch, miss=miss, what=what)[0]


def branch_of(c1: ArrayLike, c2: ArrayLike, p: ArrayLike) -> int | np.ndarray:
    """The branch (+1 left / -1 right of c1 -> c2) on which point ``p`` lies: an int for one
    point, an int array (...) for points (..., 2), so a search can fix many candidates' branches
    at once."""
    d = np.asarray(c2, float) - np.asarray(c1, float)
    q = np.asarray(p, float) - np.asarray(c1, float)
    side = np.where(d[..., 0] * q[..., 1] - d[..., 1] * q[..., 0] > 0, 1, -1)
    return int(side) if side.ndim == 0 else side


def line_angle_deg(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Acute angle (degrees, 0..90) between the lines along vectors u and v: the transmission
    angle of 001 Appendix D.1 ("if necessary one link is extended for the acute angle")."""
    cross = u[..., 0] * v[..., 1] - u[..., 1] * v[..., 0]
    dot = u[..., 0] * v[..., 0] + u[..., 1] * v[..., 1]
    ang = np.degrees(np.arctan2(np.abs(cross), dot))
    return np.minimum(ang, 180.0 - ang)


def polar(angle_rad: np.ndarray, length: float = 1.0) -> np.ndarray:
    """Vectors (..., 2) of the given length at the given angles."""
    angle_rad = np.asarray(angle_rad, dtype=float)
    return length * np.stack([np.cos(angle_rad), np.sin(angle_rad)], axis=-1)
