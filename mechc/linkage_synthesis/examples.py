"""The worked examples of Mather & Erdman 2023 (seed ``004_…``) as data, with their printed
answers, and the comparison of each printed answer with the exact solution.

The printed answers were read off plotted circles.  They are kept here only to be *checked*:
:func:`printed_residual` measures how far a printed chain is from satisfying the paper's own
standard-form equations.  Numbers are as printed in the captions (angles in degrees).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mechc.linkage_synthesis.mk_circles import ChainProblem, chain_problem

_TRIAD_PTS6 = [0, 1.553 + 1.329j, 3.023 + 2.957j, 4.564 + 2.014j, 7.432 + 2.016j,
               8.670 + 0.737j]
_TRIAD_BETA7 = [0, 30, 70, 140, 150, 130, 160]
_TRIAD_GAMMA7 = [0, -30, -60, -65, -90, -110, -130]


@dataclass(frozen=True)
class Example:
    name: str
    caption: str
    problem: ChainProblem
    printed: dict  # what the paper prints as the answer


def _dyad(points, alpha, beta):
    return chain_problem(points, {"alpha": alpha, "beta": beta}, free="beta")


def _triad(points, beta, alpha, gamma):
    return chain_problem(points, {"beta": beta, "alpha": alpha, "gamma": gamma}, free="alpha")


EXAMPLES: dict[str, Example] = {
    "fig1": Example(
        "fig1", "Figure 1: dyad, three positions, circles for beta2 = -110",
        _dyad([0, 1.75 + 1j, 3.5 + 3j], [0, -50, -90], [0, -110, None]), {}),
    "fig4": Example(
        "fig4", "Figure 4: dyad, four positions, beta2 = -110",
        _dyad([0, 1.75 + 1j, 3.5 + 2j, 5.5 + 1j], [0, -50, -90, -110], [0, -110, None, None]),
        {"solutions": [[0.514 + 0.382j, -3.141 + 1.245j], [1.232 + 0.894j, -4.895 + 1.036j]]}),
    "figA3": Example(
        "figA3", "Figure A3: dyad, five positions (beta2 searched)",
        _dyad([0, 1 + 2j, 2.5 + 4j, 4 + 3.5j, 4.6865 + 3.0306j], [0, 0, 45, 70, 85],
              [0, None, None, None, None]),
        {"solutions": [[2.67 - 2.59j, -0.64 - 2.19j]], "beta2": 35.002}),
    "tableA1": Example(
        "tableA1", "Table A1 / Figure 12: loop-three dyad, four positions, beta2 = -44.775",
        _dyad([0, 0.130 + 0.274j, -0.246 + 0.396j, -0.586 + 0.167j],
              [0, 24.919, 90.062, 132.141], [0, -44.775, None, None]),
        {"beta3": 269.067, "beta4": 96.572, "fig12_beta": [-45.508, -90.331, -95.758],
         "table4_solution": [-0.164 + 0.239j, 0.562 + 0.090j]}),
    "figA4": Example(
        "figA4", "Figures 5 / A4: triad, four positions, alpha2 = 60 (alpha3, alpha4 free)",
        _triad([0 + 4j, 2.553 + 3.329j, 5.023 + 1.957j, 8.564 + 6.014j], [0, 10, 70, 140],
               [0, 60, None, None], [0, 30, 90, 145]), {}),
    "fig7": Example(
        "fig7", "Figure 7: triad, five positions, alpha2 = 60",
        _triad([0, 1.552 + 1.329j, 3.023 + 2.957j, 4.564 + 2.014j, 6.564 + 1.014j],
               [0, 30, 70, 140, 150], [0, 60, None, None, None], [0, -30, -60, -65, -90]),
        {"solutions": [[-1.634 + 0.695j, 1.694 + 0.901j, -5.351 + 2.733j]]}),
    "figA5": Example(
        "figA5", "Figure A5: triad, six positions, alpha2 = -15 (alpha3 searched)",
        _triad(_TRIAD_PTS6, _TRIAD_BETA7[:6], [0, -15, None, None, None, None],
               _TRIAD_GAMMA7[:6]),
        {"solutions": [[1.651 + 1.567j, -2.134 + 0.998j, -6.326 + 1.137j]]}),
    "figA6": Example(
        "figA6", "Figure A6: triad, seven positions (alpha2, alpha3 searched)",
        _triad(_TRIAD_PTS6 + [11.174 - 0.659j], _TRIAD_BETA7, [0] + [None] * 6, _TRIAD_GAMMA7),
        {"solutions": [[1.651 + 1.567j, -2.134 + 0.998j, -6.326 + 1.137j]], "alpha2": -15}),
}


def printed_residual(problem: ChainProblem, links) -> np.ndarray:
    """Per position j = 2..n, how far a given chain is from position j: the modulus of the
    standard-form residual where the free angle is prescribed, and otherwise the best over the
    free angle, | |R_j| - |L_u| | (the free link's end misses the point it must reach by this
    much).  Relative to the problem size."""
    L = np.asarray(links, complex)
    u = problem.free_link
    out = []
    for j in range(1, problem.n):
        others = sum(L[l] * (np.exp(1j * problem.angles[l, j]) - 1.0)
                     for l in range(problem.k) if l != u)
        R = problem.deltas[j] - others
        if np.isnan(problem.angles[u, j]):
            out.append(abs(abs(R + L[u]) - abs(L[u])))
        else:
            out.append(abs(R - L[u] * (np.exp(1j * problem.angles[u, j]) - 1.0)))
    return np.array(out) / problem.scale
