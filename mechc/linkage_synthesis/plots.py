"""Pictures for ``mechc synth … --plot FILE``: circles and chains, the 3-bar gate and its chart,
adder error maps.  matplotlib with the Agg backend (no display needed); files are written
atomically (temporary file in the same directory, then rename)."""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

import matplotlib

from mechc.linkage_synthesis.mk_circles import PIVOT_NAMES, pole
from mechc.linkage_synthesis.three_bar_gate import STATES, kinematics

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from mechc.errors import UsageError  # noqa: E402

COLOURS = {"M": "tab:red", "K": "tab:blue", "T": "tab:green"}


def save(fig, path: str) -> None:
    """Save a figure atomically; the format follows the file suffix (png, svg, pdf)."""
    p = Path(path)
    fmt = (p.suffix.lstrip(".") or "png").lower()
    if fmt not in ("png", "svg", "pdf"):
        raise UsageError(f"{path}: plot format '{fmt}' not supported (use .png, .svg or .pdf)")
    parent = p.parent if str(p.parent) else Path(".")
    if not parent.is_dir():
        raise UsageError(f"{path}: directory '{parent}' does not exist")
    fd, tmp = tempfile.mkstemp(prefix=f".{p.name}.", suffix=f".{fmt}", dir=parent)
    os.close(fd)
    try:
        fig.savefig(tmp, format=fmt, dpi=120, bbox_inches="tight")
        os.chmod(tmp, 0o644)
        os.replace(tmp, p)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise
    finally:
        plt.close(fig)


def _circle(ax, c, colour, ls="-", lw=1.0, label=None):
    t = np.linspace(0, 2 * np.pi, 361)
    z = c.centre + c.radius * np.exp(1j * t)
    ax.plot(z.real, z.imag, ls, color=colour, lw=lw, label=label)


def plot_chain(result, path: str, title: str = "") -> None:
    """Circles of every circle position, poles (dyads), and each solution chain in position 1."""
    fig, ax = plt.subplots(figsize=(7, 6))
    pr = result.problem
    ax.plot(pr.points.real, pr.points.imag, "kx", ms=8, label="precision points")
    for j, p in enumerate(pr.points):
        ax.annotate(f"PP{j + 1}", (p.real, p.imag), textcoords="offset points", xytext=(4, 4),
                    fontsize=8)
    seen = set()
    for pc in result.circles:
        for name, c in pc.circles.items():
            if c is None:
                continue
            lab = None if name in seen else f"{name} circles"
            seen.add(name)
            _circle(ax, c, COLOURS[name], "--", 0.8, lab)
    if pr.k == 2:
        for (a, b) in ((0, 1), (0, 2), (1, 2)):
            if b < pr.n:
                try:
                    q = pole(pr, a, b)
                except ValueError:
                    continue
                ax.plot(q.real, q.imag, "k^", ms=5)
                ax.annotate(f"P{a + 1}{b + 1}", (q.real, q.imag), textcoords="offset points",
                            xytext=(3, -9), fontsize=7)
    for i, s in enumerate(result.solutions):
        chain = s.pose(0)
        z = np.array(chain)
        ax.plot(z.real, z.imag, "-", color="k", lw=2, alpha=0.8,
                label="solution chains" if i == 0 else None)
        for name, p in zip(PIVOT_NAMES, chain[:-1]):
            ax.plot(p.real, p.imag, "o", color=COLOURS[name], ms=6)
    if result.family:
        g = np.array([s.ground for s in result.family])
        ax.plot(g.real, g.imag, ".", color=COLOURS["M"], ms=2, label="ground pivots (family)")
    ax.set_aspect("equal", adjustable="datalim")
    ax.grid(True, lw=0.3)
    ax.legend(fontsize=8, loc="best")
    ax.set_title(title or f"{'dyad' if pr.k == 2 else 'triad'}, {pr.n} positions: "
                 f"{result.mode}", fontsize=10)
    save(fig, path)


def plot_three_bar(answer, path: str, chart: list[dict] | None = None,
                   request: tuple[float, float] | None = None) -> None:
    """Left: the design in its four states.  Right: healthy output positions over separation
    (the chart to pick a healthy design from), with the request marked."""
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(12, 5))
    d = answer.design
    if d is not None:
        s = d.stroke
        for (name, (a, b)), col in zip(STATES.items(), ["k", "tab:blue", "tab:orange",
                                                        "tab:green"]):
            st = kinematics(d, a * s, b * s)
            m, o = complex(st.m), float(st.output)
            A, B = a * s + 1j * d.sep, b * s - 1j * d.sep
            for p, q in ((A, m), (B, m), (m, o)):
                ax.plot([p.real, q.real], [p.imag, q.imag], "-o", color=col, ms=3, lw=1.2,
                        label=name if p == A else None)
        ax.axhline(d.sep, color="0.7", lw=0.5)
        ax.axhline(-d.sep, color="0.7", lw=0.5)
        ax.axhline(0.0, color="0.7", lw=0.5)
        ax.set_aspect("equal", adjustable="datalim")
        ax.legend(fontsize=8)
        ax.set_title(f"{'healthy' if answer.healthy else 'NOT healthy'}: d_i = "
                     f"{d.input_link:.3f}, d_o = {d.output_link:.3f}, output at "
                     f"{d.output_position:.3f}", fontsize=9)
    if chart:
        for row in chart:
            for lo, hi in row["ranges"]:
                bx.plot([row["sep"], row["sep"]], sorted([lo, hi]), "-", color="tab:green",
                        lw=3, alpha=0.6)
        if request is not None and request[1] is not None:
            bx.plot([request[0]], [request[1]], "r*", ms=12, label="request")
            bx.legend(fontsize=8)
        bx.set_xlabel("sep (half the distance between input slides)")
        bx.set_ylabel("output position in FF")
        bx.set_title("healthy output positions (green) for this stroke", fontsize=9)
        bx.grid(True, lw=0.3)
    save(fig, path)


def plot_adder(x1, x2, error, path: str, title: str = "") -> None:
    """Contour map of the structural error over the two inputs."""
    fig, ax = plt.subplots(figsize=(6, 5))
    cs = ax.contourf(x1, x2, error, levels=20, cmap="RdBu_r")
    fig.colorbar(cs, ax=ax, label="structural error")
    ax.set_xlabel("X1")
    ax.set_ylabel("X2")
    ax.set_title(title or "long-bar adder structural error", fontsize=10)
    save(fig, path)
