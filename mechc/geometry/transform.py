"""Moving a part's geometry (cells are built at a local origin, then placed)."""

from __future__ import annotations

from dataclasses import replace

from mechc.ir.mechanism import Part, Point


def _t(p: Point | None, dx: float, dy: float) -> Point | None:
    return None if p is None else (p[0] + dx, p[1] + dy)


def translate(part: Part, dx: float, dy: float) -> Part:
    bodies = [replace(b, outline=[[_t(p, dx, dy) for p in poly] for poly in b.outline],
                      pivot=_t(b.pivot, dx, dy)) for b in part.bodies]
    joints = [replace(j, p0=_t(j.p0, dx, dy), p1=_t(j.p1, dx, dy), q=_t(j.q, dx, dy),
                      pa=_t(j.pa, dx, dy), pb=_t(j.pb, dx, dy),
                      profile=[_t(p, dx, dy) for p in j.profile] if j.profile else j.profile)
              for j in part.joints]
    springs = [replace(s, pa=_t(s.pa, dx, dy), pb=_t(s.pb, dx, dy)) for s in part.springs]
    terms = {k: replace(t, off=_t(t.off, dx, dy), on=_t(t.on, dx, dy), at=_t(t.at, dx, dy))
             for k, t in part.terminals.items()}
    return Part(bodies, joints, springs, terms, dict(part.data))


def bounds(part: Part) -> tuple[float, float, float, float]:
    """(xmin, ymin, xmax, ymax) of every point of the part."""
    pts: list[Point] = []
    for b in part.bodies:
        for poly in b.outline:
            pts.extend(poly)
        if b.pivot:
            pts.append(b.pivot)
    for j in part.joints:
        pts.extend(p for p in (j.p0, j.p1, j.q, j.pa, j.pb) if p is not None)
        pts.extend(j.profile or ())
    for s in part.springs:
        pts.extend((s.pa, s.pb))
    for t in part.terminals.values():
        pts.extend((t.off, t.on))
    xs = [p[0] for p in pts]
    ys = [p[1] for p in pts]
    return min(xs), min(ys), max(xs), max(ys)
