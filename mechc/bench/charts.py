"""The benchmark's charts: speed against accuracy (Pareto fronts of the settings grid, defaults,
pruned and kinematic marked) and the stability study's four panels.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from mechc.bench.harness import Bench
from mechc.bench.stability_study import short_kinds
from mechc.physics.measures import MIN_SINGULAR_MARGIN_DEG


def pareto(points: list[tuple[float, float]]) -> list[tuple[float, float]]:
    """Points (time, error) no other point beats in both."""
    front, best = [], math.inf
    for t, e in sorted(points):
        if e < best:
            front.append((t, e))
            best = e
    return front


def chart(b: Bench, path: Path) -> None:
    import matplotlib  # here, not at the top: ``mechc`` loads this module for every command

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(8.5, 6))
    colors = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    circuits_seen = sorted({r["circuit"] for r in b.rows if r["section"] in ("grid", "levels")
                            and r["level"] == "dynamic"})
    floor = 1e-6
    for i, name in enumerate(circuits_seen):
        col = colors[i % len(colors)]
        pts = [r for r in b.rows if r["circuit"] == name and r["section"] == "grid"]
        good = [(r["seconds_per_case"], max(floor, r["error_fraction"])) for r in pts
                if r["solver_ok"]]
        bad = [(r["seconds_per_case"], max(floor, r["error_fraction"])) for r in pts
               if not r["solver_ok"]]
        if good:
            ax.scatter(*zip(*good), s=14, color=col, alpha=0.55, label=f"{name}")
            f = pareto(good)
            ax.plot(*zip(*f), color=col, lw=1.5)
        if bad:
            ax.scatter(*zip(*bad), s=18, marker="x", color=col, alpha=0.6)
        for r in b.rows:
            if (r["circuit"] == name and r["section"] == "pruning"
                    and r["variant"] == "pruned"):
                ax.scatter([r["seconds_per_case"]], [max(floor, r["error_fraction"])],
                           marker="^", s=70, color=col, edgecolor="k", zorder=5)
            if r["circuit"] == name and r["section"] == "levels":
                if r["level"] == "dynamic":
                    ax.scatter([r["seconds_per_case"]], [max(floor, r["error_fraction"])],
                               marker="*", s=220, color=col, edgecolor="k", zorder=5)
                elif r["level"] == "kinematic":
                    ax.scatter([r["seconds_per_case"]], [floor], marker="D", s=40, color=col,
                               edgecolor="k", zorder=5)
        if not good and not bad:
            ax.scatter([], [], color=col, label=name)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.axhline(0.01, color="grey", ls="--", lw=1)
    ax.text(0.01, 0.0108, "1 % of stroke", color="grey", fontsize=8,
            transform=ax.get_yaxis_transform())
    ax.set_xlabel("seconds per input change (kinematic: per state)")
    ax.set_ylabel("output position error vs closed form (fraction of stroke)")
    ax.set_title("mechc: speed against accuracy\n"
                 "dots: dynamic settings grid, x: solver broke, line: Pareto front,\n"
                 "star: defaults, triangle: pruned, diamond: kinematic (exact, drawn at 1e-6)",
                 fontsize=9)
    ax.legend(fontsize=8, loc="upper right")
    ax.grid(True, which="both", alpha=0.25)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def stability_chart(b: Bench, study: dict, path: Path) -> None:
    import matplotlib  # here, not at the top: ``mechc`` loads this module for every command

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axs = plt.subplots(2, 2, figsize=(11, 8.5))
    m = study["map"]
    ks = sorted({r["spring_factor"] for r in m})
    dts = sorted({r["dt_s"] for r in m})
    z = np.full((len(ks), len(dts)), np.nan)
    for r in m:
        z[ks.index(r["spring_factor"]), dts.index(r["dt_s"])] = max(1e-5, r["error_fraction"])
    ax = axs[0, 0]
    im = ax.imshow(np.log10(z), origin="lower", cmap="viridis", aspect="auto", vmin=-4, vmax=0)
    for r in m:
        i, j = ks.index(r["spring_factor"]), dts.index(r["dt_s"])
        mark = "ok" if r["passed"] else short_kinds(r["failure_kinds"])
        ax.text(j, i, mark.replace("/", "\n"), ha="center", va="center", fontsize=6,
                color="k" if np.log10(z[i, j]) > -1.2 else "w")
    ax.set_xticks(range(len(dts)), [f"{d * 1e3:g}" for d in dts])
    ax.set_yticks(range(len(ks)), [f"{k:g}" for k in ks])
    ax.set_xlabel("time step (ms)")
    ax.set_ylabel("spring rate factor (forces x k, damping x sqrt k)")
    ax.set_title("stability map: log10 output error; text = what mechc reported", fontsize=9)
    fig.colorbar(im, ax=ax, fraction=0.046)
    ax = axs[0, 1]
    its = study["iterations"]
    ax.loglog([r["iterations"] for r in its], [max(1e-5, r["max_violation_mm"]) for r in its],
              "o-", label="largest joint stretch (mm)")
    ax.loglog([r["iterations"] for r in its], [max(1e-5, r["error_fraction"]) for r in its],
              "s-", label="output error (fraction)")
    ax.axhline(0.1, color="r", ls="--", lw=1, label="stretch limit 0.1 mm")
    for r in its:
        if not r["passed"]:
            ax.annotate(short_kinds(r["failure_kinds"]), (r["iterations"], r["max_violation_mm"]),
                        fontsize=6, color="r")
    ax.set_xlabel("solver iterations per step")
    ax.set_title("too few iterations", fontsize=9)
    ax.legend(fontsize=7)
    ax = axs[1, 0]
    ms = study["mass"]
    ax.loglog([r["mass_factor"] for r in ms], [max(1e-5, r["error_fraction"]) for r in ms],
              "s-", label="output error (fraction)")
    ax.loglog([r["mass_factor"] for r in ms], [max(1e-5, r["max_violation_mm"]) for r in ms],
              "o-", label="largest joint stretch (mm)")
    for r in ms:
        if not r["passed"]:
            ax.annotate(short_kinds(r["failure_kinds"]), (r["mass_factor"],
                                                     max(1e-5, r["error_fraction"])),
                        fontsize=6, color="r")
    ax.set_xlabel("bar mass factor (against input sliders and levers)")
    ax.set_title("mass ratio", fontsize=9)
    ax.legend(fontsize=7)
    ax = axs[1, 1]
    tg = [r for r in b.rows if r["section"] == "toggle"]
    mg = [r["margin_deg"] for r in tg]
    er = [r["error_fraction"] for r in tg]
    sel = [(x, y) for x, y in zip(mg, er) if x and np.isfinite(y) and x > 0]
    if sel:
        ax.loglog(*zip(*sel), "o-")
    ax.axvline(MIN_SINGULAR_MARGIN_DEG, color="r", ls="--", lw=1)
    ax.text(MIN_SINGULAR_MARGIN_DEG, 0.5, " design check:\n reported below", color="r",
            fontsize=7, transform=ax.get_xaxis_transform())
    ax.set_xlabel("distance from toggle (deg, transmission angle)")
    ax.set_ylabel("closed-form angle error vs 50 digits (rad)")
    flagged = sum(1 for r in tg if r["failure_kinds"] == "flagged")
    ax.set_title(f"toggle: error grows as the margin closes; {flagged} states past it flagged",
                 fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)

