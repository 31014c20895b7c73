"""Specs read back from a design JSON: the ``spec`` object :meth:`Spec.to_json` and
:meth:`SeqSpec.to_json` write, parsed with the same expression grammar as the front ends."""

from __future__ import annotations

from mechc.frontends.blif import parse_blif
from mechc.frontends.boolfile import parse_expression_text
from mechc.frontends.fsm import parse_expression
from mechc.ir.seqspec import FlowTable, MemorySpec, SeqSpec
from mechc.ir.spec import OutputSpec, Spec
from mechc.logic.cubes import DC, Cube


def spec_from_json(d: dict, where: str = "<json>") -> Spec:
    """The ``spec`` a design JSON embeds (expressions as ``.bool`` text, cubes as strings,
    or a wide spec's network as BLIF text)."""
    if "network" in d:  # a spec too wide for a table is valued by its network
        spec = parse_blif(d["network"], f"{where}: spec.network")
        if spec.inputs != list(d["inputs"]) or spec.outputs != list(d["outputs"]):
            raise ValueError("spec.network's inputs or outputs differ from the spec's")
        spec.path, spec.kind = d.get("source", where), d.get("kind", "pla")
        return spec
    inputs = list(d["inputs"])
    funcs = {}
    for name in d["outputs"]:
        fd = d["functions"][name]
        f = OutputSpec(name)
        if "expr" in fd:
            f.expr = parse_expression_text(fd["expr"], inputs, f"{where}: spec.{name}")
        else:
            f.on = [Cube.from_string(s) for s in fd.get("on", [])]
        f.off = [Cube.from_string(s) for s in fd.get("off", [])]
        f.dc = [Cube.from_string(s) for s in fd.get("dc", [])]
        rest = fd.get("rest", 0)
        f.rest = DC if rest == "dc" else int(rest)
        funcs[name] = f
    return Spec(d.get("source", where), d.get("kind", "bool"), inputs, list(d["outputs"]),
                funcs)


def seqspec_from_json(d: dict, where: str = "<json>") -> SeqSpec:
    """The sequential spec a design JSON embeds (a flow table, or set/reset equations)."""
    inputs, outputs = list(d["inputs"]), list(d["outputs"])
    if "table" in d:
        return SeqSpec(d.get("source", where), inputs, outputs,
                       table=FlowTable.from_json(d["table"], inputs, outputs))
    names = inputs + [m["name"] for m in d.get("memories", [])]
    mems = [MemorySpec(m["name"], parse_expression(m["set"], names, where),
                       parse_expression(m["reset"], names, where), int(m["initial"]))
            for m in d.get("memories", [])]
    eqs = {o: parse_expression(f["expr"], names, where)
           for o, f in d.get("functions", {}).items()}
    start = d.get("start") or ""
    return SeqSpec(d.get("source", where), inputs, outputs, mems, eqs,
                   start_inputs=int(start, 2) if start else 0)
