"""``mechc new-cell NAME``: write a working, documented cell file to start from, and a pytest
file beside it that compiles the cell alone and proves it at the kinematic level.

The template is an OR or AND bar (the simplest cells, 001 Fig 16a/b). With ``--type`` naming a
type that is not built in, the template declares that new type with ``function = "A | B"`` and
builds the OR bar, so it compiles and proves as written; the user then changes the function
and the mechanism together. Nothing is overwritten: an existing file is an error (exit 2) and
then neither file is written.
"""

from __future__ import annotations

import argparse
import re
from pathlib import Path

from mechc.errors import EXIT_OK, UsageError
from mechc.ir.logic_types import BUILTIN

#: Built-in types the template can build (one bar); another built-in type has a stdlib cell
#: to copy instead.
TEMPLATE_TYPES = {"OR": "or_bar", "AND": "and_bar"}
STDLIB_FILE = {"NOT": "not_lever.py", "NAND": "nand_gate.py", "NOR": "nor_gate.py",
               "AND_NOT": "and_not_gate.py", "OR_NOT": "or_not_gate.py", "XOR": "xor_gate.py",
               "XNOR": "xnor_gate.py", "THRESHOLD": "threshold.py", "MEMORY": "memory.py",
               "AMPLIFIER": "amplifier.py", "CONST": "const_stop.py", "CONNECTOR": "not_lever.py"}
NAME = re.compile(r"[a-z][a-z0-9_]*")
TYPE = re.compile(r"[A-Z][A-Z0-9_]*")


def register(sub) -> None:
    p = sub.add_parser("new-cell", help="write a template cell file and its test",
                       description="Write DIR/NAME.py, a working cell (an OR or AND bar, or a "
                       "new logic type declared with function = \"A | B\" over an OR bar) with "
                       "comments on every step, and DIR/test_NAME.py, a pytest test that "
                       "compiles the cell alone and proves it at the kinematic level. Existing "
                       "files are never overwritten. See docs/write-a-cell.md.")
    p.add_argument("name", metavar="NAME", help="cell name: lower case, digits and _")
    p.add_argument("--type", dest="type_name", default="OR", metavar="T",
                   help="logic type: OR or AND, or a new type name (capitals) that the file "
                   "then declares (default: %(default)s)")
    p.add_argument("--dir", default="cells", help="directory to write into, created if "
                   "missing; pass it to --cells (default: %(default)s)")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    name, t = args.name, args.type_name
    if not NAME.fullmatch(name):
        raise UsageError(f"cell name {name!r}: use lower case letters, digits and _, starting "
                         "with a letter (e.g. wide_or)")
    if not TYPE.fullmatch(t):
        raise UsageError(f"--type {t!r}: a logic type is written in capitals, digits and _ "
                         "(e.g. OR, MAJ3)")
    if t in BUILTIN and t not in TEMPLATE_TYPES:
        raise UsageError(f"--type {t}: the template builds OR, AND or a new type; for {t} "
                         f"start from the standard cell stdlib/{STDLIB_FILE.get(t, '')} instead")
    d = Path(args.dir)
    if d.exists() and not d.is_dir():
        raise UsageError(f"--dir {d}: is a file, not a directory")
    cell, test = d / f"{name}.py", d / f"test_{name}.py"
    for f in (cell, test):
        if f.exists():
            raise UsageError(f"{f}: already exists; refusing to overwrite it (nothing written)")
    d.mkdir(parents=True, exist_ok=True)
    with open(cell, "x", encoding="utf-8") as fh:
        fh.write(cell_text(name, t))
    with open(test, "x", encoding="utf-8") as fh:
        fh.write(test_text(name))
    print(f"wrote {cell} (cell '{name}', type {t}) and {test}\n"
          f"  mechc cells --cells {d}\n"
          f"  python -m pytest {test}")
    return EXIT_OK


def cell_text(name: str, type_name: str) -> str:
    """The template cell file."""
    new = type_name not in BUILTIN
    block = TEMPLATE_TYPES.get(type_name, "or_bar")
    cls = "".join(p.capitalize() for p in name.split("_")) or "MyCell"
    if new:
        declare = (f'    type = "{type_name}"  # a new logic type, declared by the next line\n'
                   '    # its Boolean function over the input pins A, B (the .bool syntax:\n'
                   '    # & | ^ ~ and parentheses); or truth = "0111": the output for inputs\n'
                   '    # 00, 01, 10, 11. Change it together with synthesise(): every compile\n'
                   '    # proves the mechanism against it.\n'
                   '    function = "A | B"\n'
                   '    min_inputs = 2  # a declared function has one number of inputs\n'
                   '    max_inputs = 2\n')
        what = f"new logic type {type_name}, as written A | B on an OR bar"
    else:
        declare = (f'    type = "{type_name}"  # a built-in logic type (see: mechc cells)\n'
                   '    min_inputs = 2  # fan-in range the mapper may use\n'
                   '    max_inputs = 3\n')
        what = f"an {type_name} bar"
    how = {"or_bar": "a bar pushed on by any input through one-sided contacts;\na "
                     "preloaded spring pulls it back to off",
           "and_bar": "a bar sprung towards on, held back by a hook on every\ninput"}[block]
    return f'''"""{name}: {what}.

Written by ``mechc new-cell``; edit it to make your own cell (docs/write-a-cell.md, and
docs/builder-api.md for every Builder call). Use it with ``--cells DIR`` on any mechc command;
``test_{name}.py`` beside it compiles it alone and proves it at the kinematic level.

The mechanism: {how}.
"""

from mechc.cells.builder import Builder
from mechc.cells.cell import Cell


class {cls}(Cell):
    """{what[0].upper() + what[1:]} (say here what your cell is for)."""

    name = "{name}"  # the library name, the "cell" field of the design JSON
{declare}    # one line for `mechc cells`
    description = "{what}"
    # False: the mapper uses this cell only when asked (--use-cell {name}); True lets it
    # compete on cost() with the standard cells of its type
    auto_select = False

    @classmethod
    def cost(cls, n_inputs: int) -> int:
        """Parts (bodies + springs) of an instance: the mapper minimises the sum."""
        return 2 + n_inputs  # bar, spring, one input slider per input

    @classmethod
    def synthesise(cls, cid, ctx, n_inputs, params, demand):
        """The mechanism at a local origin, every signal at half stroke (the design pose):
        input terminals on the left edge (x = 0), rows going down from y = 0, the output on
        the right; every terminal moves +x by ctx.stroke from off to on."""
        b = Builder(cid, ctx)
        S, w, p = ctx.stroke, ctx.bar, ctx.pitch  # stroke, bar width, row pitch (mm)
        pins = cls.input_names(n_inputs)  # A, B, C, ...
        # one input slider per pin, one row apart
        sigs = [b.input_slider(pin, 0.0, -i * p, 1.5 * S) for i, pin in enumerate(pins)]
        # the bar: its spring is sized for `demand` (what the output must move each way);
        # `loads` is what each input must then deliver
        bar, loads = b.{block}("bar", sigs, 1.5 * S + w / 2, demand)
        bar.y = -(n_inputs - 1) * p / 2  # the output terminal on the middle row
        b.output(bar, "Z", reach=bar.x + 0.8 * S)
        # record the input loads so the compiler sizes the cells that drive this one
        return b.finish(dict(zip(pins, loads)))
'''


def test_text(name: str) -> str:
    """The pytest file written beside the cell."""
    return f'''"""The cell {name} alone: compiled between input sliders and the output, proven at
the kinematic level (its geometry moved, not its logic type) against its logic type, for every
fan-in it allows. Written by ``mechc new-cell``; run it with ``python -m pytest``."""

from pathlib import Path

from mechc.cells.library import load_library
from mechc.frontends.boolfile import parse_bool
from mechc.ir.logic_types import evaluate_type, table_rows
from mechc.ir.netlist import CellInst, Netlist
from mechc.pipeline import compile_netlist
from mechc.proofs import prove

HERE = Path(__file__).resolve().parent


def test_{name}_computes_its_type_alone():
    lib = load_library([str(HERE)])
    assert str(HERE / "{name}.py") not in lib.broken, lib.broken
    cls = lib["{name}"]
    for n in range(cls.min_inputs, cls.max_inputs + 1):
        nets = [f"i{{k}}" for k in range(n)]
        table = evaluate_type(cls.type, table_rows(n), {{}}, 1 << n)
        on = ", ".join(str(r) for r in range(1 << n) if table[r])
        spec = parse_bool(f"inputs {{' '.join(nets)}}\\noutputs z\\n"
                          + (f"z = minterms({{on}})\\n" if on else "z = 0\\n"))
        nl = Netlist(nets)
        nl.add_cell(CellInst("c1", cls.name, cls.type, tuple(nets), ("z",)),
                    pin_names=cls.input_names(n), out_pins=list(cls.outputs))
        nl.set_output("z", "z")
        design = compile_netlist(spec, nl, library=lib)
        assert design.stats["design_checks"]["passed"], design.stats["design_checks"]["failed"]
        report = prove(design, spec, lib, "kinematic")
        assert report.passed, report.failures
'''
