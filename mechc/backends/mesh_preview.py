"""A picture of the 3D assembly (PNG): every part's triangles drawn by matplotlib's 3D axes at
true proportions, coloured by plane, seen from above at a slant, lower planes drawn first
(within a plane matplotlib sorts faces by depth only roughly; a glTF viewer shows it right)."""

from __future__ import annotations

import io

import mpl_toolkits.mplot3d  # noqa: F401  (registers the "3d" projection)
import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.image import imsave
from mpl_toolkits.mplot3d.art3d import Poly3DCollection

from mechc.backends.mesh import COLOURS, Assembly


def preview(asm: Assembly, width_in: float = 14.0, dpi: int = 110, elev: float = 40.0,
            azim: float = -75.0) -> bytes:
    """The assembly drawn as PNG bytes, cropped to what it covers."""
    lo, hi = asm.bounds
    span = hi - lo
    fig = Figure(figsize=(width_in, width_in), dpi=dpi)  # no pyplot: no global state
    canvas = FigureCanvasAgg(fig)
    ax = fig.add_axes((0, 0, 1, 1), projection="3d")
    # seen from above: lower planes first, each drawn over by the planes above it (matplotlib's
    # own depth order put the frame's base plate, one large part, over everything)
    ax.computed_zorder = False
    for piece, m in sorted(asm.parts, key=lambda pm: pm[0].plane):
        colour = np.array(COLOURS[piece.plane % len(COLOURS)]) / 255.0
        ax.add_collection3d(Poly3DCollection(m.triangles, facecolors=colour,
                                             edgecolors=colour * 0.6, linewidths=0.1,
                                             zorder=piece.plane))
    ax.set_xlim(lo[0], hi[0])
    ax.set_ylim(lo[1], hi[1])
    ax.set_zlim(lo[2], hi[2])
    ax.set_box_aspect((span[0], span[1], span[2]), zoom=0.9)  # true proportions
    ax.view_init(elev=elev, azim=azim)
    ax.set_axis_off()
    canvas.draw()
    img = np.asarray(canvas.buffer_rgba())[..., :3]
    # the 3D axes are square and mostly empty: keep what the assembly covers, and a margin
    ink = np.argwhere(img.min(axis=2) < 250)
    (y0, x0), (y1, x1) = ink.min(axis=0), ink.max(axis=0)
    pad = 10
    img = img[max(0, y0 - pad):y1 + pad + 1, max(0, x0 - pad):x1 + pad + 1]
    out = io.BytesIO()
    imsave(out, img, format="png")
    return out.getvalue()
