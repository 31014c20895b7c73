"""The dwell-rise-dwell cam and its oscillating roller follower (001 §3.6, Chart III steps 4-5).

The follower program y(phi) (0 = roller on the inner dwell, 1 = on the outer dwell) is built from
cycloidal rises and returns, one inside each threshold band, with dwells elsewhere. The output
crank ZH turns about Z (below the roller, as in Fig. 34) or Z' (above): rising then turns the crank
clockwise about Z, counter-clockwise about Z', which is how one cam serves a function and its
complement (Chart III step 2). The output crank swings through the same angle as an input crank,
clockwise from "0" to "1", so a generator's output can drive the next generator's input.

Because the cam is generated as the envelope of the roller, the follower follows y(phi) exactly;
the checks here are the pressure angle along the working range and undercutting (the pitch
curve's convex radius of curvature against the roller radius).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mechc.geometry.circles import line_angle_deg, polar, quarter_turn


def cycloidal(u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Cycloidal motion and its derivative on u in [0, 1], clamped outside (dwells)."""
    u = np.clip(u, 0.0, 1.0)
    return u - np.sin(2 * np.pi * u) / (2 * np.pi), 1 - np.cos(2 * np.pi * u)


@dataclass(frozen=True)
class FollowerProgram:
    """Transitions at ascending cam-angle bands (rad); the first one is a rise from y = 0."""

    bands: tuple[tuple[float, float], ...]

    def __call__(self, phi: np.ndarray) -> np.ndarray:
        return self.evaluate(phi)[0]

    def evaluate(self, phi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(y, dy/dphi)."""
        phi = np.asarray(phi, dtype=float)
        y = np.zeros_like(phi)
        dy = np.zeros_like(phi)
        for i, (a, b) in enumerate(self.bands):
            sign = 1.0 if i % 2 == 0 else -1.0
            c, dc = cycloidal((phi - a) / (b - a))
            inside = (phi > a) & (phi < b)
            y += sign * c
            dy += np.where(inside, sign * dc / (b - a), 0.0)
        return y, dy


@dataclass(frozen=True)
class Follower:
    """Geometry in units of the crank length l; K is the cam centre (separator frame)."""

    K: tuple[float, float]
    direction: float  # angle of K -> H at mid swing (rad)
    radius: float  # |KH| at mid swing
    arm: float  # ZH
    swing: float  # output crank swing (rad)
    roller: float  # roller radius
    primed: bool  # pivot Z' (above the roller) instead of Z

    @property
    def normal(self) -> np.ndarray:
        return polar(self.direction + np.pi / 2)

    @property
    def h_mid(self) -> np.ndarray:
        return np.asarray(self.K) + polar(self.direction, self.radius)

    @property
    def pivot(self) -> np.ndarray:
        side = 1.0 if self.primed else -1.0
        return self.h_mid + side * self.arm * self.normal

    def crank_angle(self, y: np.ndarray) -> np.ndarray:
        """Absolute angle of pivot -> H for follower fraction y."""
        y = np.asarray(y, dtype=float)
        if self.primed:
            return self.direction - np.pi / 2 - self.swing * (0.5 - y)
        return self.direction + np.pi / 2 + self.swing * (0.5 - y)

    def roller_centre(self, y: np.ndarray) -> np.ndarray:
        return self.pivot + polar(self.crank_angle(y), self.arm)

    def output(self, y: np.ndarray) -> np.ndarray:
        """Output position, 0 = "0" ... 1 = "1" (clockwise), from the follower fraction."""
        y = np.asarray(y, dtype=float)
        return 1.0 - y if self.primed else y

    def pressure_angle(self, phi: np.ndarray, program: FollowerProgram, orientation: int
                       ) -> np.ndarray:
        """Pressure angle (deg): between the roller's direction of motion and the common normal,
        i.e. between the pitch-curve tangent and the crank ZH. ``orientation`` is the sign of the
        cam body's absolute rotation per unit phi."""
        y, dy = program.evaluate(phi)
        H = self.roller_centre(y)
        arm = H - self.pivot
        rot = quarter_turn(arm)
        dpsi = (self.swing if self.primed else -self.swing) * dy
        rel = H - np.asarray(self.K)
        cam_v = orientation * quarter_turn(rel)
        tangent = dpsi[..., None] * rot - cam_v
        return line_angle_deg(tangent, arm)

    def pitch_curve(self, phi: np.ndarray, program: FollowerProgram, body_angle: np.ndarray
                    ) -> np.ndarray:
        """Roller centre in the cam's own frame (cam turned to ``body_angle`` at each phi)."""
        rel = self.roller_centre(program(phi)) - np.asarray(self.K)
        c, s = np.cos(-body_angle), np.sin(-body_angle)
        return np.stack([c * rel[..., 0] - s * rel[..., 1], s * rel[..., 0] + c * rel[..., 1]], -1)


def closed_program(work: FollowerProgram, lo: float, hi: float) -> FollowerProgram:
    """Working program plus, if it ends on the outer dwell, a return over the unused part of
    the revolution so that the cam is a closed curve (never driven: the cam turns only within
    [lo, hi])."""
    if len(work.bands) % 2 == 0:
        return work
    return FollowerProgram(work.bands + ((hi, lo + 2 * np.pi),))


def curvature_radius(points: np.ndarray) -> np.ndarray:
    """Signed radius of curvature of a closed sampled curve (positive where it turns left)."""
    d1 = (np.roll(points, -1, 0) - np.roll(points, 1, 0)) / 2
    d2 = np.roll(points, -1, 0) - 2 * points + np.roll(points, 1, 0)
    cross = d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]
    speed = np.hypot(d1[:, 0], d1[:, 1])
    with np.errstate(divide="ignore"):
        return speed ** 3 / cross


def profile(pitch: np.ndarray, roller: float) -> np.ndarray:
    """Cam surface: the pitch curve offset inwards by the roller radius (closed, sampled)."""
    d1 = np.roll(pitch, -1, 0) - np.roll(pitch, 1, 0)
    t = d1 / np.hypot(d1[:, 0], d1[:, 1])[:, None]
    left = quarter_turn(t)
    area = np.sum(pitch[:, 0] * np.roll(pitch[:, 1], -1) - np.roll(pitch[:, 0], -1) * pitch[:, 1])
    inward = left if area > 0 else -left
    return pitch + roller * inward
