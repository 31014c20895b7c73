"""Find and load library cells: every Cell subclass in ``stdlib`` and in user cell directories.

User directories come from ``--cells DIR`` and the ``MECHC_CELLS`` environment variable
(``os.pathsep``-separated). A broken cell file is reported with its file and line, not a traceback.
"""

from __future__ import annotations

import importlib
import importlib.util
import inspect
import os
import pkgutil
import sys
import traceback
from collections.abc import Iterable
from pathlib import Path

from mechc.cells.cell import Cell
from mechc.errors import UsageError
from mechc.ir.logic_types import TYPES


class Library:
    def __init__(self, cells: dict[str, type[Cell]]):
        self.cells = dict(sorted(cells.items()))

    def __getitem__(self, name: str) -> type[Cell]:
        try:
            return self.cells[name]
        except KeyError:
            raise UsageError(f"unknown library cell '{name}' (see 'mechc cells')") from None

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


_CACHE: dict[tuple[str, ...], Library] = {}

#: The package of the standard cells (the repository's stdlib/ directory).
STDLIB = "mechc.stdlib"


def user_dirs(extra: Iterable[str] = ()) -> list[str]:
    env = os.environ.get("MECHC_CELLS", "")
    return [d for d in [*extra, *env.split(os.pathsep)] if d]


def load_library(extra_dirs: Iterable[str] = ()) -> Library:
    dirs = tuple(user_dirs(extra_dirs))
    if dirs in _CACHE:
        return _CACHE[dirs]
    found: dict[str, type[Cell]] = {}
    # the standard cells are found by package name, like any plugin: the loader does not
    # import them as a dependency (they import mechc.cells)
    std = list(importlib.util.find_spec(STDLIB).submodule_search_locations)
    for info in sorted(pkgutil.iter_modules(std), key=lambda i: i.name):
        if info.name.startswith("_"):
            continue
        path = Path(std[0]) / f"{info.name}.py"
        mod = _guarded(path, lambda name=info.name: importlib.import_module(f"{STDLIB}.{name}"))
        _collect(mod, path, found, standard=True)
    for d in dirs:
        p = Path(d)
        if not p.is_dir():
            raise UsageError(f"cell directory '{d}' "
                             + ("is a file, not a directory of cell files" if p.exists()
                                else "does not exist"))
        for f in sorted(p.glob("*.py")):
            if f.name.startswith("_"):
                continue
            mod = _guarded(f, lambda f=f: _import_file(f))
            _collect(mod, f, found, standard=False)
    lib = Library(found)
    _CACHE[dirs] = lib
    return lib


def _import_file(path: Path):
    mod_name = f"mechc_usercells.{path.stem}_{abs(hash(str(path.resolve()))) % 10**8}"
    spec = importlib.util.spec_from_file_location(mod_name, path)
    mod = importlib.util.module_from_spec(spec)
    sys.modules[mod_name] = mod
    spec.loader.exec_module(mod)
    return mod


def _guarded(path: Path, load):
    try:
        return load()
    except Exception as e:  # a user's cell file: say where it broke, no traceback
        frames = [f for f in traceback.extract_tb(e.__traceback__)
                  if Path(f.filename).resolve() == path.resolve()]
        line = frames[-1].lineno if frames else getattr(e, "lineno", 1) or 1
        raise UsageError(f"{path}:{line}: error while loading cell file: "
                         f"{type(e).__name__}: {e}") from None


def _collect(mod, path: Path, found: dict[str, type[Cell]], standard: bool) -> None:
    for _n, obj in inspect.getmembers(mod, inspect.isclass):
        if not issubclass(obj, Cell) or obj is Cell or obj.__module__ != mod.__name__:
            continue
        if not obj.name:
            continue  # an abstract helper base class
        if obj.type not in TYPES:
            raise UsageError(f"{path}: cell '{obj.name}' declares unknown logic type "
                             f"'{obj.type}' (known: {', '.join(TYPES)})")
        if obj.name in found:
            raise UsageError(f"{path}: cell name '{obj.name}' is already defined in "
                             f"{found[obj.name].source}")
        obj.source = str(path)
        obj.standard = standard
        found[obj.name] = obj
