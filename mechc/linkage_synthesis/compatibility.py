"""The compatibility-linkage method for a 4-position dyad: an independent check on the circles.

A dyad reaches four positions only if the 3x3 determinant [e^{i beta_j} - 1, e^{i alpha_j} - 1,
delta_j] (j = 2..4) vanishes.  Expanding along the first column gives a closed vector loop::

    D1 + D2 e^{i beta2} + D3 e^{i beta3} + D4 e^{i beta4} = 0,     D1 = -(D2 + D3 + D4)

-- a four-bar (the "compatibility linkage", Mather & Erdman 2023, Appendix A, eqs. A2-A10) whose
crank angle is the free choice beta2.  For each beta2 the loop closes in two assembly modes,
each giving (beta3, beta4) and then the dyad from the linear 3-position equations.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mechc.linkage_synthesis.mk_circles import ChainProblem, residual


@dataclass(frozen=True)
class CompatibilityLinkage:
    d1: complex
    d2: complex
    d3: complex
    d4: complex


def compatibility_linkage(problem: ChainProblem) -> CompatibilityLinkage:
    """The four link vectors D1..D4 (eqs. A2-A5) of a 4-position dyad problem (alpha known)."""
    if problem.k != 2 or problem.n != 4 or problem.free_link != 0:
        raise ValueError("the compatibility linkage is for a dyad in 4 positions with beta free")
    a = np.exp(1j * problem.angles[1]) - 1.0
    d = problem.deltas
    D2 = a[2] * d[3] - a[3] * d[2]  # eq. A2: det [a3 d3; a4 d4]
    D3 = -(a[1] * d[3] - a[3] * d[1])  # eq. A3: minus det [a2 d2; a4 d4]
    D4 = a[1] * d[2] - a[2] * d[1]  # eq. A4: det [a2 d2; a3 d3]
    return CompatibilityLinkage(complex(-(D2 + D3 + D4)), complex(D2), complex(D3), complex(D4))


@dataclass(frozen=True)
class CompatibilitySolution:
    beta2: float  # rad
    beta3: float
    beta4: float
    mode: int  # +1 / -1: the sign taken on acos in eq. A8
    links: np.ndarray  # W, Z
    residual: float


def solve_compatibility(problem: ChainProblem, beta2: float) -> list[CompatibilitySolution]:
    """Both closures of the compatibility linkage for crank angle beta2 (rad), each turned into
    a dyad by the linear equations of positions 2 and 3, with its residual over all four.

    The paper's eqs. A8 and A10 both take +acos; a closed loop pairs +acos for beta3 with the
    mirror (-acos) solution for beta4, so beta4 here follows from the loop itself.
    """
    cl = compatibility_linkage(problem)
    R = cl.d1 + cl.d2 * np.exp(1j * beta2)  # eq. A6
    r, l3, l4 = abs(R), abs(cl.d3), abs(cl.d4)
    if r == 0.0 or l3 == 0.0:
        return []
    x = (l4**2 - r**2 - l3**2) / (2 * r * l3)  # eq. A7 (law of cosines)
    if abs(x) > 1.0:
        return []  # the loop cannot close for this beta2
    out = []
    for mode in (+1, -1):
        b3 = np.angle(R) + mode * np.arccos(x) - np.angle(cl.d3)  # eq. A8
        b3 = float(np.angle(np.exp(1j * b3)))
        v4 = -(R + cl.d3 * np.exp(1j * b3))
        b4 = float(np.angle(v4 / cl.d4))
        links = dyad_from_betas(problem, beta2, b3)
        ang = problem.angles.copy()
        ang[0, 1:] = [beta2, b3, b4]
        out.append(CompatibilitySolution(beta2, b3, b4, mode, links,
                                         residual(problem, links, ang)))
    return out


def dyad_from_betas(problem: ChainProblem, beta2: float, beta3: float) -> np.ndarray:
    """W, Z from the linear standard form of positions 1-3 (paper eq. 1)."""
    a = np.exp(1j * problem.angles[1]) - 1.0
    M = np.array([[np.exp(1j * beta2) - 1.0, a[1]], [np.exp(1j * beta3) - 1.0, a[2]]])
    return np.linalg.solve(M, problem.deltas[1:3])
