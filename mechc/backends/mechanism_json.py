"""Mechanism <-> JSON (the ``geometry`` of each cell and the top-level ``mechanism``)."""

from __future__ import annotations

from dataclasses import asdict, fields

from mechc.ir.check import Check
from mechc.ir.mechanism import Mechanism, Part, SynthContext


def mechanism_json(m: Mechanism) -> dict:
    return {
        "stroke_mm": m.ctx.stroke,
        "rules": {k: v for k, v in asdict(m.ctx).items()},
        "order": list(m.order),
        "inputs": {k: p.to_json() for k, p in m.inputs.items()},
        "actuators": m.actuators,
        "nets": {k: p.to_json() for k, p in sorted(m.nets.items())},
        "outputs": {k: {"owner": o, "pin": p} for k, (o, p) in m.outputs.items()},
        "checks": [c.to_json() for c in m.checks],
    }


def mechanism_from_json(d: dict, cells: list[dict]) -> Mechanism:
    names = {f.name for f in fields(SynthContext)}
    ctx = SynthContext(**{k: v for k, v in d.get("rules", {}).items() if k in names})
    cell_parts = {c["id"]: Part.from_json(c["geometry"]) for c in cells if "geometry" in c}
    checks = [Check(c["name"], c["where"], float(c["value"]), float(c["limit"]), c["sense"],
                    c.get("unit", "")) for c in d.get("checks", [])]
    return Mechanism(ctx, cell_parts,
                     {k: Part.from_json(p) for k, p in d["inputs"].items()},
                     {k: Part.from_json(p) for k, p in d["nets"].items()},
                     {k: (v["owner"], v["pin"]) for k, v in d["outputs"].items()},
                     dict(d.get("actuators", {})), list(d["order"]), checks)
