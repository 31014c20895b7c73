"""The cell protocol: what a library cell declares so the compiler can use it.

A cell is a small class in a file under ``stdlib/`` (or a directory given with ``--cells`` or
``MECHC_CELLS``); ``mechc cells`` lists it without any change to the compiler. See
docs/write-a-cell.md.

Besides its logic type and cost, a cell builds its mechanism (``synthesise``), and the compiler
evaluates it with the generic closed-form kinematics and pymunk dynamics of
``mechc.physics`` — a cell with parts those do not cover (cams, rollers, toggles) overrides
``kinematics`` / ``build_dynamics``. A cell with design rules of its own returns them as checks
(``checks``), which the design-check pass adds to the design's.
"""

from __future__ import annotations

import string
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from mechc.ir.check import Check
from mechc.ir.mechanism import Demand, Part, SynthContext
from mechc.physics.closed_form import solve


@dataclass(frozen=True)
class Pin:
    name: str
    kind: str = "translating"  # or "rotating"
    direction: str = "in"  # "in" | "out"


class Cell:
    """Base class of library cells.

    Class attributes a subclass sets:

    - ``name``: unique library name (lower case), the ``cell`` field of netlist cells;
    - ``type``: the logic type it realises: a built-in one (``mechc.ir.logic_types.TYPES``) or
      a new name, declared by ``function`` or ``truth`` (below);
    - ``function``: the type's Boolean function as an expression in the .bool syntax over the
      input pin names, e.g. ``"A&B | A&C | B&C"`` (only for a new type, or to restate a
      built-in one, which is then checked);
    - ``truth``: the same as a truth table instead, ``"00010111"``: the output for inputs
      000, 001, ..., 111, first pin the most significant bit;
    - ``min_inputs`` / ``max_inputs``: how many input pins it can have (fan-in);
    - ``pin_kind``: ``"translating"`` or ``"rotating"`` terminals;
    - ``outputs``: output pin names;
    - ``description``: one line for ``mechc cells``;
    - ``auto_select``: False keeps the mapper from choosing it unless asked for by name.
    """

    name: ClassVar[str] = ""
    type: ClassVar[str] = ""
    min_inputs: ClassVar[int] = 2
    max_inputs: ClassVar[int] = 2
    outputs: ClassVar[tuple[str, ...]] = ("Z",)
    pin_kind: ClassVar[str] = "translating"
    description: ClassVar[str] = ""
    function: ClassVar[str] = ""  # a new logic type's expression over the input pins
    truth: ClassVar[str | tuple[int, ...]] = ""  # ... or its truth table (first pin = MSB)
    source: ClassVar[str] = ""  # set by the library loader: file the cell came from
    source_sha256: ClassVar[str] = ""  # set by the loader: hash of that file's bytes
    standard: ClassVar[bool] = False  # set by the loader: True for the cells of stdlib/
    auto_select: ClassVar[bool] = True  # offered to the mapper by cost (else only on request)
    stateful: ClassVar[bool] = False  # kinematics needs the previous state (MEMORY)

    @classmethod
    def input_names(cls, n: int) -> list[str]:
        """Input pin names for an instance with ``n`` inputs (A, B, C, ... by default)."""
        return list(string.ascii_uppercase[:n])

    @classmethod
    def pins(cls, n: int) -> list[Pin]:
        return ([Pin(p, cls.pin_kind, "in") for p in cls.input_names(n)]
                + [Pin(p, cls.pin_kind, "out") for p in cls.outputs])

    @classmethod
    def cost(cls, n_inputs: int) -> int:
        """Parts count (bodies + springs) of an instance; the mapper minimises the sum."""
        raise NotImplementedError

    @classmethod
    def synthesise(cls, cid: str, ctx: SynthContext, n_inputs: int, params: dict,
                   demand: Demand) -> Part:
        """The mechanism at a local origin: input terminals on the left edge (x = 0), rows
        going down from y = 0, every signal at half stroke. ``demand`` is the force the output
        must deliver each way; the part's ``data["input_loads"]`` says what each input asks."""
        raise NotImplementedError(f"cell {cls.name} has no mechanism")

    @classmethod
    def checks(cls, cid: str, part: Part, ctx: SynthContext) -> list[Check]:
        """The cell's own design rules on its placed instance ``cid`` (numbers in
        ``part.data``), beyond what the compiler measures on every mechanism; a failed one
        fails the design like any other check. The default has none."""
        return []

    @classmethod
    def rest_checks(cls, cid: str, part: Part, ctx: SynthContext, poses) -> list[Check]:
        """The cell's own rules on its placed instance at rest: ``poses`` (a
        ``mechc.parts.poses.Poses``) holds every body's coordinates in every rest state of the
        whole mechanism (every input vector the design checks take). The default has none."""
        return []

    @classmethod
    def kinematics(cls, part: Part, fixed: dict[str, np.ndarray], size: int, extra=None):
        """Poses of every body given the input terminal bodies' displacements (closed form)."""
        return solve(part, fixed, size, extra)

    @classmethod
    def build_dynamics(cls, scene, part: Part) -> None:
        """Add to the pymunk scene what the generic bodies, joints and springs of ``part``
        leave out (motors, special shapes); the default adds nothing."""
