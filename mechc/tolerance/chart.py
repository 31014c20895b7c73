"""Pictures of a tolerance run: the dimensions that matter most and each cell's share
(matplotlib, written as PNG)."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # files only: no display on a build machine
import matplotlib.pyplot as plt  # noqa: E402

from mechc.tolerance.montecarlo import ToleranceResult  # noqa: E402


def sensitivity_chart(result: ToleranceResult, path: str | Path, title: str, top: int = 20) -> None:
    """Top dimensions by how far each alone moves an output at its tolerance, and per cell
    the root-sum-square of its dimensions' effects."""
    ranked = result.ranked[:top]
    fig, (a, b) = plt.subplots(1, 2, figsize=(12, max(4, 0.3 * top)),
                               gridspec_kw={"width_ratios": [3, 2]})
    names = [r.dim.name for r in ranked][::-1]
    a.barh(names, [r.position_mm for r in ranked][::-1], color="#4a7ab5")
    a.set_xlabel("largest output movement from this dimension alone at its tolerance (mm)")
    a.set_title("dimensions (finite differences of the closed forms)")
    a.tick_params(axis="y", labelsize=7)
    owners = list(result.per_owner.items())[:top][::-1]
    b.barh([k for k, _ in owners], [v for _, v in owners], color="#b5734a")
    b.set_xlabel("root-sum-square of its dimensions' effects (mm)")
    b.set_title("per cell, net or input")
    b.tick_params(axis="y", labelsize=8)
    s = result.settings
    lo, hi = result.ci
    fig.suptitle(f"{title}: yield {result.yield_:.2%} [{lo:.2%}, {hi:.2%}] of {result.samples} "
                 f"samples at +-{s.tol} mm, pin clearance {s.clearance} mm, springs "
                 f"+-{s.spring_tol:.0%}", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
