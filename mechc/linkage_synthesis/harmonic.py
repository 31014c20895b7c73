"""Harmonic transformers and homogeneous parameters (``002_…``, Chapter 3 §3-2, Chapter 4).

An *ideal* harmonic transformer (a Scotch yoke or similar right-triangle mechanism) relates a
crank angle X_i to a slide position X_k exactly by X_k = R sin X_i (eq. 4-1).  The practical
crank-and-link version of Fig. 4-2 (crank R, link L, slide line offset W from the crank pivot)
differs from it by the structural error dX_k = -L (1 - cos eps) with L sin eps = R cos X_i - W
(eqs. 4-2 to 4-5).  Homogeneous parameters rescale any finite travel to 0..1 (eqs. 3-10 to 3-16)
so that tabulated mechanisms can be compared with a required function (eqs. 4-11 to 4-13).

Angles in radians; X_i is measured clockwise from the crank position perpendicular to the slide
(the book's zero position, crank pointing "up" at the slide).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


def homogeneous(x, lo: float, hi: float):
    """Eq. 3-10 / 3-14: h = (x - x_min) / (x_max - x_min), 0 at the lower and 1 at the upper
    bound of the travel."""
    return (np.asarray(x, float) - lo) / (hi - lo)


def from_homogeneous(h, lo: float, hi: float):
    """Eq. 3-11 / 3-16: x = x_min + h (x_max - x_min)."""
    return lo + np.asarray(h, float) * (hi - lo)


def ideal_harmonic(radius: float, angle):
    """Eq. 4-1: X_k = R sin X_i."""
    return radius * np.sin(np.asarray(angle, float))


def _sin_range(lo: float, hi: float) -> tuple[float, float]:
    """Minimum and maximum of sin over [lo, hi] (the three cases of Fig. 4-6)."""
    vals = [np.sin(lo), np.sin(hi)]
    for ext in (np.pi / 2, -np.pi / 2):
        k = np.ceil((lo - ext) / (2 * np.pi))
        if ext + 2 * np.pi * k <= hi:
            vals.append(np.sin(ext))
    return float(min(vals)), float(max(vals))


def harmonic_homogeneous(theta, x_lo: float, travel: float):
    """Eq. 4-12: the homogeneous output H_k of an ideal harmonic transformer as a function of
    the homogeneous crank parameter theta_i, for a crank travelling from x_lo through ``travel``
    (rad).  Eqs. 4-13a-c are the special cases where the extreme of sin lies at an end or
    inside the travel; :func:`_sin_range` picks the case."""
    smin, smax = _sin_range(x_lo, x_lo + travel)
    return (np.sin(x_lo + np.asarray(theta, float) * travel) - smin) / (smax - smin)


@dataclass(frozen=True)
class CrankLinkTransformer:
    """Fig. 4-2: crank R pivoted at the origin, link L to a slider on the line y = W."""

    radius: float
    link: float
    offset: float

    def eps(self, angle):
        """Link angle to the slide, from eq. 4-5: L sin eps = R cos X_i - W."""
        return np.arcsin((self.radius * np.cos(np.asarray(angle, float)) - self.offset)
                         / self.link)

    def output(self, angle):
        """Eq. 4-2: X'_k = R sin X_i - L (1 - cos eps)."""
        return ideal_harmonic(self.radius, angle) + self.structural_error(angle)

    def structural_error(self, angle):
        """Eq. 4-4: dX_k = -L (1 - cos eps)."""
        return -self.link * (1.0 - np.cos(self.eps(angle)))


def best_offset(radius: float, x_lo: float, x_hi: float) -> float:
    """The slide offset W that keeps |eps| (hence the structural error) smallest over a crank
    travel: W at the middle of the range of R cos X_i (the choice drawn in Fig. 4-2)."""
    cmin, cmax = _sin_range(x_lo + np.pi / 2, x_hi + np.pi / 2)  # cos x = sin(x + pi/2)
    return radius * 0.5 * (cmin + cmax)


def max_structural_error(tr: CrankLinkTransformer, x_lo: float, x_hi: float,
                         samples: int = 2001) -> float:
    """Largest |dX_k| over the crank travel, sampled (the error is smooth and the ends and the
    crank-perpendicular position are included)."""
    x = np.linspace(x_lo, x_hi, samples)
    return float(np.max(np.abs(tr.structural_error(x))))
