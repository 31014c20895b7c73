"""``mechc cells``: the cell library, as a table or JSON."""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from mechc.cells.characterise import SHIPPED, characterise_standard
from mechc.cells.library import Library, load_library
from mechc.errors import EXIT_OK
from mechc.ui import table


def register(sub) -> None:
    k = sub.add_parser("cells", help="list the cell library",
                       description="List library cells: name, logic type, pins, cost (parts). "
                       "Cells come from stdlib/ and from directories in --cells / MECHC_CELLS.")
    k.add_argument("--cells", dest="cell_dirs", action="append", default=[], metavar="DIR",
                   help="extra directory of cell files (repeatable)")
    k.add_argument("action", nargs="?", choices=["list", "characterise"], default="list",
                   help="list (default), or characterise: measure the stdlib cells' timing "
                   "tables in pymunk and write them (docs/performance.md)")
    k.add_argument("--json", action="store_true", help="print as JSON")
    k.add_argument("--out", default=None, metavar="FILE",
                   help="characterise: the file to write (default: the tables mechc ships)")
    k.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    lib = load_library(args.cell_dirs)
    if args.action == "characterise":
        return characterise(lib, args.out)
    rows, items = [], []
    for name, cell in lib.cells.items():
        n = cell.min_inputs
        fan = (f"{cell.min_inputs}" if cell.min_inputs == cell.max_inputs
               else f"{cell.min_inputs}-{cell.max_inputs}")
        pins = ",".join(cell.input_names(n)) + (f"..{cell.input_names(cell.max_inputs)[-1]}"
                                                 if cell.max_inputs > n else "")
        rows.append([name, cell.type, fan, f"{pins or '-'} -> {','.join(cell.outputs)}",
                     cell.pin_kind, cell.cost(n), cell.description])
        items.append({"name": name, "type": cell.type, "inputs": [cell.min_inputs,
                      cell.max_inputs], "outputs": list(cell.outputs), "pin_kind": cell.pin_kind,
                      "cost": {str(k): cell.cost(k) for k in range(cell.min_inputs,
                                                                   cell.max_inputs + 1)},
                      "description": cell.description, "source": cell.source})
    if args.json:
        print(json.dumps(items, indent=2))
    else:
        print(table(rows, ["cell", "type", "inputs", "pins", "kind", "cost", "description"]))
    return EXIT_OK


def characterise(lib: Library, out: str | None) -> int:
    """Measure the stdlib cells' timing tables (``mechc.cells.characterise``) and write them."""
    path = Path(out) if out else SHIPPED
    data = characterise_standard(lib, say=lambda s: print(s, file=sys.stderr, flush=True))
    path.write_text(json.dumps(data, indent=1) + "\n")
    print(f"wrote {len(data['tables'])} cell tables to {path}")
    return EXIT_OK
