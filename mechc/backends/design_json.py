"""The design JSON back end: Design <-> JSON (validated against the shipped schema; the
mechanism geometry of every cell and the top-level ``mechanism``), written atomically.

A design file is plain JSON in a compact layout: the top-level keys and the records of the big
lists and maps (cells, nets, the mechanism's parts) one per line, each record without
whitespace. A 10-input random spec's design is about 2.6 times smaller that way than indented,
and still diffs line by line (benchmarks/design_file.py). Reading validates against the schema
with jsonschema-rs, and only on a failure with the pure-Python jsonschema, whose error path and
message the user sees: the same verdict and message as before, a hundred times faster on a
large design. Any valid JSON layout loads, indented files of earlier versions included, and a
design written as ``NAME.json.gz`` is the same text gzip-compressed (9 times smaller again).
"""

from __future__ import annotations

import gzip
import json
import math
import os
import tempfile
import zlib
from dataclasses import asdict, fields
from functools import lru_cache
from importlib import resources
from pathlib import Path

import jsonschema
import jsonschema_rs

from mechc import FORMAT_VERSION, __version__
from mechc.errors import SpecError, UsageError, read_input
from mechc.frontends.spec_json import seqspec_from_json, spec_from_json
from mechc.ir.check import Check
from mechc.ir.design import Design
from mechc.ir.layout import Layout, Place
from mechc.ir.mechanism import GROUND, Mechanism, Part, SynthContext
from mechc.ir.netlist import Netlist
from mechc.ir.seqspec import SequentialError


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
        out["mechanism"] = mechanism_json(mech)
    if getattr(d, "sequential", None) is not None:
        out["sequential"] = d.sequential.to_json()
    # where each library cell came from (mechc/cells/sources.py): simulate reloads user cells
    if d.cell_sources:
        out["cell_sources"] = {k: dict(v) for k, v in sorted(d.cell_sources.items())}
    return out


def _net_key(name: str):
    if name.startswith("n") and name[1:].isascii() and name[1:].isdigit():
        return (1, int(name[1:]), name)
    return (0, 0, name)


#: The first bytes of a gzip file: a design may be written compressed (``-o NAME.json.gz``).
GZIP_MAGIC = b"\x1f\x8b"


def design_bytes(text: str, path: str | Path) -> str | bytes:
    """What a design file at ``path`` holds: the JSON text, or for a name ending in ``.gz``
    that text gzip-compressed (with no time stamp, so the bytes stay reproducible)."""
    if str(path).lower().endswith(".gz"):
        return gzip.compress(text.encode("utf-8"), mtime=0)
    return text


def dumps(obj: dict) -> str:
    """Indented JSON: small documents a person reads (proof reports)."""
    return json.dumps(obj, indent=2, ensure_ascii=False) + "\n"


#: A container below the top level is written on one line unless its one-line text is longer
#: (a short one, such as the list of inputs, also directly under the top level).
ONE_LINE_MAX = 100_000
SHORT = 120


def dumps_design(obj: dict) -> str:
    """A design in the compact layout: the top level and its lists and maps one entry per
    line, short ones and anything deeper on one line without spaces unless it is over
    ONE_LINE_MAX characters (the mechanism's rods, say), which is then broken the same way.
    Deterministic: two runs on one spec give the same bytes."""
    out: list[str] = []
    _write(obj, 0, out)
    return "".join(out) + "\n"


def _compact(o) -> str:
    return json.dumps(o, ensure_ascii=False, separators=(",", ":"))


def _write(o, depth: int, out: list[str]) -> None:
    if isinstance(o, (dict, list)) and o:
        if depth >= 1:
            text = _compact(o)
            if len(text) <= (ONE_LINE_MAX if depth >= 2 else SHORT):
                out.append(text)
                return
        is_dict = isinstance(o, dict)
        out.append("{\n" if is_dict else "[\n")
        items = list(o.items()) if is_dict else list(enumerate(o))
        pad = "  " * (depth + 1)
        for n, (k, v) in enumerate(items):
            out.append(pad + _compact(k) + ": " if is_dict else pad)
            _write(v, depth + 1, out)
            out.append(",\n" if n + 1 < len(items) else "\n")
        out.append("  " * depth + ("}" if is_dict else "]"))
    else:
        out.append(_compact(o))


def check_writable(path: str | Path) -> None:
    """Why ``path`` cannot take an output file, as a UsageError (checked before the work that
    produces the output, so a long run does not end in a write that was never possible)."""
    p = Path(path)
    if p.is_dir():
        raise UsageError(f"{p}: is a directory, expected an output file name")
    parent = p.parent if str(p.parent) else Path(".")
    if not parent.is_dir():
        raise UsageError(f"{p}: directory '{parent}' does not exist")


def write_atomic(path: str | Path, text: str | bytes) -> None:
    """Write via a temporary file in the same directory and rename: a failure leaves any
    existing file untouched. ``text``: UTF-8 text, or bytes (a binary format) as they are."""
    p = Path(path)
    check_writable(p)
    data = text.encode("utf-8") if isinstance(text, str) else text
    if p.exists() and not p.is_file():  # a device or pipe (/dev/stdout, /dev/null): no rename
        try:
            with open(p, "wb") as f:
                f.write(data)
        except OSError as e:
            raise UsageError(f"{p}: cannot write: {e.strerror or e}") from None
        return
    tmp = None
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{p.name}.", suffix=".tmp", dir=p.parent)
        with os.fdopen(fd, "wb") as f:
            f.write(data)
            f.flush()
            os.fsync(f.fileno())
        if p.exists():
            os.chmod(tmp, p.stat().st_mode & 0o777)
        else:
            os.chmod(tmp, 0o644)
        os.replace(tmp, p)
    except BaseException as e:
        if tmp is not None:
            try:
                os.unlink(tmp)
            except OSError:
                pass
        if isinstance(e, OSError):  # permissions, a full disk, a read-only or virtual file system
            raise UsageError(f"{p}: cannot write: {e.strerror or e}; any existing file is "
                             "unchanged") from None
        raise


@lru_cache(maxsize=1)
def schema() -> dict:
    return json.loads(resources.files("mechc").joinpath("schema/mechc.schema.json").read_text())


@lru_cache(maxsize=1)
def fast_validator():
    """The schema compiled by jsonschema-rs (Draft 2020-12, as the schema declares)."""
    return jsonschema_rs.Draft202012Validator(schema())


def validate(obj: dict, where: str) -> None:
    """Against the schema: jsonschema-rs decides (0.2 s where jsonschema takes 19 s on an 80 MB
    design); a design it rejects is validated again by jsonschema for the message, which
    names the first wrong place by its path."""
    try:
        if fast_validator().is_valid(obj):
            return
    except ValueError:  # a value jsonschema-rs does not take (a numpy scalar): jsonschema decides
        pass
    v = jsonschema.Draft202012Validator(schema())
    errors = sorted(v.iter_errors(obj), key=lambda e: list(e.absolute_path))
    if not errors:  # the two validators disagree: jsonschema-rs's own message, never a pass
        e = next(iter(fast_validator().iter_errors(obj)))
        loc = "/".join(str(p) for p in e.instance_path) or "(top level)"
        raise UsageError(f"{where}: not a valid mechc design at {loc}: {e.message}")
    if errors:
        e = errors[0]
        loc = "/".join(str(p) for p in e.absolute_path) or "(top level)"
        raise UsageError(f"{where}: not a valid mechc design at {loc}: {e.message}")


#: Largest magnitude of any number in a design. A coordinate of 1e9 mm is 1000 km: anything
#: larger is a corrupted file, and it overflows the drawing and the solver (to NaN) later on.
MAX_MAGNITUDE = 1e9

#: What reading a structurally wrong design raises: a missing key, a list too short, a value of
#: the wrong type. Caught only around the decoding of the file, never around the work on it.
DECODE_ERRORS = (KeyError, IndexError, TypeError, ValueError, AttributeError)


def load_design_json(path: str | Path) -> dict:
    p = Path(path)
    data = read_input(p, "a design file (.json)", "design")
    if data[:2] == GZIP_MAGIC:  # a design written as NAME.json.gz
        try:
            data = gzip.decompress(data)
        except (OSError, EOFError, zlib.error) as e:
            raise UsageError(f"{p}: cannot read design: a damaged gzip file ({e})") from None
    try:
        obj = json.loads(data)  # bytes: UTF-8, UTF-16 or UTF-32, as RFC 8259 allows
    except json.JSONDecodeError as e:
        raise SpecError(str(p), e.lineno, e.colno, f"invalid JSON: {e.msg}") from None
    except UnicodeDecodeError as e:
        raise UsageError(f"{p}: cannot read design: invalid {e.encoding} at byte {e.start}: "
                         "expected a JSON text") from None
    except RecursionError:
        raise UsageError(f"{p}: invalid JSON: nested too deeply") from None
    if not isinstance(obj, dict) or obj.get("format") != "mechc":
        raise UsageError(f"{p}: not a mechc design (expected \"format\": \"mechc\")")
    if obj.get("version") != FORMAT_VERSION:
        raise UsageError(f"{p}: design format version {obj.get('version')} is not supported "
                         f"(this mechc reads version {FORMAT_VERSION}); recompile the spec")
    check_design(obj, str(p))
    return obj


def check_design(obj: dict, where: str) -> None:
    """Everything reading a design checks before any work on it: numbers in range, the schema,
    the references the schema cannot express. Compile runs it too, so it never writes a file
    that ``simulate`` or ``draw`` would then refuse."""
    check_numbers(obj, where)
    validate(obj, where)
    check_references(obj, where)
    check_cell_types(obj, where)


def check_cell_types(obj: dict, where: str) -> None:
    """A logic type that is not built in was declared by a user cell file: the cell must have
    one in ``cell_sources`` (mechc/cells/sources.py), else the type means nothing here."""
    from mechc.ir.logic_types import BUILTIN

    sources = obj.get("cell_sources") or {}
    for i, c in enumerate(obj["cells"]):
        if c["type"] not in BUILTIN and sources.get(c["cell"], {}).get("library") != "user":
            raise UsageError(f"{where}: not a valid mechc design at cells/{i}/type: "
                             f"{c['type']!r} is not a built-in logic type, and cell "
                             f"{c['cell']!r} has no user cell file in cell_sources to declare it")


def check_numbers(obj, where: str) -> None:
    """Every number finite and within MAX_MAGNITUDE. Python's json reads NaN, Infinity and
    1e400 (as inf), and a JSON schema lets NaN through every minimum/maximum. A quick walk
    decides (0.3 s on a 4 MB design); only a design that fails is walked again for the path."""
    if not has_bad_number(obj):
        return
    todo: list[tuple[object, tuple]] = [(obj, ())]
    while todo:
        o, path = todo.pop()
        if isinstance(o, dict):
            todo.extend((v, (*path, k)) for k, v in o.items())
        elif isinstance(o, list):
            todo.extend((v, (*path, i)) for i, v in enumerate(o))
        elif isinstance(o, float) and not (math.isfinite(o) and abs(o) <= MAX_MAGNITUDE) or \
                isinstance(o, int) and not isinstance(o, bool) and abs(o) > MAX_MAGNITUDE:
            loc = "/".join(str(k) for k in path) or "(top level)"
            raise UsageError(f"{where}: not a valid mechc design at {loc}: {o} is not a finite "
                             f"number of magnitude at most {MAX_MAGNITUDE:g}")


def has_bad_number(obj) -> bool:
    """Whether any number in ``obj`` is NaN, infinite or of magnitude over MAX_MAGNITUDE
    (containers only on the stack, no paths: four times faster than the walk with paths)."""
    m = MAX_MAGNITUDE
    stack = [obj]
    while stack:
        o = stack.pop()
        for v in (o.values() if isinstance(o, dict) else o):
            t = type(v)
            if t is float:
                if not -m <= v <= m:  # NaN fails both comparisons
                    return True
            elif t is int:
                if v > m or v < -m:
                    return True
            elif t is dict or t is list:
                stack.append(v)
            elif t is not str and t is not bool and isinstance(v, (int, float)):
                if not -m <= float(v) <= m:  # a numpy scalar, in a design not yet written
                    return True
    return False


def check_references(obj: dict, where: str) -> None:
    """What the schema cannot say: every joint, spring and terminal names a body that exists,
    the mechanism's cell order is the set of cells with geometry, its outputs name a cell or an
    input with that pin, and the numbers the schema leaves open are in range. A broken reference
    would otherwise surface as a KeyError deep in a proof or a drawing."""
    mech = obj.get("mechanism")
    if not mech:
        return
    parts = [((("cells", i, "geometry")), c["geometry"]) for i, c in enumerate(obj["cells"])
             if "geometry" in c]
    parts += [(("mechanism", "inputs", k), v) for k, v in mech["inputs"].items()]
    parts += [(("mechanism", "nets", k), v) for k, v in mech["nets"].items()]

    def bad(path: tuple, what: str) -> UsageError:
        return UsageError(f"{where}: not a valid mechc design at "
                          f"{'/'.join(str(k) for k in path)}: {what}")

    bodies: dict[str, tuple] = {}
    for path, part in parts:
        for i, b in enumerate(part["bodies"]):
            if b["id"] in bodies or b["id"] == GROUND:
                raise bad((*path, "bodies", i, "id"), f"body id {b['id']!r} is used twice")
            bodies[b["id"]] = path

    def known(path: tuple, name) -> None:
        if name != GROUND and name not in bodies:
            raise bad(path, f"{name!r} is not a body of this design (nor {GROUND!r})")

    for path, part in parts:
        for i, j in enumerate(part["joints"]):
            here = (*path, "joints", i)
            for key in ("a", "b", "driven"):
                if key in j:
                    known((*here, key), j[key])
            prof = j.get("profile")
            if prof is not None and not (isinstance(prof, list) and all(
                    isinstance(q, list) and len(q) == 2
                    and all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in q)
                    for q in prof)):
                raise bad((*here, "profile"), "expected a list of [x, y] points")
            for key in ("radius_a_mm", "friction"):
                if key in j and not (isinstance(j[key], (int, float)) and j[key] >= 0):
                    raise bad((*here, key), f"{j[key]!r}: expected a number >= 0")
        for i, sp in enumerate(part["springs"]):
            here = (*path, "springs", i)
            known((*here, "a"), sp["a"])
            known((*here, "b"), sp["b"])
            if sp["rest_length_mm"] < 0:
                raise bad((*here, "rest_length_mm"), f"{sp['rest_length_mm']}: a length "
                          "cannot be negative")
        for k, t in part["terminals"].items():
            known((*path, "terminals", k, "body"), t["body"])
    for net, part in mech["nets"].items():  # a net's rod: one pin from its driver, one to its load
        for i, b in enumerate(part["bodies"]):
            ends = [sum(1 for j in part["joints"] if j["kind"] == "pin" and j[k] == b["id"])
                    for k in ("b", "a")]
            if b["kind"] != "pushrod" or ends != [1, 1]:
                raise bad(("mechanism", "nets", net, "bodies", i),
                          "a net's body must be a pushrod with one pin from its driver (b = "
                          f"the rod) and one to its load (a = the rod); {b['id']!r} is a "
                          f"{b['kind']} with {ends[0]} and {ends[1]}")
    geometry = {c["id"]: c["geometry"] for c in obj["cells"] if "geometry" in c}
    order = mech["order"]
    if sorted(order) != sorted(geometry):
        extra = sorted(set(order) - set(geometry)) or sorted(
            cid for cid in set(order) if order.count(cid) > 1)
        missing = sorted(set(geometry) - set(order))
        raise bad(("mechanism", "order"), "expected each cell with geometry once: "
                  + (f"{extra[0]!r} is not one or is listed twice" if extra
                     else f"{missing[0]!r} is missing"))
    for name, o in mech["outputs"].items():
        owner, pin = o["owner"], o["pin"]
        part = geometry.get(owner) or (mech["inputs"].get(owner[3:])
                                       if owner.startswith("in:") else None)
        if part is None or pin not in part["terminals"]:
            raise bad(("mechanism", "outputs", name), f"owner {owner!r} has no terminal {pin!r}")


def design_from_json(obj: dict, where: str = "<json>", mechanism: bool = True) -> Design:
    """The Design a checked JSON holds; ``mechanism=False`` leaves the geometry unread (a logic
    proof needs only the netlist; the whole file was still checked on loading)."""
    try:
        spec = _spec_from_json(obj["spec"], where)
    except DECODE_ERRORS as e:
        raise UsageError(f"{where}: inconsistent spec echo: {_why(e)}") from None
    try:
        nl = Netlist.from_json(obj["inputs"], obj["outputs"], obj["cells"])
    except DECODE_ERRORS as e:
        raise UsageError(f"{where}: inconsistent netlist: {_why(e)}") from None
    layout = None
    if obj.get("layout"):
        try:
            cells = {c["id"]: Place(**c["place"]) for c in obj["cells"] if "place" in c}
            lj = obj["layout"]
            layout = Layout(cells, {k: Place(**v) for k, v in lj.get("inputs", {}).items()},
                            tuple(lj.get("pitch_mm", (0, 0))), lj.get("crossings", 0))
        except DECODE_ERRORS as e:
            raise UsageError(f"{where}: inconsistent layout: {_why(e)}") from None
    mech = None
    if mechanism and obj.get("mechanism"):
        try:
            mech = mechanism_from_json(obj["mechanism"], obj["cells"])
        except DECODE_ERRORS as e:
            raise UsageError(f"{where}: inconsistent mechanism geometry: {_why(e)}") from None
    design = Design(spec, obj.get("equations", {}), obj.get("implemented", {}), nl, layout,
                    obj.get("stats", {}), mechanism=mech)
    design.cell_sources = dict(obj.get("cell_sources") or {})  # mechc/cells/sources.py
    return design


def _spec_from_json(d: dict, where: str):
    if d.get("kind") == "fsm":
        try:
            return seqspec_from_json(d, where)
        except SequentialError as e:  # a DesignError (exit 1), but here the file is wrong
            raise ValueError(str(e)) from None
    return spec_from_json(d, where)


def _why(e: Exception) -> str:
    """A decoding error as a phrase: a bare KeyError prints only the quoted key."""
    if isinstance(e, KeyError):
        return f"missing or unknown {e.args[0]!r}" if e.args else "missing entry"
    return str(e) or type(e).__name__


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
                    c.get("unit", ""), c.get("detail", "")) for c in d.get("checks", [])]
    return Mechanism(ctx, cell_parts,
                     {k: Part.from_json(p) for k, p in d["inputs"].items()},
                     {k: Part.from_json(p) for k, p in d["nets"].items()},
                     {k: (v["owner"], v["pin"]) for k, v in d["outputs"].items()},
                     dict(d.get("actuators", {})), list(d["order"]), checks)
