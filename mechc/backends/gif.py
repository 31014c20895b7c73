"""``mechc view --gif``: the viewer's tour as an animated GIF, drawn without a browser.

matplotlib draws the same outlines as the page (``animation.py``'s poses, the page's colours),
one frame per 1/fps s of slowed-down time along each change and one long frame per rest state;
pillow writes the GIF with one palette for every frame, so frames that differ little store
little.
"""

from __future__ import annotations

import math
import os
import tempfile
from collections.abc import Callable
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # no display: files only
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.collections import PolyCollection  # noqa: E402
from matplotlib.patches import Rectangle  # noqa: E402
from PIL import Image  # noqa: E402

from mechc.backends.animation import Animation, Segment  # noqa: E402
from mechc.errors import UsageError  # noqa: E402

# (fill, edge) per body class, as viewer.css
COLOURS = {"in": ("#9ecae1", "#08519c"), "L0": ("#d9d9d9", "#525252"),
           "L1": ("#a1d99b", "#238b45"), "L2": ("#fdae6b", "#d94801"),
           "L3": ("#dadaeb", "#54278f"), "L4": ("#fcbba1", "#a50f15"),
           "net": ("#bcbddc", "#6a51a3"), "out": ("#d9d9d9", "#252525"),
           "out_on": ("#74c476", "#006d2c")}
HOLD_MS = 700  # each rest state stays this long


def body_class(anim: Animation, b: dict) -> str:
    outs = {t["body"] for t in anim.terminals["outputs"].values()}
    own = b["owner"]
    if own.startswith("in:"):
        return "in"
    if own.startswith("net:"):
        return "net"
    return "out" if b["id"] in outs else f"L{min(int(b['layer']), 4)}"


def frames_of(anim: Animation, fps: int, slow: float) -> list[tuple[Segment, float, int]]:
    """(segment, seconds into it, display ms) of every frame of the tour."""
    out = []
    for seg in anim.tour:
        if seg.hold:
            out.append((seg, 0.0, HOLD_MS))
            continue
        dur = seg.duration(anim.cases)
        n = max(2, math.ceil(dur * slow * fps))
        out += [(seg, dur * k / n, round(1000 / fps)) for k in range(1, n + 1)]
    return out


def write(anim: Animation, path: str | Path, width: int = 720, fps: int = 12,
          slow: float = 10.0,
          progress: Callable[[int, int], None] | None = None) -> tuple[int, int]:
    """Render the tour to ``path`` (atomically); returns (frames, bytes). ``progress`` is
    told (frames drawn, frames) as the frames are drawn."""
    if not anim.tour:
        raise UsageError("nothing to animate: the trace has no tour")
    pts = np.array([p for b in anim.bodies for poly in b["outline"] for p in poly])
    (x0, y0), (x1, y1) = pts.min(axis=0), pts.max(axis=0)
    s = anim.stroke
    # room for the labels (px, as drawn) and for the strokes the parts move (mm)
    label_px = 12 * max(len(n) + 4 for n in anim.inputs + anim.outputs)
    k = (width - 2 * label_px) / (x1 - x0 + 2 * s)  # px per mm
    x0, x1 = x0 - s - label_px / k, x1 + s + label_px / k
    y0, y1 = y0 - 0.8 * s, y1 + 0.8 * s + 16 / k
    dpi = 100
    height = max(120, int(round(width * (y1 - y0) / (x1 - x0))) + 30)
    fig = plt.figure(figsize=(width / dpi, height / dpi), dpi=dpi)
    ax = fig.add_axes((0, 0, 1, (height - 30) / height))
    ax.set_xlim(x0, x1)
    ax.set_ylim(y0, y1)
    ax.set_aspect("equal", adjustable="box")
    ax.axis("off")
    fs = 11 * 72 / dpi  # 11 px
    for c in anim.cells:
        bx0, by0, bx1, by1 = c["box"]
        ax.add_patch(Rectangle((bx0 - 2, by0 - 2), bx1 - bx0 + 4, by1 - by0 + 4,
                               facecolor="#f7f7f7", edgecolor="#bdbdbd", lw=0.6, ls="--"))
        ax.text(bx0 - 2, by1 + 3, f"{c['id']} {c['type']}", fontsize=0.8 * fs,
                color="#525252")
    classes = [body_class(anim, b) for b in anim.bodies]
    order = sorted(range(len(anim.bodies)), key=lambda i: anim.bodies[i]["layer"])
    coll = PolyCollection([], closed=True, linewidths=0.7)
    ax.add_collection(coll)
    row = {b["id"]: i for i, b in enumerate(anim.bodies)}
    in_txt = {n: ax.text(0, 0, "", ha="right", va="center", fontsize=1.2 * fs,
                         fontweight="bold", color=COLOURS["in"][1]) for n in anim.inputs}
    out_txt = {n: ax.text(0, 0, "", ha="left", va="center", fontsize=1.2 * fs,
                          fontweight="bold") for n in anim.outputs}
    title = fig.text(0.01, 1 - 20 / height, "", fontsize=1.1 * fs, fontweight="bold",
                     color="#252525")
    images, durations = [], []
    palette = None
    plan = frames_of(anim, max(1, fps), slow)
    for seg, tau, ms in plan:
        if progress is not None:
            progress(len(images), len(plan))
        pose = anim.pose_at(seg, tau)
        world = anim.world(pose)
        outs = anim.signals(pose)
        ins = anim.signals(pose, "inputs")
        verts, faces, edges = [], [], []
        on_bodies = {anim.terminals["outputs"][o]["body"] for o, v in outs.items() if v > 0.5}
        for i in order:
            cls = classes[i]
            if cls == "out" and anim.bodies[i]["id"] in on_bodies:
                cls = "out_on"
            for poly in world[i]:
                verts.append(poly)
                faces.append(COLOURS[cls][0])
                edges.append(COLOURS[cls][1])
        coll.set_verts(verts)
        coll.set_facecolors(faces)
        coll.set_edgecolors(edges)
        for n, t in anim.terminals["inputs"].items():
            i = row[t["body"]]
            xs = np.concatenate([p[:, 0] for p in world[i]])
            in_txt[n].set_position((xs.min() - 0.2 * s, t["off"][1]))
            in_txt[n].set_text(f"{n} = {int(ins[n] > 0.5)}")
        for n, t in anim.terminals["outputs"].items():
            px, py = anim.point_at(pose, t["body"], t["point"])
            on = outs[n] > 0.5
            out_txt[n].set_position((px + 0.6 * s, py))
            out_txt[n].set_text(f"{n} = {int(on)}")
            out_txt[n].set_color(COLOURS["out_on"][1] if on else "#252525")
        title.set_text(f"{anim.title}   " + " ".join(f"{n}={int(ins[n] > 0.5)}"
                                                     for n in anim.inputs)
                       + "  ->  " + " ".join(f"{n}={int(outs[n] > 0.5)}" for n in anim.outputs)
                       + f"   ({anim.level} poses, mechc view)")
        fig.canvas.draw()
        rgb = Image.frombuffer("RGBA", fig.canvas.get_width_height(),
                               fig.canvas.buffer_rgba()).convert("RGB")
        if palette is None:  # one palette for every frame: unchanged pixels stay unchanged
            palette = _palette(rgb)
        images.append(rgb.quantize(palette=palette, dither=Image.Dither.NONE))
        durations.append(ms)
    plt.close(fig)
    p = Path(path)
    fd, tmp = tempfile.mkstemp(prefix=f".{p.name}.", suffix=".gif", dir=p.parent or ".")
    os.close(fd)
    try:
        images[0].save(tmp, save_all=True, append_images=images[1:], duration=durations,
                       loop=0, optimize=True, disposal=1)
        mask = os.umask(0)  # mkstemp makes the file private: give it a plain file's mode
        os.umask(mask)
        os.chmod(tmp, 0o666 & ~mask)
        os.replace(tmp, p)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)
    return len(images), p.stat().st_size



def _palette(first: Image.Image) -> Image.Image:
    """A 64-colour palette from the first frame and a swatch of every colour a later frame
    may show first (an output turning green, say)."""
    swatch = [c for pair in COLOURS.values() for c in pair]
    w, h = first.size
    strip = Image.new("RGB", (w, 8 * len(swatch)), "white")
    for k, c in enumerate(swatch):
        strip.paste(c, (0, 8 * k, w, 8 * k + 8))
    both = Image.new("RGB", (w, h + strip.size[1]))
    both.paste(first, (0, 0))
    both.paste(strip, (0, h))
    return both.quantize(colors=64, method=Image.Quantize.MEDIANCUT)
