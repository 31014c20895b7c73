"""Algebraic factoring of hazard-free covers (passes/factor.py) and the ternary check
(passes/ternary.py): on random functions the factored netlist computes the spec wherever it is
specified, and has no static hazard (the distributive law keeps hazard freedom), checked by
brute force over every single-input change; a BLIF network's kept structure re-reads to the
same functions."""

from __future__ import annotations

import numpy as np
import pytest

from mechc.cells.library import load_library
from mechc.frontends.blif import parse_blif
from mechc.frontends.boolfile import parse_bool
from mechc.logic.cubes import DC, input_matrix
from mechc.passes.factor import factored_netlist
from mechc.passes.map import MapOptions, map_equations
from mechc.passes.minimise import MinimiseOptions, minimise
from mechc.passes.ternary import static_hazards
from tests.helpers import EXAMPLES, bool_text, random_table
from tests.spec_formats.test_blif import ripple_adder_blif

LIB = load_library()


@pytest.mark.parametrize("p_dc", [0.0, 0.1])
@pytest.mark.parametrize("seed", range(6))
def test_factored_covers_compute_the_spec_without_hazards(seed, p_dc):
    """Fully specified functions: no static hazard at all. With don't-cares the check judges
    the completed function, changes through a don't-care included, which the minimiser's
    hazard-free covers do not promise: there the factored netlist must have none the
    two-level one does not have."""
    rng = np.random.default_rng(seed)
    n = 5
    names = [f"x{i}" for i in range(n)]
    tables = {f"f{j}": random_table(rng, n, p_dc=p_dc) for j in range(2)}
    spec = parse_bool(bool_text(names, tables), "r.bool")
    eq = minimise(spec, MinimiseOptions())
    nl = factored_netlist(eq, LIB, MapOptions())
    m = input_matrix(n)
    vals = nl.evaluate({x: m[k] for k, x in enumerate(names)})
    for o, t in tables.items():
        got = vals[nl.outputs[o]]
        care = t != 2
        assert np.array_equal(got[care], t[care] == 1), o
    found = static_hazards(nl)
    if p_dc == 0.0:
        assert found == {}
    else:
        flat = static_hazards(map_equations(eq, LIB, MapOptions()).netlist)
        assert all(found[o] <= flat.get(o, 0) for o in found), (found, flat)
    depth = nl.depth()
    assert depth and max(depth.values()) >= 1


def test_blif_structure_rereads_to_the_same_functions():
    for text, path in ((ripple_adder_blif(3), "r.blif"),
                       ((EXAMPLES / "full_adder_net.blif").read_text(), "fa.blif")):
        spec = parse_blif(text, path)
        again = parse_blif(spec.structure, "structure.blif")
        assert again.inputs == spec.inputs and again.outputs == spec.outputs
        for o in spec.outputs:
            assert np.array_equal(again.table(o), spec.table(o)), o
            assert DC not in spec.table(o)
        assert spec.structure.count(".names") >= len(spec.outputs)
