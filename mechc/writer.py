"""The output writer: Design <-> JSON (validated against the shipped schema), atomic file writes."""

from __future__ import annotations

import json
import os
import tempfile
from functools import lru_cache
from importlib import resources
from pathlib import Path

from mechc import FORMAT_VERSION, __version__
from mechc.errors import SpecError, UsageError
from mechc.layout import Layout, Place
from mechc.netlist.ir import Netlist
from mechc.pipeline import Design
from mechc.spec.model import Spec


def design_to_json(d: Design, timings: bool = False) -> dict:
    nl = d.netlist
    places = d.layout.cells if d.layout else {}
    cells = []
    mech = d.mechanism
    for c in nl.topo_cells():
        j = c.to_json()
        if c.id in places:
            j["place"] = places[c.id].to_json()
        if mech is not None and c.id in mech.cells:
            j["geometry"] = mech.cells[c.id].to_json()
        cells.append(j)
    nets = [{"id": k, **v} for k, v in sorted(nl.nets().items(), key=lambda kv: _net_key(kv[0]))]
    stats = dict(d.stats)
    if timings:
        stats["seconds"] = {k: round(v, 6) for k, v in d.seconds.items()}
    out = {
        "format": "mechc",
        "version": FORMAT_VERSION,
        "generator": f"mechc {__version__}",
        "inputs": list(nl.inputs),
        "outputs": dict(nl.outputs),
        "spec": d.spec.to_json(),
        "equations": dict(d.equations),
        "implemented": dict(d.implemented),
        "cells": cells,
        "nets": nets,
        "layout": d.layout.to_json() if d.layout else None,
        "stats": stats,
    }
    if mech is not None:
        from mechc.mech.io import mechanism_json

        out["mechanism"] = mechanism_json(mech)
    if getattr(d, "sequential", None) is not None:
        out["sequential"] = d.sequential.to_json()
    return out


def _net_key(name: str):
    if name.startswith("n") and name[1:].isdigit():
        return (1, int(name[1:]), name)
    return (0, 0, name)


def dumps(obj: dict) -> str:
    return json.dumps(obj, indent=2, ensure_ascii=False) + "\n"


def write_atomic(path: str | Path, text: str) -> None:
    """Write via a temporary file in the same directory and rename: a failure leaves any
    existing file untouched."""
    p = Path(path)
    if p.is_dir():
        raise UsageError(f"{p}: is a directory, expected an output file name")
    if p.exists() and not p.is_file():  # a device or pipe (/dev/stdout, /dev/null): no rename
        with open(p, "w", encoding="utf-8") as f:
            f.write(text)
        return
    parent = p.parent if str(p.parent) else Path(".")
    if not parent.is_dir():
        raise UsageError(f"{p}: directory '{parent}' does not exist")
    fd, tmp = tempfile.mkstemp(prefix=f".{p.name}.", suffix=".tmp", dir=parent)
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            f.write(text)
            f.flush()
            os.fsync(f.fileno())
        if p.exists():
            os.chmod(tmp, p.stat().st_mode & 0o777)
        else:
            os.chmod(tmp, 0o644)
        os.replace(tmp, p)
    except BaseException:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        raise


@lru_cache(maxsize=1)
def schema() -> dict:
    return json.loads(resources.files("mechc").joinpath("schema/mechc.schema.json").read_text())


def validate(obj: dict, where: str) -> None:
    import jsonschema

    v = jsonschema.Draft202012Validator(schema())
    errors = sorted(v.iter_errors(obj), key=lambda e: list(e.absolute_path))
    if errors:
        e = errors[0]
        loc = "/".join(str(p) for p in e.absolute_path) or "(top level)"
        raise UsageError(f"{where}: not a valid mechc design at {loc}: {e.message}")


def load_design_json(path: str | Path) -> dict:
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise UsageError(f"{p}: file not found") from None
    except (OSError, UnicodeDecodeError) as e:
        raise UsageError(f"{p}: cannot read design: {e}") from None
    try:
        obj = json.loads(text)
    except json.JSONDecodeError as e:
        raise SpecError(str(p), e.lineno, e.colno, f"invalid JSON: {e.msg}") from None
    if not isinstance(obj, dict) or obj.get("format") != "mechc":
        raise UsageError(f"{p}: not a mechc design (expected \"format\": \"mechc\")")
    if obj.get("version") != FORMAT_VERSION:
        raise UsageError(f"{p}: design format version {obj.get('version')} is not supported "
                         f"(this mechc reads version {FORMAT_VERSION}); recompile the spec")
    validate(obj, str(p))
    return obj


def design_from_json(obj: dict, where: str = "<json>") -> Design:
    if obj["spec"].get("kind") == "fsm":
        from mechc.spec.sequential import SeqSpec, SequentialError

        try:
            spec = SeqSpec.from_json(obj["spec"], where)
        except (KeyError, ValueError, SequentialError) as e:
            raise UsageError(f"{where}: inconsistent sequential spec: {e}") from None
    else:
        spec = Spec.from_json(obj["spec"], where)
    try:
        nl = Netlist.from_json(obj["inputs"], obj["outputs"], obj["cells"])
    except ValueError as e:
        raise UsageError(f"{where}: inconsistent netlist: {e}") from None
    layout = None
    if obj.get("layout"):
        cells = {c["id"]: Place(**c["place"]) for c in obj["cells"] if "place" in c}
        lj = obj["layout"]
        layout = Layout(cells, {k: Place(**v) for k, v in lj.get("inputs", {}).items()},
                        tuple(lj.get("pitch_mm", (0, 0))), lj.get("crossings", 0))
    mech = None
    if obj.get("mechanism"):
        from mechc.mech.io import mechanism_from_json

        try:
            mech = mechanism_from_json(obj["mechanism"], obj["cells"])
        except (KeyError, TypeError, ValueError) as e:
            raise UsageError(f"{where}: inconsistent mechanism geometry: {e}") from None
    return Design(spec, obj.get("equations", {}), obj.get("implemented", {}), nl, layout,
                  obj.get("stats", {}), mechanism=mech)
