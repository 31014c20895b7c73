"""Vectorised plane geometry for loop closure: circle intersections on a chosen branch.

Points are arrays of shape (..., 2). A dyad (two links meeting at a joint) is closed by
intersecting two circles; of the two solutions, ``branch`` = +1 takes the one to the left of the
directed line from the first centre to the second, -1 the one to the right. A linkage keeps the
branch it was assembled in, so each caller fixes it once from the reference position.
"""

from __future__ import annotations

import numpy as np


class LoopClosureError(ValueError):
    """The two circles do not meet: the linkage cannot reach this position (count and the worst
    shortfall in the message)."""


def circle_intersection(c1: np.ndarray, r1: float, c2: np.ndarray, r2: float, branch: int,
                        what: str = "dyad") -> np.ndarray:
    c1 = np.asarray(c1, dtype=float)
    c2 = np.asarray(c2, dtype=float)
    d_vec = c2 - c1
    d = np.hypot(d_vec[..., 0], d_vec[..., 1])
    a = (d * d + r1 * r1 - r2 * r2) / (2 * d)
    h2 = r1 * r1 - a * a
    if np.any(~(h2 >= 0)):
        bad = np.count_nonzero(~(h2 >= 0))
        worst = float(np.nanmin(h2))
        raise LoopClosureError(f"{what}: circles do not meet at {bad} position(s) "
                               f"(worst h^2 = {worst:.3g})")
    h = np.sqrt(h2)
    ex = d_vec / d[..., None]
    ey = np.stack([-ex[..., 1], ex[..., 0]], axis=-1)
    return c1 + a[..., None] * ex + (branch * h)[..., None] * ey


def branch_of(c1: np.ndarray, c2: np.ndarray, p: np.ndarray) -> int:
    """The branch (+1 left / -1 right of c1 -> c2) on which point ``p`` lies."""
    d = np.asarray(c2, float) - np.asarray(c1, float)
    q = np.asarray(p, float) - np.asarray(c1, float)
    return 1 if d[0] * q[1] - d[1] * q[0] > 0 else -1


def line_angle_deg(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Acute angle (degrees, 0..90) between the lines along vectors u and v: the transmission
    angle of 001 Appendix D.1 ("if necessary one link is extended for the acute angle")."""
    cross = u[..., 0] * v[..., 1] - u[..., 1] * v[..., 0]
    dot = u[..., 0] * v[..., 0] + u[..., 1] * v[..., 1]
    ang = np.degrees(np.arctan2(np.abs(cross), dot))
    return np.minimum(ang, 180.0 - ang)


def polar(angle_rad: np.ndarray, length: float = 1.0) -> np.ndarray:
    angle_rad = np.asarray(angle_rad, dtype=float)
    return length * np.stack([np.cos(angle_rad), np.sin(angle_rad)], axis=-1)
