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


class Turn:
    """One body's turn from its design pose over N states, kept as it was computed: the
    angle, or the arm from the pivot to a point a closed form placed (``arm``: x, y over the
    states, the design arm's x0, y0 and its angle phi0), from which the angle (one arctan2)
    and its cosine and sine (dot and cross products, no trig) are derived when first asked
    for. A proof that reads only positions never pays the arctan2. The arrays are read-only
    once stored."""

    __slots__ = ("_angle", "_arm", "_cs")

    def __init__(self, angle=None, arm=None):
        self._angle = angle
        self._arm = arm
        self._cs = None

    def angle(self) -> np.ndarray:
        if self._angle is None:
            x, y, _, _, phi0 = self._arm
            theta = np.arctan2(y, x)
            theta -= phi0  # in [-pi - phi0, pi - phi0]: wrap the one side that can leave
            if not isinstance(phi0, float) and np.ndim(phi0):
                theta = (theta + np.pi) % (2 * np.pi) - np.pi
            elif phi0 > 0:
                np.add(theta, 2 * np.pi, out=theta, where=theta < -np.pi)
            else:
                np.subtract(theta, 2 * np.pi, out=theta, where=theta >= np.pi)
            self._angle = theta
        return self._angle

    def cos_sin(self) -> tuple[np.ndarray, np.ndarray]:
        if self._arm is None:  # from the angle, each time (it may be a caller's array)
            return cos_sin(self._angle)
        if self._cs is None:  # the placed arm against the design arm: dot and cross
            x, y, x0, y0, _ = self._arm
            k = 1.0 / (x0 * x0 + y0 * y0)
            c, s = x * x0, y * x0
            c += y * y0
            s -= x * y0
            c *= k
            s *= k
            self._cs = (c, s)
        return self._cs


class Turns(MutableMapping):
    """Turn angles (rad, ccw from the design pose) per body over N states: reading an entry
    gives the angle; :meth:`cos_sin` gives its cosine and sine the cheapest way the entry
    allows (see :class:`Turn`)."""

    def __init__(self, items: dict | None = None):
        self._v: dict[str, Turn] = {}
        if items:
            self.update(items)

    def __getitem__(self, key: str) -> np.ndarray:
        return self._v[key].angle()

    def __setitem__(self, key: str, angle: np.ndarray) -> None:
        self._v[key] = Turn(angle)

    def set_arm(self, key: str, x, y, x0, y0, phi0) -> None:
        """The turn that takes the design arm (x0, y0), at angle phi0, to (x, y)."""
        self._v[key] = Turn(arm=(x, y, x0, y0, phi0))

    def entry(self, key: str) -> Turn | None:
        """The stored turn (its identity says whether a placed point is still current)."""
        return self._v.get(key)

    def cos_sin(self, key: str) -> tuple[np.ndarray, np.ndarray]:
        return self._v[key].cos_sin()

    def __contains__(self, key: object) -> bool:
        return key in self._v

    def __delitem__(self, key: str) -> None:
        del self._v[key]

    def __iter__(self) -> Iterator[str]:
        return iter(self._v)

    def __len__(self) -> int:
        return len(self._v)

    def update(self, other=(), **kw) -> None:
        if isinstance(other, Turns):  # as stored: nothing derived
            self._v.update(other._v)
        else:
            super().update(other, **kw)


@dataclass
class Poses:
    """Body displacements from the design pose for N states."""

    u: dict[str, np.ndarray] = field(default_factory=dict)  # sliders (mm along axis)
    theta: Turns = field(default_factory=Turns)  # levers, links (rad, ccw; Turns)
    xy: dict[str, tuple[np.ndarray, np.ndarray]] = field(default_factory=dict)  # links: ref
    #                                                 point's displacement (mm)
    bad: dict[str, np.ndarray] = field(default_factory=dict)  # states where a body is unsolved
    singular_margin: Angles = field(default_factory=Angles)  # joint -> degrees (Angles)
    transmission: Angles = field(default_factory=Angles)  # joint -> degrees (Angles)
    state: dict[str, np.ndarray] = field(default_factory=dict)  # stateful cell -> new state
    # world points a closed form placed while solving, (body, x0, y0) -> (x, y, turn): the
    # closure check and a lever's ``position`` reuse them instead of re-deriving them through
    # trig (``turn``: the body's ``Turns`` entry they were placed with, None for the ground)
    placed: dict[tuple, tuple] = field(default_factory=dict, repr=False, compare=False)

    def __post_init__(self):
        if not isinstance(self.theta, Turns):  # given as a dict of angles
            self.theta = Turns(self.theta)
        for name in ("singular_margin", "transmission"):  # given as a dict of degrees
            if not isinstance(getattr(self, name), Angles):
                setattr(self, name, Angles(getattr(self, name)))

    def known(self, body: str) -> bool:
        return body == GROUND or body in self.u or body in self.theta

    def mark(self, body: str, bad: np.ndarray, own: bool = False) -> None:
        """Add the states ``bad`` to the body's bad ones (``own``: the caller made ``bad``
        for this and keeps no reference, so it is stored without a copy)."""
        if body in self.bad:
            self.bad[body] = self.bad[body] | bad
        else:
            self.bad[body] = bad if own else bad.copy()

    def update(self, other: Poses) -> None:
        for k in ("u", "theta", "xy", "bad", "singular_margin", "transmission", "state",
                  "placed"):
            getattr(self, k).update(getattr(other, k))


def cos_sin(th) -> tuple[np.ndarray, np.ndarray]:
    """cos and sin of ``th`` from one tangent of the half angle: numpy vectorises float64 tan
    but sends cos and sin to scalar libm (~5x slower each); the results agree with libm to
    one ulp (|error| <= 2.3e-16, checked in tests/perf/test_perf_kinematics.py)."""
    t = np.multiply(th, 0.5)
    if not isinstance(t, np.ndarray):  # one number
        t = np.tan(t)
        q = 1.0 / (1.0 + t * t)
        return (1.0 - t * t) * q, (t + t) * q
    np.tan(t, out=t)  # the temporaries reused in place: the same values, fewer allocations
    c = t * t
    q = np.add(c, 1.0)
    np.divide(1.0, q, out=q)
    np.subtract(1.0, c, out=c)
    c *= q
    np.add(t, t, out=t)
    t *= q
    return c, t


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
