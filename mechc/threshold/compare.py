"""Computation against the scanned Tables V and VI and Program A's sample output (001 §3.7,
Appendix D): the numbers behind the comparison section of docs/threshold.md.

    python -m mechc.threshold.compare
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np

from mechc.geometry.circles import circle_intersection
from mechc.threshold.cam import Follower, FollowerProgram
from mechc.threshold.linkage import basic_loop, make_loop, sample_points, threshold_gaps
from mechc.threshold.seed_tables import (
    PROGRAM_A_THETA7,
    TABLE_V,
    TABLE_V_PATTERNS,
    TABLE_VI,
    TABLE_VI_FOLLOWER,
)
from mechc.threshold.separator import SeparatorLayout, analyse, layout


def _mags(pattern: tuple[int, ...]) -> tuple[int, ...]:
    return tuple(m for m in pattern if m)


def table_v_computed(col: int, tilt_rule: str = "table_v") -> dict[str, float | None]:
    """Table V's quantities for column ``col`` (0..4) from :func:`separator.layout`."""
    lay = layout(_mags(TABLE_V_PATTERNS[col]), tilt_rule=tilt_rule)
    out: dict[str, float | None] = {}
    for c in ("A", "B", "C"):
        if c in lay.centres:
            (x, y), (xp, yp) = lay.centres[c]
            out.update({f"x_X{c}": x, f"y_X{c}": y, f"x_X{c}'": xp, f"y_X{c}'": yp})
        else:
            out.update({f"x_X{c}": None, f"y_X{c}": None, f"x_X{c}'": None, f"y_X{c}'": None})
    for k in ("AD", "DE", "BE", "BG", "CG", "AF"):
        out[k] = lay.lengths.get(k)
    d = np.degrees(lay.half_swing)
    out.update(dtheta=2 * d, theta0=90 + d, theta1=90 - d)
    return out


def table_v_differences(tilt_rule: str = "table_v") -> list[tuple[str, int, float, float]]:
    """(quantity, column, printed, computed) where they differ by more than 1e-5 (the table
    prints five decimals)."""
    out = []
    for col in range(5):
        comp = table_v_computed(col, tilt_rule)
        for key, printed in TABLE_V.items():
            p, c = printed[col], comp[key]
            if p is None and c is None:
                continue
            if p is None or c is None or abs(p - c) > 1.5e-5:
                out.append((key, col, p, c))
    return out


def program_a_theta7() -> np.ndarray:
    """Direction of A -> D (deg) for W = (2,1,1) in Program A's input order (x1 on crank C,
    x2 on B, x3 on A)."""
    lay = layout((2, 1, 1))
    combos = np.array(list(itertools.product((0, 1), repeat=3)))
    tips = {"A": lay.tip("A", combos[:, 2], False), "B": lay.tip("B", combos[:, 1], False),
            "C": lay.tip("C", combos[:, 0], False)}
    j = lay.solve(tips)
    v = j["D"] - j["A"]
    return np.degrees(np.arctan2(v[:, 1], v[:, 0]))


@dataclass
class TableVIColumn:
    column: int
    pattern: tuple[int, ...]
    gaps: tuple[int, ...]
    theta0_printed: float
    theta0_computed: float
    delta_printed: np.ndarray  # sorted
    delta_computed: np.ndarray  # sorted
    path_gaps_deg: np.ndarray  # threshold gaps of the printed loop counting every F path
    transmission_min: float  # printed loop, every F position and path (deg)
    ours_gaps_deg: np.ndarray  # threshold gaps of mechc's loop for the same separator and gaps
    ours_loop: tuple[float, float, float, float]  # K_x, K_y, FJ, JK


def _positive(lay: SeparatorLayout) -> tuple[bool, ...]:
    """Fixed centres that make every weight positive (the basic linkages of Figs. 33, 34)."""
    return tuple(c < 0 for c in lay.proportions.coeffs)


def _cam_angles(lay: SeparatorLayout, K, fj, jk, branch) -> np.ndarray:
    """Absolute KJ angle (deg) for input combinations 000..111, all weights positive."""
    combos = np.array(list(itertools.product((0, 1), repeat=len(lay.cranks))))
    pr = _positive(lay)
    F = lay.solve({c: lay.tip(c, 1 - combos[:, i] if pr[i] else combos[:, i], pr[i])
                   for i, c in enumerate(lay.cranks)})["F"]
    J = circle_intersection(F, fj, np.broadcast_to(np.asarray(K), F.shape), jk, branch)
    v = J - np.asarray(K)
    return np.degrees(np.arctan2(v[:, 1], v[:, 0]))


def table_vi_column(col: int) -> TableVIColumn:
    pattern, letters, K, fj, jk, theta0, deltas = TABLE_VI[col]
    mags = _mags(pattern)
    lay = layout(mags)
    gaps = tuple("abcdefg".index(c) for c in letters)
    best = None
    for branch in (1, -1):
        ang = _cam_angles(lay, K, fj, jk, branch)
        rel = (ang - ang[0] + 180) % 360 - 180
        rel = rel if rel[np.argmax(np.abs(rel))] > 0 else -rel
        d = np.sort(np.abs(rel[1:]))
        err = np.abs(d - np.sort(deltas)).max() if len(d) == len(deltas) else np.inf
        if best is None or err < best[0]:
            best = (err, branch, ang[0] % 360, d)
    _, branch, th0, d = best
    sp = sample_points(analyse(lay, 50), _positive(lay))
    loop = make_loop(K, fj, jk, branch, sp)
    phi = np.degrees(loop.cam_angle(sp.F))
    mine = basic_loop(mags, gaps)
    phi_m = np.degrees(mine.cam_angle(sp.F))  # mechc's loop serves both centres; shown on these
    return TableVIColumn(col, pattern, gaps, theta0, float(th0), np.sort(deltas), d,
                         threshold_gaps(phi, sp, gaps), float(loop.transmission(sp.F).min()),
                         threshold_gaps(phi_m, sp, gaps), (*mine.K, mine.FJ, mine.JK))


def table_vi_pressure_estimate(col: int) -> float:
    """Largest pressure angle (deg) of Table VI's follower (ZH = 0.35 l, swing as an input
    crank, K-H as printed, roller on the K-H line at the inner dwell) if each rise took a whole
    separation angle of its threshold gap with cycloidal motion. Appendix E's cam section is
    missing from the scan, so this is an estimate of what the printed follower implies."""
    pattern, letters, K, fj, jk, _theta0, _deltas = TABLE_VI[col]
    c = table_vi_column(col)
    lay = layout(_mags(pattern))
    sp = sample_points(analyse(lay, 50), _positive(lay))
    loop = make_loop(K, fj, jk, _branch_for(col), sp)
    phi = loop.cam_angle(sp.F)
    rest = sp.lo == sp.hi
    bands = []
    for g in c.gaps:
        lo = phi[rest & (sp.lo == g)].max()
        hi = phi[rest & (sp.lo == g + 1)].min()
        bands.append((float(lo), float(hi)))
    swing = 2 * lay.half_swing
    radius = TABLE_VI_FOLLOWER["KH"][col] + TABLE_VI_FOLLOWER["ZH"] * np.sin(swing / 2)
    fol = Follower(K, 0.0, float(radius), TABLE_VI_FOLLOWER["ZH"], swing, 0.1, False)
    grid = np.linspace(phi.min(), phi.max(), 4001)
    return float(fol.pressure_angle(grid, FollowerProgram(tuple(bands)), loop.orientation).max())


def _branch_for(col: int) -> int:
    pattern, _letters, K, fj, jk, theta0, _d = TABLE_VI[col]
    lay = layout(_mags(pattern))
    errs = {}
    for b in (1, -1):
        a = _cam_angles(lay, K, fj, jk, b)[0] % 360
        errs[b] = abs((a - theta0 + 180) % 360 - 180)
    return min(errs, key=errs.get)


def main() -> None:
    print("Table V differences (quantity, column, printed, computed):")
    for key, col, p, c in table_v_differences():
        print(f"  {key:7s} {'I II III IV V'.split()[col]:4s} {p} {c}")
    print("Table V column V with the mirror droop rule:", table_v_differences("mirror")[:4])
    print("Program A theta7:", np.round(program_a_theta7(), 5), "printed", PROGRAM_A_THETA7)
    for col in range(len(TABLE_VI)):
        c = table_vi_column(col)
        print(f"Table VI col {col + 1}: {c.pattern} gaps {c.gaps}: theta0 {c.theta0_printed} vs "
              f"{c.theta0_computed:.4f}; max |delta diff| "
              f"{np.abs(c.delta_printed - c.delta_computed).max():.4f} "
              f"(worst at {c.delta_printed[np.argmax(np.abs(c.delta_printed - c.delta_computed))]})"
              f"; path gaps {np.round(c.path_gaps_deg, 2)} trans {c.transmission_min:.2f}; "
              f"mechc gaps {np.round(c.ours_gaps_deg, 2)} loop {np.round(c.ours_loop, 3)}; "
              f"pressure estimate {table_vi_pressure_estimate(col):.1f}")


if __name__ == "__main__":
    main()
