"""Plane circle geometry on complex numbers: the intersections every synthesis method here needs
(the ordinary circle meeting itself is the geometry kernel's, :mod:`mechc.geometry.circles`).

Points are complex numbers (x + iy).  Two representations are used:

* an ordinary circle ``(centre, radius)`` for drawing and for the paper's construction
  (Mather & Erdman 2023, eqs. 10-14);
* a *generalised* circle ``A|t|^2 + 2 Re(B t) + C = 0`` (A, C real, B complex), which also
  covers straight lines (A = 0).  The precision-position equations produce these directly and a
  circle can turn into a line as a free choice varies, so the search code must not divide by A.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mechc.geometry.circles import circle_intersection, circle_meeting


@dataclass(frozen=True)
class Circle:
    centre: complex
    radius: float

    def contains(self, p: complex, tol: float = 1e-9) -> bool:
        return abs(abs(p - self.centre) - self.radius) <= tol * max(1.0, self.radius)


def intersect_circles(c1: complex, r1: float, c2: complex, r2: float) -> list[complex]:
    """The paper's eqs. 10-14 (distance a from centre 1 to the radical line, half-chord y, then
    the two points C1 + a e1 +- y e2, e2 = e1 turned a quarter turn), by the geometry kernel.
    Returns 0, 1 (tangent) or 2 points."""
    d = abs(c2 - c1)
    if d == 0.0 or d > r1 + r2 or d < abs(r1 - r2):
        return []
    # rounding may leave y^2 a hair below 0 at a tangency: clamp, as eq. 11 allows
    hi, y2 = circle_meeting(complex(c1), r1, complex(c2), r2, 1, miss="clamp")
    if y2 <= 0.0:
        return [complex(hi)]
    lo = circle_intersection(complex(c1), r1, complex(c2), r2, -1, miss="clamp")
    return [complex(hi), complex(lo)]


def circumcircle(z1: complex, z2: complex, z3: complex) -> Circle:
    """Circle through three points (raises if they are collinear)."""
    w = (z3 - z1) / (z2 - z1)
    if abs(w.imag) < 1e-14 * max(1.0, abs(w)):
        raise ValueError("circumcircle: the three points are collinear")
    c = (z2 - z1) * (w - abs(w) ** 2) / (2j * w.imag) + z1
    return Circle(complex(c), float(abs(z1 - c)))


def rotation_centre(p: complex, q: complex, angle: float) -> complex:
    """Centre of the rotation by ``angle`` (rad, counter-clockwise) that takes p to q."""
    e = np.exp(1j * angle)
    return complex((q - e * p) / (1.0 - e))


def reflect(p: complex, l1: complex, l2: complex) -> complex:
    """Mirror image of p in the line through l1 and l2."""
    u = (l2 - l1) / abs(l2 - l1)
    return complex(l1 + u * np.conj((p - l1) / u))


# --- generalised circles -------------------------------------------------------------------


def apollonius(a, b, c, d):
    """Coefficients (A, B, C) of the locus |a + b t| = |c + d t| in the complex t-plane.

    Works on numpy arrays (broadcast).  A = |b|^2 - |d|^2, B = conj(a) b - conj(c) d,
    C = |a|^2 - |c|^2.
    """
    A = np.abs(b) ** 2 - np.abs(d) ** 2
    B = np.conj(a) * b - np.conj(c) * d
    C = np.abs(a) ** 2 - np.abs(c) ** 2
    return A, B, C


def gcircle_to_circle(A: float, B: complex, C: float) -> Circle | None:
    """Centre and radius of a generalised circle; None for a line (A negligible against B and
    C, i.e. a circle of practically infinite radius) or an empty locus."""
    if abs(A) <= 1e-13 * max(abs(B), abs(C), 1e-300):
        return None
    centre = -np.conj(B) / A
    r2 = abs(B) ** 2 / A**2 - C / A
    if r2 < 0.0:
        return None
    return Circle(complex(centre), float(np.sqrt(r2)))


def intersect_gcircles(A1, B1, C1, A2, B2, C2):
    """Both intersection points of two generalised circles, vectorised.

    Subtracting the equations gives the radical line Re(P t) = -Q/2 with P = A2 B1 - A1 B2,
    Q = A2 C1 - A1 C2; the line is then cut with whichever circle is better conditioned.  The two
    points are returned as (hi, lo, ok), ordered along the line direction i*conj(P), so each label
    moves continuously while the parameters do (the search for concurrent circles relies on it).
    ``ok`` is False where the circles do not meet.
    """
    A1, B1, C1, A2, B2, C2 = np.broadcast_arrays(*(np.asarray(x) for x in (A1, B1, C1, A2, B2,
                                                                           C2)))
    P = A2 * B1 - A1 * B2
    Q = A2 * C1 - A1 * C2
    n = np.conj(P)
    nn = np.abs(n)
    with np.errstate(invalid="ignore", divide="ignore"):
        t0 = -0.5 * Q * n / nn**2
        e = 1j * n / nn
        use1 = np.abs(A1) >= np.abs(A2)
        A = np.where(use1, A1, A2)
        B = np.where(use1, B1, B2)
        C = np.where(use1, C1, C2)
        qa = A
        qb = 2.0 * (A * np.real(np.conj(t0) * e) + np.real(B * e))
        qc = A * np.abs(t0) ** 2 + 2.0 * np.real(B * t0) + C
        disc = qb * qb - 4.0 * qa * qc
        ok = (disc >= 0.0) & (nn > 0.0)
        sq = np.sqrt(np.where(ok, disc, 0.0))
        # stable quadratic roots: q = -(qb + sign(qb) sq)/2, roots q/qa and qc/q
        qq = -0.5 * (qb + np.where(qb >= 0.0, 1.0, -1.0) * sq)
        big = np.abs(qa) > 1e-300
        s1 = np.where(big, qq / np.where(big, qa, 1.0), np.nan)
        s2 = np.where(qq != 0.0, qc / np.where(qq != 0.0, qq, 1.0), np.nan)
        # a (near-)line circle: one root runs off to infinity and the other stays finite
        s1 = np.where(big, s1, s2)
        s_hi = np.fmax(s1, s2)
        s_lo = np.fmin(s1, s2)
    ok = ok & np.isfinite(s_hi) & np.isfinite(s_lo)
    return t0 + s_hi * e, t0 + s_lo * e, ok
