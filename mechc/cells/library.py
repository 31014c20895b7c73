"""Find and load library cells: every Cell subclass in ``stdlib`` and in user cell directories.

User directories come from ``--cells DIR`` and the ``MECHC_CELLS`` environment variable
(``os.pathsep``-separated). A broken cell file (it does not import, a cell declares an unknown
type or a name already taken) does not stop the others: the library loads what it can, warns once
on stderr with the file and line, and remembers it, so only a command that needs a cell it may
hold fails (exit 2, naming it). A cell may declare a new logic type (``function`` or ``truth``),
which is registered in :mod:`mechc.ir.logic_types` as its file loads.
"""

from __future__ import annotations

import hashlib
import importlib
import importlib.util
import inspect
import os
import pkgutil
import re
import sys
import traceback
from collections.abc import Iterable
from pathlib import Path

from mechc.cells.cell import Cell
from mechc.errors import DesignError, MechcError, UsageError
from mechc.ir.logic_types import BUILTIN, TYPES, declare_type, table_from_function, table_from_truth


class Library:
    def __init__(self, cells: dict[str, type[Cell]], broken: dict[str, str] | None = None):
        self.cells = dict(sorted(cells.items()))
        #: cell files that failed to load: path -> "path:line: message"
        self.broken: dict[str, str] = dict(broken or {})

    def __getitem__(self, name: str) -> type[Cell]:
        try:
            return self.cells[name]
        except KeyError:
            raise UsageError(f"unknown library cell '{name}' (see 'mechc cells')"
                             + self.broken_hint()) from None

    def broken_hint(self) -> str:
        """'; it may be in a cell file that failed to load: ...' (empty when none failed)."""
        if not self.broken:
            return ""
        return ("; it may be in a cell file that failed to load: "
                + "; ".join(self.broken.values()))

    def no_cell_error(self, type_name: str) -> MechcError:
        """The error for a design that needs a cell of ``type_name`` the library lacks: a usage
        error naming the broken cell files if any (one may hold it), else a design error."""
        msg = f"the cell library has no cell of type {type_name}"
        return UsageError(msg + self.broken_hint()) if self.broken else DesignError(msg)

    def __contains__(self, name: str) -> bool:
        return name in self.cells

    def for_type(self, type_name: str, n_inputs: int,
                 prefer: Iterable[str] = ()) -> type[Cell] | None:
        """Cheapest cell realising ``type_name`` with ``n_inputs`` inputs (ties: by name) among
        the cells offered to the mapper (``auto_select``) and those named in ``prefer``; a
        preferred cell that fits wins."""
        best = None
        prefer = set(prefer)
        for name in sorted(prefer):
            cell = self.cells.get(name)
            if cell and cell.type == type_name and cell.min_inputs <= n_inputs <= cell.max_inputs:
                return cell
        for cell in self.cells.values():
            if cell.type != type_name or not cell.min_inputs <= n_inputs <= cell.max_inputs:
                continue
            if not cell.auto_select:
                continue
            key = (cell.cost(n_inputs), cell.name)
            if best is None or key < best[0]:
                best = (key, cell)
        return best[1] if best else None

    def standard_cells(self, type_name: str) -> list[str]:
        """The standard library's cells of a logic type (what a user cell may stand in for)."""
        return [n for n, c in self.cells.items() if c.type == type_name and c.standard]

    def max_fan_in(self, type_name: str) -> int:
        return max((c.max_inputs for c in self.cells.values() if c.type == type_name), default=0)


_CACHE: dict[tuple, Library] = {}
TYPE_NAME = re.compile(r"[A-Z][A-Z0-9_]*")  # as the design JSON schema requires
_WARNED: set[str] = set()  # broken-file messages already printed (once per process)

#: The package of the standard cells (the repository's stdlib/ directory).
STDLIB = "mechc.stdlib"


class CellFileError(Exception):
    """A cell file that loads but declares something wrong (line: its class statement)."""

    def __init__(self, line: int, message: str):
        super().__init__(message)
        self.line = line


def user_dirs(extra: Iterable[str] = ()) -> list[str]:
    env = os.environ.get("MECHC_CELLS", "")
    return [d for d in [*extra, *env.split(os.pathsep)] if d]


def load_library(extra_dirs: Iterable[str] = (), files: Iterable[str] = ()) -> Library:
    """The standard cells, every cell file in ``extra_dirs`` (and ``MECHC_CELLS``), and the
    single cell ``files`` (what a design JSON recorded), cached per argument set."""
    dirs = tuple(user_dirs(extra_dirs))
    files = tuple(str(f) for f in files)
    key = (dirs, files)
    if key in _CACHE:
        return _CACHE[key]
    found: dict[str, type[Cell]] = {}
    broken: dict[str, str] = {}
    # the standard cells are found by package name, like any plugin: the loader does not
    # import them as a dependency (they import mechc.cells)
    std = list(importlib.util.find_spec(STDLIB).submodule_search_locations)
    for info in sorted(pkgutil.iter_modules(std), key=lambda i: i.name):
        if info.name.startswith("_"):
            continue
        path = Path(std[0]) / f"{info.name}.py"
        _load_file(path, lambda name=info.name: importlib.import_module(f"{STDLIB}.{name}"),
                   found, broken, standard=True)
    user_files: list[Path] = []
    for d in dirs:
        p = Path(d)
        if not p.is_dir():
            raise UsageError(f"cell directory '{d}' "
                             + ("is a file, not a directory of cell files" if p.exists()
                                else "does not exist"))
        # _helpers.py and test_*.py (a cell's tests, as mechc new-cell writes) are not cells
        user_files += [f for f in sorted(p.glob("*.py"))
                       if not f.name.startswith(("_", "test_"))]
    seen = {f.resolve() for f in user_files}
    for f in files:  # a recorded source already in a --cells directory is loaded once
        if Path(f).resolve() not in seen:
            user_files.append(Path(f))
            seen.add(Path(f).resolve())
    for f in user_files:
        _load_file(f, lambda f=f: _import_file(f), found, broken, standard=False)
    _drop_undeclared(found, broken)
    for msg in broken.values():
        if msg not in _WARNED:
            _WARNED.add(msg)
            print(f"mechc: warning: {msg} (its cells are not loaded)", file=sys.stderr)
    lib = Library(found, broken)
    _CACHE[key] = lib
    return lib


def _drop_undeclared(found: dict[str, type[Cell]], broken: dict[str, str]) -> None:
    """A cell of a declared type needs the declaring cell in this library (the type registry is
    per process: a file loaded for another library may have declared it)."""
    declared = {c.type for c in found.values() if c.function or c.truth}
    for cell in list(found.values()):
        t = TYPES[cell.type]
        if t.table is None or cell.type in declared or cell.source in broken:
            continue
        broken[cell.source] = (f"{cell.source}:{_line(cell)}: " + _unknown_type(cell))
        for other in [c for c in found.values() if c.source == cell.source]:
            del found[other.name]


def _unknown_type(obj: type[Cell]) -> str:
    return (f"cell '{obj.name}' declares unknown logic type '{obj.type}': declare a new type "
            "in the cell with function = \"...\" (an expression over its pins) or truth = "
            f"\"...\" (known types: {', '.join(sorted(BUILTIN))})")


def file_sha256(path: str | Path) -> str:
    """The content hash a design records for each cell file it uses."""
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def _import_file(path: Path):
    mod_name = f"mechc_usercells.{path.stem}_{abs(hash(str(path.resolve()))) % 10**8}"
    spec = importlib.util.spec_from_file_location(mod_name, path)
    mod = importlib.util.module_from_spec(spec)
    sys.modules[mod_name] = mod
    spec.loader.exec_module(mod)
    return mod


def _load_file(path: Path, load, found: dict[str, type[Cell]], broken: dict[str, str],
               standard: bool) -> None:
    """Import one cell file and add its cells to ``found``; a file that fails adds none and is
    recorded in ``broken`` as "path:line: message"."""
    try:
        mod = load()
        cells = _collect(mod, path, standard)
        for obj in cells:
            if obj.name in found:
                raise CellFileError(_line(obj), f"cell name '{obj.name}' is already defined "
                                    f"in {found[obj.name].source}")
    except CellFileError as e:
        broken[str(path)] = f"{path}:{e.line}: {e}"
        return
    except Exception as e:  # a user's cell file: say where it broke, no traceback
        frames = [f for f in traceback.extract_tb(e.__traceback__)
                  if Path(f.filename).resolve() == path.resolve()]
        line = frames[-1].lineno if frames else getattr(e, "lineno", 1) or 1
        broken[str(path)] = (f"{path}:{line}: error while loading cell file: "
                             f"{type(e).__name__}: {e}")
        return
    digest = file_sha256(path)
    for obj in cells:
        obj.source = str(path)
        obj.source_sha256 = digest
        obj.standard = standard
        found[obj.name] = obj


def _line(obj) -> int:
    try:
        return inspect.getsourcelines(obj)[1]
    except (OSError, TypeError):
        return 1


def _collect(mod, path: Path, standard: bool) -> list[type[Cell]]:
    """The cells a module defines, each type checked (a new one declared)."""
    out = []
    for _n, obj in inspect.getmembers(mod, inspect.isclass):
        if not issubclass(obj, Cell) or obj is Cell or obj.__module__ != mod.__name__:
            continue
        if not obj.name:
            continue  # an abstract helper base class
        if obj.function or obj.truth:
            _declare(obj, path)
        elif obj.type not in TYPES:
            raise CellFileError(_line(obj), _unknown_type(obj))
        if any(c.name == obj.name for c in out):
            raise CellFileError(_line(obj), f"cell name '{obj.name}' is defined twice")
        out.append(obj)
    return out


def _declare(obj: type[Cell], path: Path) -> None:
    """Register the logic type a cell declares with ``function`` or ``truth``."""
    line = _line(obj)
    if not TYPE_NAME.fullmatch(obj.type):
        raise CellFileError(line, f"cell '{obj.name}': type {obj.type!r}: a logic type is "
                            "written in capitals, digits and '_' (e.g. MAJ3)")
    if obj.function and obj.truth:
        raise CellFileError(line, f"cell '{obj.name}': give function or truth, not both")
    if obj.min_inputs != obj.max_inputs:
        raise CellFileError(line, f"cell '{obj.name}': a cell declaring its function must have "
                            f"one number of inputs (min_inputs = max_inputs), not "
                            f"{obj.min_inputs}..{obj.max_inputs}")
    pins = obj.input_names(obj.min_inputs)
    try:
        if obj.function:
            table = table_from_function(obj.function, pins, f"{path}: cell '{obj.name}' "
                                        "function")
        else:
            table = table_from_truth(obj.truth, len(pins))
        declare_type(obj.type, table, str(path))
    except MechcError as e:  # the expression's own parse error (pins named)
        raise CellFileError(line, f"cell '{obj.name}': {e} (the function is over the input "
                            f"pins {', '.join(pins)})") from None
    except ValueError as e:
        raise CellFileError(line, f"cell '{obj.name}': {e}") from None
