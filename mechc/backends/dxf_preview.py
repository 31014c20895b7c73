"""A picture of DXF cut sheets (PNG, SVG or PDF by the file's suffix): the DXF itself drawn by
ezdxf's drawing add-on onto matplotlib, so the picture shows what a cutter will read, not a
second drawing of the parts."""

from __future__ import annotations

import io

import ezdxf
from ezdxf.addons.drawing import Frontend, RenderContext
from ezdxf.addons.drawing.config import BackgroundPolicy, Configuration
from ezdxf.addons.drawing.matplotlib import MatplotlibBackend
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure


def preview(dxf_text: str, fmt: str = "png", width_in: float = 12.0, dpi: int = 120) -> bytes:
    """The drawing of ``dxf_text`` as an image file's bytes (``fmt``: png, svg or pdf), white
    background, ``width_in`` inches wide, its height from the sheets' proportions."""
    doc = ezdxf.read(io.StringIO(dxf_text))
    msp = doc.modelspace()
    lo, hi = _extent(msp)
    aspect = (hi[1] - lo[1]) / max(hi[0] - lo[0], 1e-9)
    fig = Figure(figsize=(width_in, max(2.0, width_in * aspect)))  # no pyplot: no global state
    FigureCanvasAgg(fig)
    ax = fig.add_axes((0, 0, 1, 1))
    config = Configuration(background_policy=BackgroundPolicy.WHITE)
    Frontend(RenderContext(doc), MatplotlibBackend(ax), config=config).draw_layout(msp)
    out = io.BytesIO()
    fig.savefig(out, format=fmt, dpi=dpi, facecolor="white")
    return out.getvalue()


def _extent(msp) -> tuple[tuple[float, float], tuple[float, float]]:
    """The bounding box of the sheet frames (the whole drawing where there are none)."""
    from ezdxf import bbox  # the bounding-box module is needed here only

    box = bbox.extents(msp.query('LWPOLYLINE[layer=="sheets"]') or msp)
    return (box.extmin.x, box.extmin.y), (box.extmax.x, box.extmax.y)
