"""Front end for synthesisable Verilog (combinational), read by Yosys.

Yosys parses and elaborates the module (``read_verilog``, ``hierarchy -auto-top``, ``proc``,
``flatten``), synthesises it to simple gates and writes it as BLIF; that network is read by the
BLIF front end, so the ``Spec`` carries both the functions (for minimisation and the proofs)
and the gate structure (``Spec.structure``, where multi-level synthesis starts); beyond 20
input bits it is valued by that gate network alone (``Spec.network``), as a wide BLIF is. A vector
port bit ``A[3]`` becomes the input ``A3`` (the Verilog name is kept for display). Errors that
Yosys reports are given back as ``file:line:col`` of the Verilog source; flip-flops, latches
and memories are refused at their line (sequential specs are written as .fsm or .kiss2).
"""

from __future__ import annotations

import json
import re

from mechc.errors import SpecError
from mechc.frontends.blif import parse_blif
from mechc.frontends.lexer import read_text
from mechc.ir.spec import Spec
from mechc.logic.yosys import run_yosys

_SOURCE = "input.v"
_SCRIPT = f"""read_verilog -noautowire -sv {_SOURCE}
hierarchy -check -auto-top
proc
flatten
opt_clean
check -assert
write_json elaborated.json
synth -flatten
abc -g AND,NAND,OR,NOR,XOR,XNOR,ANDNOT,ORNOT
opt_clean -purge
write_blif gates.blif
"""
#: Yosys cell types that hold state.
_STATEFUL = re.compile(r"dff|dlatch|latch|\$ff|\$sr|\$mem|\$_SR|\$_FF", re.IGNORECASE)
_LOCATED = re.compile(rf"^{re.escape(_SOURCE)}:(\d+)(?:\.(\d+))?(?:-[\d.]+)?:\s*ERROR:\s*(.*)$")
_SRC = re.compile(rf"{re.escape(_SOURCE)}:(\d+)\.(\d+)")


def parse_verilog_file(path: str) -> Spec:
    return parse_verilog(read_text(path), str(path))


def parse_verilog(text: str, path: str = "<string>") -> Spec:
    res = run_yosys(_SCRIPT, {_SOURCE: text}, ["elaborated.json", "gates.blif"])
    lines = text.split("\n")
    if res.returncode != 0 or "gates.blif" not in res.files:
        line, col, msg = yosys_error(res.log, lines)
        raise SpecError(path, line, col, msg)
    doc = json.loads(res.files["elaborated.json"])
    (top, mod), = ((n, m) for n, m in doc["modules"].items()
                   if m.get("attributes", {}).get("top"))
    module_line, module_col = _src(mod.get("attributes", {}), (1, 1))
    for c in mod.get("cells", {}).values():
        if _STATEFUL.search(c["type"]):
            line, col = _src(c.get("attributes", {}), (module_line, module_col))
            raise SpecError(path, line, col, "sequential logic (a flip-flop, latch or memory, "
                            f"Yosys cell {c['type']}) is not supported: mechc reads "
                            "combinational Verilog; write a machine as .fsm or .kiss2")
    rename, display = port_names(mod, path, module_line, module_col)
    blif = res.files["gates.blif"]
    blif = "\n".join(" ".join(rename.get(w, w) for w in ln.split()) for ln in blif.split("\n"))
    try:
        spec = parse_blif(blif, path)
    except SpecError as e:  # a limit of the network (e.g. too many inputs), not a BLIF typo
        raise SpecError(path, module_line, module_col,
                        f"module {top}: {e.message}") from None
    spec.kind = "pla"
    spec.display = display
    return spec


def port_names(mod: dict, path: str, line: int, col: int) -> tuple[dict, dict]:
    """BLIF port bit name -> mechc name (``A[3]`` -> ``A3``), and mechc name -> Verilog name
    where they differ; two bits that would get one name are an error."""
    rename: dict[str, str] = {}
    display: dict[str, str] = {}
    seen: dict[str, str] = {}
    for name, port in mod["ports"].items():
        if port["direction"] not in ("input", "output"):
            raise SpecError(path, line, col, f"port {name} is {port['direction']}: mechc "
                            "reads inputs and outputs only")
        width = len(port["bits"])
        offset = int(port.get("offset", 0))
        for k in range(width):
            original = name if width == 1 else f"{name}[{k + offset}]"
            safe = name if width == 1 else f"{name}{k + offset}"
            if not re.match(r"^[A-Za-z_][A-Za-z0-9_]*$", safe):
                raise SpecError(path, line, col, f"port name {name!r} is not usable (letters, "
                                "digits and '_', not starting with a digit)")
            if safe in seen:
                raise SpecError(path, line, col, f"port bit {original} and {seen[safe]} "
                                f"would both be called {safe}: rename one of the ports")
            seen[safe] = original
            rename[original] = safe
            if safe != original:
                display[safe] = original
    return rename, display


def _src(attrs: dict, default: tuple[int, int]) -> tuple[int, int]:
    m = _SRC.search(str(attrs.get("src", "")))
    return (int(m.group(1)), int(m.group(2))) if m else default


def yosys_error(log: str, lines: list[str]) -> tuple[int, int, str]:
    """The first error Yosys reported, as (line, column, message) in the Verilog source.
    Yosys gives a line (sometimes a column); where it does not, the column is that of the
    token the message quotes on that line, else the line's first non-blank character."""
    located = None
    bare = None
    warning = None  # 'check -assert' fails with a count; the warning before it says what
    for raw in log.splitlines():
        m = _LOCATED.match(raw.strip())
        if m:
            located = m
            break
        if raw.startswith("Warning:") and warning is None:
            warning = raw.split("Warning:", 1)[1].strip()
        if "ERROR:" in raw and bare is None:
            bare = raw.split("ERROR:", 1)[1].strip()
            if "check -assert" in bare and warning:
                bare = warning
    if located:
        line = int(located.group(1))
        msg = located.group(3).strip()
        if "end of file" in msg:  # Yosys names the line it started from; the end is later
            line = max((k for k, t in enumerate(lines, start=1) if t.strip()), default=1)
        col = int(located.group(2)) if located.group(2) else _column(lines, line, msg)
        return line, col, msg
    msg = bare or "Yosys could not read this Verilog"
    for word in _quoted(msg):  # no line given: point at the first use of a quoted name
        for k, text in enumerate(lines, start=1):
            c = _find_word(text, word)
            if c:
                return k, c, msg
    return 1, 1, msg


def _quoted(msg: str) -> list[str]:
    out = [m.group(1).lstrip("\\") for m in re.finditer(r"`([^']+)'", msg)]
    out += re.findall(r"\\([A-Za-z_]\w*)", msg)  # Yosys' escaped names: m.\w
    out += [m.group(1) for m in re.finditer(r"unexpected '([^']+)'", msg)]
    out += [m.group(1) for m in re.finditer(r"unexpected (TOK_\w+|\w+)", msg)
            if not m.group(1).startswith("TOK_")]
    return [w.split(".")[-1] for w in out if w]


def _find_word(text: str, word: str) -> int:
    if re.match(r"^\w+$", word):
        m = re.search(rf"(?<![\w$]){re.escape(word)}(?![\w$])", text)
        return m.start() + 1 if m else 0
    k = text.find(word)
    return k + 1 if k >= 0 else 0


def _column(lines: list[str], line: int, msg: str) -> int:
    text = lines[line - 1] if 0 < line <= len(lines) else ""
    for word in _quoted(msg):
        c = _find_word(text, word)
        if c:
            return c
    stripped = len(text) - len(text.lstrip())
    return stripped + 1 if text.strip() else 1
