"""Step 6: SET/RESET and output equations minimised from the excitation tables, merged into one
``Equations`` for the mapper; ``SeqEquations`` is what the mapper builds and the JSON reports."""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from mechc.errors import DesignError
from mechc.ir import expr as ex
from mechc.ir.equations import Equations
from mechc.ir.seqspec import SeqSpec
from mechc.ir.spec import OutputSpec, Spec
from mechc.logic.cubes import DC, Cube, eval_cover
from mechc.passes.flowtable.excite import Excitation
from mechc.passes.flowtable.options import SynthOptions
from mechc.passes.minimise import count_shared, minimise


@dataclass
class SeqEquations:
    """What the mapper builds and the JSON reports: equations over inputs + memories."""

    inputs: list[str]
    outputs: list[str]
    memories: list[str]
    initial: dict[str, int]
    set_names: dict[str, str]  # memory -> name of its SET function in ``eq``
    reset_names: dict[str, str]
    eq: Equations  # over inputs + memories; outputs: SET, RESET functions and spec outputs
    form: str  # "table" | "setreset"
    classes: list[list[str]] = field(default_factory=list)
    codes: dict[str, str] = field(default_factory=dict)  # merged row -> code
    state_codes: dict[str, str] = field(default_factory=dict)  # spec row -> code
    cover: dict = field(default_factory=dict)
    assignment: dict = field(default_factory=dict)
    essential_hazards: list[dict] = field(default_factory=list)
    checked: dict = field(default_factory=dict)
    warnings: list[str] = field(default_factory=list)  # for the user (compile prints them)
    seconds: float = 0.0

    def text(self, name: str) -> str:
        return self.eq.text(name)

    def cover_of(self, name: str) -> list[Cube]:
        """The cover the mapper builds (with consensus terms)."""
        return (self.eq.hazard_free.get(name) or self.eq.covers[name]).cubes

    def to_json(self) -> dict:
        d = {
            "form": self.form,
            "memories": [{"name": m, "set": self.text(self.set_names[m]),
                          "reset": self.text(self.reset_names[m]),
                          "initial": self.initial[m]} for m in self.memories],
            "outputs": {o: self.text(o) for o in self.outputs},
            "essential_hazards": self.essential_hazards,
            "checked": self.checked,
        }
        if self.warnings:
            d["warnings"] = list(self.warnings)
        if self.form == "table":
            d["merged_rows"] = self.classes
            d["assignment"] = {"variables": list(self.memories), "codes": dict(self.codes),
                               "state_codes": dict(self.state_codes), **self.assignment}
            d["cover"] = self.cover
        return d


def unique_names(base: list[str], taken: set[str]) -> list[str]:
    """``base`` names made distinct from ``taken`` (and each other) by a numeric suffix."""
    out = []
    for b in base:
        name, i = b, 1
        while name in taken:
            name = f"{b}_{i}"
            i += 1
        taken.add(name)
        out.append(name)
    return out


def spec_of_tables(names: list[str], tables: dict[str, np.ndarray], path: str) -> Spec:
    """Truth tables (0, 1, DC) as a combinational ``Spec``, the minimiser's input."""
    nv = len(names)
    funcs = {}
    for o, t in tables.items():
        funcs[o] = OutputSpec(o, on=[Cube.minterm(int(i), nv) for i in np.flatnonzero(t == 1)],
                              dc=[Cube.minterm(int(i), nv) for i in np.flatnonzero(t == DC)])
    return Spec(path, "fsm", list(names), list(tables), funcs)


def excitation_equations(spec: SeqSpec, exc: Excitation, mem: list[str], opts: SynthOptions,
                         initial: dict[str, int]) -> SeqEquations:
    """Minimise SET, RESET (one kind first, the other with zeros where the first is built on;
    both orders tried) and the outputs; merge into one Equations for the mapper."""
    names = exc.names
    taken = set(names) | set(spec.outputs)
    set_names = dict(zip(mem, unique_names([f"set_{m}" for m in mem], taken)))
    reset_names = dict(zip(mem, unique_names([f"reset_{m}" for m in mem], taken)))
    mopts = replace(opts.minimise, complements=False)
    best = None
    # both orders for a few memories; beyond, SET first (each order costs 2 minimisations)
    for first in ("set", "reset") if len(mem) <= 4 else ("set",):
        a = {(set_names if first == "set" else reset_names)[m]: t
             for m, t in zip(mem, exc.sets if first == "set" else exc.resets)}
        eq_a = minimise(spec_of_tables(names, a, spec.path), mopts) if a else None
        b = {}
        for j, m in enumerate(mem):
            other = (exc.resets if first == "set" else exc.sets)[j].copy()
            built = _built(eq_a, (set_names if first == "set" else reset_names)[m], len(names))
            clash = built & (other == 1)
            if clash.any():
                raise DesignError(f"internal error: SET and RESET of {m} required on together")
            other[built] = 0
            b[(reset_names if first == "set" else set_names)[m]] = other
        eq_b = minimise(spec_of_tables(names, b, spec.path), mopts) if b else None
        lits = (eq_a.literals if eq_a else 0) + (eq_b.literals if eq_b else 0)
        if best is None or lits < best[0]:
            best = (lits, eq_a, eq_b)
    _, eq_a, eq_b = best
    outs = {o: exc.outputs[j] for j, o in enumerate(spec.outputs)}
    eq_z = minimise(spec_of_tables(names, outs, spec.path), opts.minimise)
    eq = merge_equations(names, [e for e in (eq_a, eq_b) if e is not None], eq_z, set_names,
                         reset_names, mem, spec.outputs)
    return SeqEquations(list(spec.inputs), list(spec.outputs), mem, initial, set_names,
                        reset_names, eq, "table")


def _built(eq: Equations | None, name: str, nv: int) -> np.ndarray:
    """Where the function the mapper will build (the hazard-free cover) is on."""
    if eq is None:
        return np.zeros(1 << nv, dtype=bool)
    cover = eq.hazard_free.get(name) or eq.covers[name]
    return eval_cover(cover.cubes, np.arange(1 << nv, dtype=np.int64))


def merge_equations(names, sr_eqs: list[Equations], eq_z: Equations, set_names, reset_names,
                    mem, outputs) -> Equations:
    """SET/RESET and output equations as one ``Equations`` (SETs, RESETs, then outputs), the
    single object the mapper builds."""
    order = [set_names[m] for m in mem] + [reset_names[m] for m in mem] + list(outputs)
    eq = Equations(list(names), order, {})
    for e in [*sr_eqs, eq_z]:
        eq.covers.update(e.covers)
        eq.hazard_free.update(e.hazard_free)
    # SET/RESET are built as the sums of products they are (their don't-cares were spent on
    # S·R = 0); the outputs may use the mapper's complement and XOR forms
    # (XOR forms are left out: their don't-care resolution is not checked for double changes)
    eq.complements.update(eq_z.complements)
    eq.hazard_free_complements.update(eq_z.hazard_free_complements)
    eq.covers = {o: eq.covers[o] for o in order}
    eq.shared_terms = count_shared(eq)
    return eq


def expr_of(se: SeqEquations, name: str) -> ex.Expr:
    return se.eq.expr(name)
