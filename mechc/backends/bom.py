"""The bill of materials: every part to cut or buy, as CSV (one row per kind of identical part,
with its count and the names of the parts it covers).

Rows by ``category``:

- ``plate``: a piece cut from plate (mechc/backends/fabrication.py), identical pieces of one
  plane on one row; its plane, material, length x width x thickness and number of holes;
- ``link``: the bar of a rod joint, with the same figures (its plane: the parts list's);
- ``frame``: the ground's plates (mechc/backends/frame.py): the base plate, with its holes and
  slots, and the stop blocks; ``screw``: what fixes them (the base plate's mounting screws, a
  screw per stop block);
- ``spring``: music-wire springs as designed (mechc/cells/springs.py): rate, preload, largest
  force, free length, wire and mean coil diameter, active coils, extension or compression;
- ``pin``: steel dowel pins by diameter and the plates they pass (grip = plates x thickness;
  a pin to the frame also needs the frame's depth);
- ``roller``: the rollers of cam and friction contacts, by diameter;
- ``actuator``: one per input: rated force, the force it must give either way, stroke;
- ``motor``: powered rollers (rotor bodies): speed.
"""

from __future__ import annotations

import csv
import io
import math
from collections.abc import Callable, Hashable, Iterable

from mechc.backends.fabrication import ROD_LINK, Fabrication, Piece

COLUMNS = ("category", "item", "count", "plane", "material", "length_mm", "width_mm",
           "thickness_mm", "holes", "diameter_mm", "grip_mm", "rate_N_per_mm", "preload_N",
           "max_force_N", "free_length_mm", "wire_mm", "mean_diameter_mm", "active_coils",
           "spring_kind", "force_N", "required_on_N", "required_off_N", "stroke_mm",
           "speed_rpm", "notes", "ids")


def _r(v: float, nd: int = 3) -> float:
    return round(float(v), nd)


def _shape_key(p: Piece) -> tuple:
    """The piece's outline and holes moved to its lower left corner, to 0.01 mm: equal keys
    are the same part."""
    x0, y0 = p.outline.bounds[:2]
    ring = tuple((round(x - x0, 2), round(y - y0, 2)) for x, y in p.outline.exterior.coords)
    holes = tuple(sorted((round(h.centre[0] - x0, 2), round(h.centre[1] - y0, 2),
                          round(h.diameter, 3)) for h in p.holes))
    return ring, holes


def _grouped(items: Iterable, key: Callable[[object], Hashable]) -> list[list]:
    groups: dict[Hashable, list] = {}
    for it in items:
        groups.setdefault(key(it), []).append(it)
    return list(groups.values())


def bom_rows(fab: Fabrication) -> list[dict]:
    """The rows of the bill of materials (dicts over ``COLUMNS``)."""
    rows: list[dict] = []
    plates = sorted(fab.pieces, key=lambda p: (p.plane is None, p.plane or 0, p.id))
    for group in _grouped(plates, lambda p: (p.plane, p.kind, _shape_key(p))):
        p = group[0]
        length, width = p.size()
        rows.append({
            "category": ("link" if p.role == ROD_LINK else "frame" if p.kind == "frame"
                         else "plate"),
            "item": p.role or p.kind, "count": len(group),
            "plane": "" if p.plane is None else p.plane, "material": fab.material,
            "length_mm": _r(length, 2), "width_mm": _r(width, 2), "thickness_mm": fab.thickness,
            "holes": len(p.holes),
            "notes": f"{p.kind}; outline area {p.outline.area:.1f} mm2",
            "ids": " ".join(q.id for q in group)})
    if fab.frame is not None:
        feats = fab.frame.features
        for kind, item, size in (("mount", "screw M4 (frame to the bench)", "M4"),
                                 ("stop", "screw M3 (stop block to the base plate)", "M3")):
            ids = [f.ref for f in feats if f.kind == kind]
            if ids:
                rows.append({"category": "screw", "item": item, "count": len(ids),
                             "diameter_mm": size[1:], "notes": "length: the plates it passes "
                             "and the bench's or spacer's depth", "ids": " ".join(ids)})

    def spring_key(s):
        c = s.coil
        return (round(s.rate, 6), round(s.preload, 4), round(s.max_force or 0.0, 4),
                round(s.rest, 3), None if c is None else (c.wire, c.mean_diameter,
                                                          round(c.active_coils, 3),
                                                          round(c.free_length, 3), c.kind))
    for group in _grouped(fab.springs, spring_key):
        s = group[0]
        c = s.coil
        row = {"category": "spring", "item": f"{c.kind if c else 'helical'} spring",
               "count": len(group), "material": "music wire ASTM A228",
               "rate_N_per_mm": _r(s.rate, 6), "preload_N": _r(s.preload, 4),
               "max_force_N": "" if s.max_force is None else _r(s.max_force, 4),
               "notes": f"installed length at rest {s.rest:g} mm",
               "ids": " ".join(x.id for x in group)}
        if c is not None:
            row.update({"free_length_mm": _r(c.free_length), "wire_mm": c.wire,
                        "mean_diameter_mm": _r(c.mean_diameter), "diameter_mm":
                        _r(c.mean_diameter + c.wire), "active_coils": _r(c.active_coils),
                        "spring_kind": c.kind})
        rows.append(row)

    def pin_key(p):
        return (p.diameter, p.plates, p.to_ground, p.unholed > 0)

    for group in _grouped(sorted(fab.pins, key=lambda p: p.joint), pin_key):
        d, plates, ground, unholed = pin_key(group[0])
        notes = ["fixed pivot: add the frame's depth to the grip"] if ground else []
        if unholed:
            notes.insert(0, "a part it joins has no hole for it (the pin's centre lies on or "
                         "past that part's edge): check the design before cutting")
        rows.append({"category": "pin", "item": f"dowel pin {d:g} mm", "count": len(group),
                     "material": fab.pin_material, "diameter_mm": d,
                     "grip_mm": _r(plates * fab.thickness, 2) if plates else "",
                     "notes": "; ".join(notes), "ids": " ".join(x.joint for x in group)})
    for group in _grouped(fab.rollers, lambda r: round(r[1], 3)):
        rows.append({"category": "roller", "item": f"roller {group[0][1]:g} mm",
                     "count": len(group), "diameter_mm": _r(group[0][1]),
                     "ids": " ".join(j for j, _ in group)})
    for name, a in sorted(fab.actuators.items()):
        rows.append({"category": "actuator", "item": f"linear actuator for input {name}",
                     "count": 1, "force_N": a.get("rated_force_N", ""),
                     "required_on_N": a.get("required_right_N", ""),
                     "required_off_N": a.get("required_left_N", ""), "stroke_mm": fab.stroke,
                     "notes": "rated force; required: what the mechanism needs towards on "
                     "and off", "ids": f"in:{name}"})
    for b in fab.motors:
        rpm = "" if b.speed is None else _r(abs(b.speed) * 60 / (2 * math.pi), 2)
        rows.append({"category": "motor", "item": "motor driving a powered roller", "count": 1,
                     "speed_rpm": rpm, "notes": "counter-clockwise" if (b.speed or 0) >= 0
                     else "clockwise", "ids": b.id})
    return rows


def write_bom(fab: Fabrication) -> str:
    """The bill of materials as CSV text (header row, then :func:`bom_rows`)."""
    out = io.StringIO()
    w = csv.DictWriter(out, COLUMNS, restval="", lineterminator="\n")
    w.writeheader()
    w.writerows(bom_rows(fab))
    return out.getvalue()
