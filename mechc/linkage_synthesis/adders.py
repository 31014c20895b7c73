"""Bar-linkage adders and their structural error (``002_…``, Chapter 2, eqs. 8 and 13-15).

Structural error is the error a linkage makes by its very geometry, before any manufacturing
error: the exact adder of Fig. 2-12 has none; the long-bar adder of Fig. 2-15 and the whiffletree
separator of the threshold generators (``001_…`` Fig. 22, eq. 3.13) are only approximately linear.
The threshold synthesis must budget for that error, so :func:`structural_error` computes it for
any chain of floating levers from the paths of their driving points.

Conventions: points are complex numbers (mm), displacements are measured along ``direction``
(the line of the slides, default +x) from the reference (first) sample.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from mechc.geometry.circles import circle_intersection

# --- the exact adder ---------------------------------------------------------------------------


def exact_adder(a1: float, a2: float, x1, x2):
    """Eq. 8: (A1 + A2) X3 = A1 X1 + A2 X2 (Fig. 2-12; free from structural error)."""
    return (a1 * np.asarray(x1, float) + a2 * np.asarray(x2, float)) / (a1 + a2)


def bar_shortening(length: float, angle) -> np.ndarray:
    """Eq. 15b: a bar of length L at angle theta to the slides loses L (1 - cos theta) of its
    projection -- the whole source of the long-bar adder's structural error."""
    return length * (1.0 - np.cos(np.asarray(angle, float)))


# --- the long-bar (approximate) adder of Fig. 2-15 ---------------------------------------------


@dataclass(frozen=True)
class LongBarAdder:
    """Fig. 2-15.  Input slides run along y = y1 and y = y2 carrying pins S1, S2 at
    x = X1 - l1, X2 - l2; bars of length l1, l2 run from them (towards +x) to pins P1, P2 of a
    lever whose pin P3 rides the output slide y = y3 at x = X3.  P1 and P2 sit at signed
    distances r1, r2 from P3 along the lever (r1 > 0 > r2 puts P3 between them).  With
    y_i = y3 + r_i the bars are parallel to the slides in the zero state (X1 = X2 = 0), as the
    book assumes."""

    r1: float
    r2: float
    l1: float
    l2: float
    y3: float = 0.0
    y1: float | None = None
    y2: float | None = None

    @property
    def weights(self) -> tuple[float, float]:
        """(w1, w2) with X3 ~ w1 X1 + w2 X2 (eq. 13: w_i = A_i / (A1 + A2))."""
        d = self.r1 - self.r2
        return -self.r2 / d, self.r1 / d

    def _y(self):
        return (self.y3 + self.r1 if self.y1 is None else self.y1,
                self.y3 + self.r2 if self.y2 is None else self.y2)


@dataclass
class LongBarState:
    x3: np.ndarray  # output pin displacement from the zero state
    phi: np.ndarray  # lever tilt (rad)
    theta1: np.ndarray  # bar angles to the slides (rad)
    theta2: np.ndarray
    error: np.ndarray  # structural error: x3 - (w1 X1 + w2 X2)
    ok: np.ndarray  # bool: Newton converged and the bars reach


def long_bar_adder(adder: LongBarAdder, x1, x2, iters: int = 50) -> LongBarState:
    """Exact motion of the Fig. 2-15 adder (vectorised), with the error from eqs. 14-15.

    Eq. 14 holds exactly for the x coordinates of the three collinear lever pins; eq. 15 relates
    each lever pin to its slide through the bar angle.  Eliminating the output gives one equation
    in the lever tilt phi, solved by Newton's method from the linear estimate.
    """
    x1, x2 = np.broadcast_arrays(np.asarray(x1, float), np.asarray(x2, float))
    r1, r2, l1, l2 = adder.r1, adder.r2, adder.l1, adder.l2
    y1, y2 = adder._y()
    y3 = adder.y3

    def parts(phi):
        s1 = (y3 + r1 * np.cos(phi) - y1) / l1
        s2 = (y3 + r2 * np.cos(phi) - y2) / l2
        c1, c2 = np.sqrt(1.0 - s1 * s1), np.sqrt(1.0 - s2 * s2)
        return s1, s2, c1, c2

    with np.errstate(invalid="ignore"):
        phi = np.arcsin(np.clip((x2 - x1) / (r1 - r2), -1.0, 1.0))
        for _ in range(iters):
            s1, s2, c1, c2 = parts(phi)
            f = x1 - x2 + (r1 - r2) * np.sin(phi) - l1 * (1.0 - c1) + l2 * (1.0 - c2)
            df = ((r1 - r2) * np.cos(phi) + s1 * r1 * np.sin(phi) / c1
                  - s2 * r2 * np.sin(phi) / c2)
            step = f / df
            phi = phi - step
            if np.all(np.abs(step[np.isfinite(step)]) < 1e-16):
                break
        s1, s2, c1, c2 = parts(phi)
        f = x1 - x2 + (r1 - r2) * np.sin(phi) - l1 * (1.0 - c1) + l2 * (1.0 - c2)
    th1, th2 = np.arcsin(s1), np.arcsin(s2)
    w1, w2 = adder.weights
    s10, s20, _, _ = parts(0.0)
    th10, th20 = np.arcsin(s10), np.arcsin(s20)
    # eq. 14 with eq. 15b: the projections lost by the bars, relative to the zero state
    error = -(w1 * (bar_shortening(l1, th1) - bar_shortening(l1, th10))
              + w2 * (bar_shortening(l2, th2) - bar_shortening(l2, th20)))
    # where the output pin itself lands, through bar 1 and the lever (zero-state based)
    x3 = x1 - bar_shortening(l1, th1) + bar_shortening(l1, th10) + r1 * np.sin(phi)
    ok = np.isfinite(f) & (np.abs(f) < 1e-9 * max(l1, l2)) & np.isfinite(error)
    return LongBarState(x3, phi, th1, th2, error, ok)


# --- whiffletree levers: the separator of the threshold generators ----------------------------


@dataclass(frozen=True)
class LeverStage:
    """One floating lever of a whiffletree (``001_…`` Fig. 22), given by its reference state.

    The lever end ``pin`` rides a driven point (e.g. an input crank pin); its other end ``far``
    is pulled by a link from ``anchor`` (a driven point, or the previous stage's output).  The
    output point is F = pin + p (far - pin): 0 < p < 1 between the ends, p < 0 or p > 1 on an
    extension (which gives a negative weight, as in Fig. 31(d-e)).  Lengths and the assembly
    side follow from these reference positions.
    """

    pin: complex
    far: complex
    anchor: complex
    p: float

    @property
    def lever(self) -> float:
        return abs(self.far - self.pin)

    @property
    def link(self) -> float:
        return abs(self.far - self.anchor)

    @property
    def side(self) -> float:
        """Which of the two circle intersections the far end takes (sign of a cross product)."""
        return float(np.sign(np.imag(np.conj(self.anchor - self.pin) * (self.far - self.pin))))

    @property
    def output(self) -> complex:
        return self.pin + self.p * (self.far - self.pin)


@dataclass
class AdderError:
    """Result of :func:`structural_error` (arrays over the N samples)."""

    output: np.ndarray  # complex: the last stage's output point
    displacement: np.ndarray  # its displacement along ``direction`` from sample 0
    linear: np.ndarray  # the linear law sum w_i s_i (eq. 3.13 of 001_…, eq. 13 of 002_…)
    error: np.ndarray  # displacement - linear: the structural error (mm)
    weights: list[float]  # w for [anchor of stage 0, pin of stage 0, pin of stage 1, ...]
    far: np.ndarray  # (stages, N) complex: the far lever ends
    transmission: np.ndarray  # (stages, N) deg: angle between lever and link, folded to <= 90
    ok: np.ndarray  # bool: every stage assembles

    @property
    def max_abs(self) -> float:
        return float(np.max(np.abs(self.error[self.ok]))) if self.ok.any() else float("inf")


def structural_error(stages: Sequence[LeverStage], pins: Sequence, anchor,
                     direction: complex = 1.0) -> AdderError:
    """Structural error of a chain of floating levers against its linear law.

    ``pins[k]`` is the path (complex array, N samples, sample 0 = the reference state) of stage
    k's pinned end; ``anchor`` the path of stage 0's anchor.  Stage k > 0 is anchored at stage
    k-1's output (in Fig. 22 of ``001_…``: stage 0 = lever BG with pin B, anchor C, output E;
    stage 1 = lever AD with pin A, anchor E, output F).  Displacements are components along
    ``direction``.  The linear law weights the input displacements by
    (prod p, (1 - p_0) prod_{j>0} p_j, ..., 1 - p_last) -- eq. 3.13 of ``001_…``.
    """
    if len(pins) != len(stages):
        raise ValueError(f"{len(stages)} stages but {len(pins)} pin paths")
    u = complex(direction) / abs(direction)
    q = np.asarray(anchor, complex)
    for k, st in enumerate(stages[1:], start=1):
        if abs(st.anchor - stages[k - 1].output) > 1e-9 * max(1.0, st.lever):
            raise ValueError(f"stage {k}: anchor {st.anchor} is not stage {k - 1}'s output "
                             f"{stages[k - 1].output}")
    fars, trans = [], []
    ok = np.ones(q.shape, bool)
    for st, pin in zip(stages, pins):
        pin = np.asarray(pin, complex)
        # the far end on the lever's side of pin -> anchor (the kernel's branch +1 is the
        # positive side Im(conj(q - pin) (far - pin)) > 0); NaN where the circles miss
        far = circle_intersection(pin, st.lever, q, st.link, st.side, miss="nan")
        ok &= np.isfinite(far)
        fars.append(far)
        with np.errstate(invalid="ignore"):
            cosang = np.real((pin - far) * np.conj(q - far)) / (st.lever * st.link)
            ang = np.degrees(np.arccos(np.clip(cosang, -1.0, 1.0)))
        trans.append(np.minimum(ang, 180.0 - ang))
        q = pin + st.p * (far - pin)
    disp = np.real((q - q[0]) * np.conj(u))
    # weights of the linear law, composed stage by stage
    w = [1.0]  # anchor of stage 0
    for st in stages:
        w = [wi * st.p for wi in w] + [1.0 - st.p]
    inputs = [np.asarray(anchor, complex)] + [np.asarray(p, complex) for p in pins]
    lin = sum(wi * np.real((x - x[0]) * np.conj(u)) for wi, x in zip(w, inputs))
    return AdderError(q, disp, lin, disp - lin, w, np.array(fars), np.array(trans), ok)
