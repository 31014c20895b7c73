"""Where a design's cells came from: recorded in the design JSON at compile, used by
``simulate`` to load the same cell files again without ``--cells``.

Each library cell a design uses is recorded as ``{"library": "standard"}`` or
``{"library": "user", "path": ABSOLUTE_PATH, "sha256": HASH_OF_THE_FILE}``. Reading a design,
a user cell is loaded from that path when no ``--cells`` directory (nor ``MECHC_CELLS``) supplies
it; a file that is gone, or whose bytes changed since the compile, is an error (exit 2) naming
the cell and the file: a changed cell may build or mean something else than the geometry and
logic type the design holds. Passing ``--cells DIR`` with the cell in it is the way to simulate
with the file as it is now (a warning then says it changed).
"""

from __future__ import annotations

import sys
from pathlib import Path

from mechc.cells.library import Library, file_sha256, load_library, user_dirs
from mechc.errors import UsageError
from mechc.ir.netlist import Netlist

STANDARD = "standard"
USER = "user"


def cell_sources(nl: Netlist, lib: Library) -> dict[str, dict]:
    """Each library cell ``nl`` uses -> its source record (sorted by cell name)."""
    out: dict[str, dict] = {}
    for name in sorted({c.cell for c in nl.cells.values()}):
        cls = lib[name]
        if cls.standard:
            out[name] = {"library": STANDARD}
        else:
            out[name] = {"library": USER, "path": str(Path(cls.source).resolve()),
                         "sha256": cls.source_sha256}
    return out


def library_for_design(sources: dict[str, dict], cell_dirs: list[str] | tuple[str, ...],
                       where: str) -> Library:
    """The library to prove or draw a design with: the standard cells, ``cell_dirs`` (and
    ``MECHC_CELLS``), and every user cell file the design recorded that those do not supply."""
    base = load_library(cell_dirs)
    explicit = bool(user_dirs(cell_dirs))
    files: list[str] = []
    for name, src in sorted(sources.items()):
        if src.get("library") != USER:
            continue
        path, want = src.get("path", ""), src.get("sha256", "")
        cls = base.cells.get(name)
        if cls is not None and explicit and not cls.standard:
            if file_sha256(cls.source) != want:
                print(f"mechc: warning: {where}: cell '{name}' was compiled from a file with "
                      f"sha256 {want[:12]}; {cls.source} (sha256 "
                      f"{cls.source_sha256[:12]}) differs, and is used as --cells asks",
                      file=sys.stderr)
            continue
        p = Path(path)
        if not p.is_file():
            raise UsageError(f"{where}: cell '{name}' was compiled from {path}, which no longer "
                             "exists: pass --cells DIR with a directory that holds the cell")
        got = file_sha256(p)
        if got != want:
            raise UsageError(f"{where}: cell '{name}': {path} changed since the design was "
                             f"compiled (sha256 {want[:12]}, now {got[:12]}): recompile, or "
                             f"pass --cells {p.parent} to simulate with the file as it is now")
        files.append(str(p))
    if not files:
        return base
    lib = load_library(cell_dirs, files)
    for f in files:
        if f in lib.broken:
            raise UsageError(f"{where}: the design's cell file failed to load: {lib.broken[f]}")
    return lib
