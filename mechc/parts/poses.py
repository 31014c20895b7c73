"""What a closed-form solve gives: every body's coordinate over N states (``Poses``).

Kept apart from the solver so that the part kinds (``mechc.parts``), which read and write these
coordinates, and the solver that orders them (``mechc.physics.closed_form``) share it without
importing each other.
"""

from __future__ import annotations

import math
import weakref
from collections.abc import Iterator, MutableMapping
from dataclasses import dataclass, field
from typing import Protocol

import numpy as np

from mechc.ir.mechanism import GROUND


class KinematicsError(Exception):
    """The mechanism is not determinate from its geometry (a modelling error, not a state)."""


class _Entries(MutableMapping):
    """A mapping that keeps each entry as it was computed (``_v``) and derives what is read
    from it; copying from the same kind copies the stored entries, nothing derived."""

    def __init__(self, items: dict | None = None):
        self._v: dict = {}
        if items:
            self.update(items)

    def __contains__(self, key: object) -> bool:
        return key in self._v

    def __delitem__(self, key: str) -> None:
        del self._v[key]

    def __iter__(self) -> Iterator[str]:
        return iter(self._v)

    def __len__(self) -> int:
        return len(self._v)

    def update(self, other=(), **kw) -> None:
        if isinstance(other, type(self)):  # as stored: nothing derived
            self._v.update(other._v)
        else:
            super().update(other, **kw)


DEG, TAN, SIDES = "deg", "tan", "sides"  # the domains an angle is stored in


class Angles(_Entries):
    """Angles (degrees, 0..90) per joint over N states, each kept in the domain it was computed
    in: degrees; the angle's tangent (:meth:`set_tan`: a ratio of a cross and a dot product,
    or of a square root and a cosine); or the squared third side of a triangle of two fixed
    sides (:meth:`set_sides`: the law of cosines) — no trig per state. Reading an entry gives
    degrees; a check wants the extreme only, so :meth:`min_deg` takes it in the stored domain
    and converts that one value."""

    def __getitem__(self, key: str) -> np.ndarray:
        a, domain, sides = self._v[key]
        if domain == SIDES:
            a, domain = sides_tan(a, *sides), TAN
        return np.degrees(np.arctan(a)) if domain == TAN else a

    def __setitem__(self, key: str, degrees: np.ndarray) -> None:
        self._v[key] = (degrees, DEG, None)

    def set_tan(self, key: str, tangent: np.ndarray) -> None:
        """Store the angle as its tangent (inf: 90°, NaN: undefined, as NaN degrees)."""
        self._v[key] = (tangent, TAN, None)

    def set_sides(self, key: str, d2: np.ndarray, r2, l2) -> None:
        """Store the acute angle between the sides r and l of a triangle as the square ``d2``
        of its third side in every state (r², l²: numbers, or arrays of the states): the
        cosine |r² + l² - d²| / 2rl is linear in d², so the smallest angle is at the smallest
        or the largest d² and only those two are converted. 0° where the triangle cannot
        close, NaN where d² is NaN; per state exactly :func:`sides_tan`."""
        self._v[key] = (d2, SIDES, (r2, l2))

    def min_deg(self, key: str) -> float | None:
        """The smallest angle over the states (degrees); NaN if every state is undefined,
        None if there are no states."""
        a, domain, sides = self._v[key]
        if not np.size(a):
            return None
        if domain == SIDES:
            v = _sides_min_tan(a, *sides)
            domain = TAN
        else:
            v = float(np.fmin.reduce(a, axis=None))  # NaN only if every state is NaN
        if math.isnan(v):
            return math.nan
        return math.degrees(math.atan(v)) if domain == TAN else v


def sides_tan(d2, r2, l2):
    """Per state, tan of the acute angle between the sides r and l of a triangle whose third
    side is d: |arm×rod| / |arm·rod| in units of d² (A = 1/2 + (r² - l²)/2d², H² = r²/d² - A²,
    the lever-from-rod closed form's numbers): H / |r²/d² - A|, which unlike arccos of the
    cosine stays accurate near 0°; 0 where the triangle cannot close (H² < 0)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = np.divide(1.0, d2)
        A = inv * (0.5 * (r2 - l2))
        A += 0.5
        u = inv * r2
        H = np.sqrt(u - A * A)
        u -= A
        return np.fmax(H, 0.0) / np.abs(u)


def _sides_min_tan(d2: np.ndarray, r2, l2) -> float:
    """The smallest of :func:`sides_tan` over the states (NaN if every state is NaN): at the
    smallest or the largest d² (the angle rises to 90° at d² = r² + l² and falls on both
    sides, 0 past closing), those two worked out in Python floats (the same IEEE operations
    as numpy's, so the same values, without a numpy call per operation); every state's where
    the dimensions vary per state or a d² is 0 (a side of no length, whose angle the closed
    form leaves undefined or 0 by the sign of r² - l²)."""
    global _LAST_SIDES
    if isinstance(r2, (float, int)) and isinstance(l2, (float, int)):
        last = _LAST_SIDES  # one array serves the transmission and the toggle checks
        if last[0]() is d2 and last[1] == r2 and last[2] == l2 and not d2.flags.writeable:
            return last[3]
        lo = float(np.fmin.reduce(d2, axis=None))
        if math.isnan(lo):  # every state undefined
            return math.nan
        if lo != 0:
            a = _sides_tan_1(lo, r2, l2)
            b = _sides_tan_1(float(np.fmax.reduce(d2, axis=None)), r2, l2)
            v = a if b != b or a <= b else b  # the smaller, NaN passed over (as fmin)
            _LAST_SIDES = (weakref.ref(d2), r2, l2, v)
            return v
    return float(np.fmin.reduce(sides_tan(d2, r2, l2), axis=None))


#: the last (d² by weak reference, r², l², smallest tangent) worked out: a read-only d² is not
#: changed since, and the reference does not keep a proof's chunk alive
_LAST_SIDES: tuple = (lambda: None, None, None, math.nan)


def _sides_tan_1(d2: float, r2: float, l2: float) -> float:
    """:func:`sides_tan` of one d² > 0 (inf included), operation for operation."""
    inv = 1.0 / d2
    A = inv * (0.5 * (r2 - l2)) + 0.5
    u = inv * r2
    h2 = u - A * A
    h = math.sqrt(h2) if h2 > 0 else 0.0  # fmax(NaN, 0): 0 past the toggle
    w = abs(u - A)
    if w == 0:
        return math.inf if h > 0 else math.nan
    return h / w


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


class Turns(_Entries):
    """Turn angles (rad, ccw from the design pose) per body over N states: reading an entry
    gives the angle; :meth:`cos_sin` gives its cosine and sine the cheapest way the entry
    allows (see :class:`Turn`)."""

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
