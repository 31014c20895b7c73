"""What a closed-form solve gives: every body's coordinate over N states (``Poses``).

Kept apart from the solver so that the part kinds (``mechc.parts``), which read and write these
coordinates, and the solver that orders them (``mechc.physics.closed_form``) share it without
importing each other.
"""

from __future__ import annotations

import math
from collections.abc import Iterator, MutableMapping
from dataclasses import dataclass, field
from typing import Protocol

import numpy as np

from mechc.ir.mechanism import GROUND


class KinematicsError(Exception):
    """The mechanism is not determinate from its geometry (a modelling error, not a state)."""


class Angles(MutableMapping):
    """Angles (degrees, 0..90) per joint over N states, each kept in the domain it was computed
    in: degrees, or the angle's tangent (:meth:`set_tan`: a ratio of a cross and a dot
    product, or of a square root and a cosine — no trig per state). Reading an entry gives
    degrees; a check wants the extreme only, so :meth:`min_deg` takes it in the stored domain
    (the tangent rises with the angle on 0..90°) and converts that one value."""

    def __init__(self, items: dict | None = None):
        self._v: dict[str, tuple[np.ndarray, bool]] = {}  # joint -> (values, is tangent)
        if items:
            self.update(items)

    def __getitem__(self, key: str) -> np.ndarray:
        a, tan = self._v[key]
        return np.degrees(np.arctan(a)) if tan else a

    def __setitem__(self, key: str, degrees: np.ndarray) -> None:
        self._v[key] = (degrees, False)

    def set_tan(self, key: str, tangent: np.ndarray) -> None:
        """Store the angle as its tangent (inf: 90°, NaN: undefined, as NaN degrees)."""
        self._v[key] = (tangent, True)

    def __delitem__(self, key: str) -> None:
        del self._v[key]

    def __iter__(self) -> Iterator[str]:
        return iter(self._v)

    def __len__(self) -> int:
        return len(self._v)

    def update(self, other=(), **kw) -> None:
        if isinstance(other, Angles):  # as stored: no conversion
            self._v.update(other._v)
        else:
            super().update(other, **kw)

    def min_deg(self, key: str) -> float | None:
        """The smallest angle over the states (degrees); NaN if every state is undefined,
        None if there are no states."""
        a, tan = self._v[key]
        if not np.size(a):
            return None
        if np.isnan(a).all():
            return math.nan
        v = float(np.nanmin(a))
        return math.degrees(math.atan(v)) if tan else v


@dataclass
class Poses:
    """Body displacements from the design pose for N states."""

    u: dict[str, np.ndarray] = field(default_factory=dict)  # sliders (mm along axis)
    theta: dict[str, np.ndarray] = field(default_factory=dict)  # levers, links (rad, ccw)
    xy: dict[str, tuple[np.ndarray, np.ndarray]] = field(default_factory=dict)  # links: ref
    #                                                 point's displacement (mm)
    bad: dict[str, np.ndarray] = field(default_factory=dict)  # states where a body is unsolved
    singular_margin: Angles = field(default_factory=Angles)  # joint -> degrees (Angles)
    transmission: Angles = field(default_factory=Angles)  # joint -> degrees (Angles)
    state: dict[str, np.ndarray] = field(default_factory=dict)  # stateful cell -> new state
    # world points a closed form placed while solving, (body, x0, y0) -> (x, y): the closure
    # check reuses them instead of re-deriving them through trig (private to ``solve``)
    placed: dict[tuple[str, float, float], tuple[np.ndarray, np.ndarray]] = field(
        default_factory=dict, repr=False, compare=False)

    def __post_init__(self):
        for name in ("singular_margin", "transmission"):  # given as a dict of degrees
            if not isinstance(getattr(self, name), Angles):
                setattr(self, name, Angles(getattr(self, name)))

    def known(self, body: str) -> bool:
        return body == GROUND or body in self.u or body in self.theta

    def mark(self, body: str, bad: np.ndarray) -> None:
        if body in self.bad:
            self.bad[body] = self.bad[body] | bad
        else:
            self.bad[body] = bad.copy()

    def update(self, other: Poses) -> None:
        for k in ("u", "theta", "xy", "bad", "singular_margin", "transmission", "state"):
            getattr(self, k).update(getattr(other, k))


def cos_sin(th) -> tuple[np.ndarray, np.ndarray]:
    """cos and sin of ``th`` from one tangent of the half angle: numpy vectorises float64 tan
    but sends cos and sin to scalar libm (~5x slower each); the results agree with libm to
    one ulp (|error| <= 2.3e-16, checked in tests/perf/test_perf_kinematics.py)."""
    t = np.tan(np.multiply(th, 0.5))
    t2 = t * t
    q = 1.0 / (1.0 + t2)
    return (1.0 - t2) * q, (t + t) * q


class PoseSink(Protocol):
    """A running measure fed chunk by chunk with the poses a sweep solves (the design checks'
    ``CheckStats``, the interference check)."""

    def add(self, poses: Poses) -> None: ...


class PoseTee:
    """Feeds each chunk of poses to several running measures (a sweep takes one)."""

    def __init__(self, *measures: PoseSink):
        self.measures = measures

    def add(self, poses: Poses) -> None:
        for m in self.measures:
            m.add(poses)
