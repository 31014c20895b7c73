"""Wide PLAs (22-70 inputs, beyond the truth-table limit) compile end to end, and the netlist,
evaluated from the JSON cells alone by the evaluator below, agrees with the spec's cubes on
every point of every spec cube and on random vectors. The spec is evaluated here from its
rows, independently of mechc's parser-side model and of the minimiser."""

from __future__ import annotations

import json
from functools import reduce

import numpy as np
import pytest

TYPES = {
    "AND": lambda a: reduce(np.logical_and, a),
    "OR": lambda a: reduce(np.logical_or, a),
    "NAND": lambda a: ~reduce(np.logical_and, a),
    "NOR": lambda a: ~reduce(np.logical_or, a),
    "NOT": lambda a: ~a[0],
    "AND_NOT": lambda a: a[0] & ~a[1],
    "OR_NOT": lambda a: a[0] | ~a[1],
    "XOR": lambda a: reduce(np.logical_xor, a),
    "XNOR": lambda a: ~reduce(np.logical_xor, a),
}


def eval_cells(design: dict, vectors: list[int], n: int) -> dict[str, np.ndarray]:
    """Output values for each vector (input k is bit n-1-k), from the cell list only."""
    nets = {name: np.array([(x >> (n - 1 - k)) & 1 for x in vectors], dtype=bool)
            for k, name in enumerate(design["inputs"])}
    pending = list(design["cells"])
    while pending:
        later = []
        for c in pending:
            if not all(i in nets for i in c["inputs"]):
                later.append(c)
                continue
            args = [nets[i] for i in c["inputs"]]
            if c["type"] == "CONST":
                out = np.full(len(vectors), bool(c["params"]["value"]))
            elif c["params"].get("logic") in ("identity", "invert"):
                out = args[0] if c["params"]["logic"] == "identity" else ~args[0]
            else:
                out = TYPES[c["type"]](args)
            nets[c["outputs"][0]] = out
        assert len(later) < len(pending), "cells with undriven inputs"
        pending = later
    return {o: nets[net] for o, net in design["outputs"].items()}


def cube_text(mask: int, value: int, n: int) -> str:
    return "".join("-" if not mask >> (n - 1 - k) & 1 else
                   ("1" if value >> (n - 1 - k) & 1 else "0") for k in range(n))


def make_pla(rng: np.random.Generator, n: int, m: int, kind: str):
    """A PLA with structure to minimise: clusters of on-cubes around a few seeds (neighbours
    differ in a literal or two, so they merge), don't-care cubes nearby, and for type fr an
    explicit off-set drawn away from each output's on/dc cubes. Every cube has at most 9 free
    inputs, so its points can all be checked."""
    rows: list[tuple[int, int, str]] = []  # (mask, value, output characters)
    spec = {j: {"on": [], "dc": [], "off": []} for j in range(m)}
    full = (1 << n) - 1

    def near(mask, value, flips):
        for b in rng.choice(n, size=flips, replace=False).tolist():
            bit = 1 << b
            if mask & bit and rng.random() < 0.5:
                value ^= bit
            else:
                mask |= bit
                value = (value & ~bit) | (bit if rng.random() < 0.5 else 0)
        return mask, value

    for j in range(m):
        for _ in range(3):
            free = rng.choice(n, size=int(rng.integers(5, 9)), replace=False)
            mask = full & ~sum(1 << int(b) for b in free)
            value = int(rng.integers(0, 1 << 62)) & mask
            for _ in range(int(rng.integers(4, 9))):
                cm, cv = near(mask, value, int(rng.integers(1, 3)))
                spec[j]["on"].append((cm, cv))
            cm, cv = near(mask, value, 2)
            spec[j]["dc"].append((cm, cv))
        if kind == "fr":
            mine = spec[j]["on"] + spec[j]["dc"]
            while len(spec[j]["off"]) < 12:
                free = rng.choice(n, size=int(rng.integers(3, 9)), replace=False)
                om = full & ~sum(1 << int(b) for b in free)
                ov = (int(rng.integers(0, 1 << 62)) | int(rng.integers(0, 1 << 62)) << 62) & om
                if all(((ov ^ v) & om & m_) for m_, v in mine):  # disjoint from on and dc
                    spec[j]["off"].append((om, ov))
    for j in range(m):
        for key, ch in (("on", "1"), ("dc", "-"), ("off", "0")):
            for cm, cv in spec[j][key]:
                rows.append((cm, cv, "".join(ch if i == j else "~" for i in range(m))))
    order = rng.permutation(len(rows))
    lines = [f".i {n}", f".o {m}", f".type {kind}"]
    lines += [f"{cube_text(*rows[i][:2], n)} {rows[i][2]}" for i in order]
    return "\n".join(lines + [".e"]) + "\n", spec


def spec_value(spec_j: dict, x: int, rest: int) -> int:
    """2 = don't care; dc over on over off, as espresso reads a PLA."""
    if any(x & m == v for m, v in spec_j["dc"]):
        return 2
    if any(x & m == v for m, v in spec_j["on"]):
        return 1
    if any(x & m == v for m, v in spec_j["off"]):
        return 0
    return rest


def cube_points(mask: int, value: int, n: int) -> list[int]:
    pts = [value]
    for b in range(n):
        if not mask >> b & 1:
            pts += [p | 1 << b for p in pts]
    return pts


def check_design(design: dict, spec: dict, n: int, rest: int, rng) -> int:
    """Every point of every spec cube, the neighbours (one literal flipped) of three corners of
    each, and 4096 random vectors."""
    vectors = set()
    full = (1 << n) - 1
    for s in spec.values():
        for m, v in s["on"] + s["dc"] + s["off"]:
            vectors.update(cube_points(m, v, n))
            for corner in (v, v | (full & ~m), v | (int.from_bytes(rng.bytes(9), "little")
                                                    & full & ~m)):
                vectors.update(corner ^ (1 << b) for b in range(n) if m >> b & 1)
    vectors.update(int.from_bytes(rng.bytes(8), "little") & ((1 << n) - 1) for _ in range(4096))
    vectors = sorted(vectors)
    got = eval_cells(design, vectors, n)
    names = list(design["outputs"])
    cared = 0
    for j, s in spec.items():
        for x, g in zip(vectors, got[names[j]].tolist()):
            want = spec_value(s, x, rest)
            if want != 2:
                assert g == bool(want), f"output {names[j]} wrong at {x:0{n}b}"
                cared += 1
    return cared


# Wide PLAs fan each input out to dozens of cells, more than the default 50 N actuator moves;
# the mechanism's force check is not the subject here, so the actuators are made strong enough.
COMPILE = ("--time-limit", "5", "--actuator-force", "1000")


@pytest.mark.parametrize("n,m,kind,seed", [(22, 2, "fd", 1), (30, 1, "fr", 2), (33, 3, "fd", 3),
                                           (40, 2, "fr", 4), (70, 2, "fd", 5)])
def test_wide_pla_compiles_and_matches_its_cubes(cli, tmp_path, n, m, kind, seed):
    rng = np.random.default_rng(seed)
    text, spec = make_pla(rng, n, m, kind)
    src = tmp_path / "wide.pla"
    src.write_text(text)
    out = tmp_path / "wide.json"
    code, _stdout, err = cli("compile", src, "-o", out, *COMPILE)
    assert code == 0, err
    design = json.loads(out.read_text())
    rest = 2 if kind == "fr" else 0
    assert check_design(design, spec, n, rest, rng) > 1000
    stats = design["stats"]["minimisation"]
    assert stats["proven"] is False
    assert {o["method"] for o in stats["outputs"].values()} == {"espresso"}
    # minimisation did something: fewer terms than the spec's on-cubes
    assert design["stats"]["terms"] < sum(len(s["on"]) for s in spec.values())


@pytest.mark.parametrize("n,seed", [(65, 6), (117, 9)])
def test_wide_logic_stages_beyond_64_inputs(n, seed):
    """Two- and three-word cubes through parse, minimise, map and the JSON cell list."""
    from mechc.cells.library import load_library
    from mechc.frontends.pla import parse_pla
    from mechc.passes.map import map_equations
    from mechc.passes.minimise import minimise

    rng = np.random.default_rng(seed)
    text, spec = make_pla(rng, n, 2, "fd")
    eq = minimise(parse_pla(text, "wide.pla"))
    nl = map_equations(eq, load_library(())).netlist
    design = {"inputs": nl.inputs, "outputs": nl.outputs,
              "cells": [c.to_json() for c in nl.cells.values()]}
    assert check_design(design, spec, n, 0, rng) > 1000
    assert eq.terms < sum(len(s["on"]) for s in spec.values())


def test_sampled_proof_reports_itself_and_catches_a_changed_spec(cli, tmp_path):
    rng = np.random.default_rng(7)
    text, spec = make_pla(rng, 30, 2, "fr")
    src = tmp_path / "w.pla"
    src.write_text(text)
    out = tmp_path / "w.json"
    assert cli("compile", src, "-o", out, *COMPILE)[0] == 0
    report = tmp_path / "r.json"
    code, stdout, _ = cli("simulate", out, "--level", "logic", "--logic-method", "sampled",
                          "--report", report)
    r = json.loads(report.read_text())
    assert code == 0 and r["passed"] and r["exhaustive"] is False and r["method"] == "sampled"
    points = {p for s in spec.values() for m, v in s["on"] + s["dc"] + s["off"]
              for p in cube_points(m, v, 30)}
    # every cube has <= 9 free inputs: all its points are enumerated, neighbours come on top
    assert r["sampling"]["cube_vectors"] > len(points)
    assert r["cases"] > len(points) + (1 << 15)
    # one on-cube of output 0 turned into an off-cube: its points now contradict the design
    lines = text.splitlines()
    k = next(i for i, ln in enumerate(lines) if ln.endswith(" 1~"))
    lines[k] = lines[k][:-2] + "0~"
    bad = tmp_path / "bad.pla"
    bad.write_text("\n".join(lines) + "\n")
    for method in ("sampled", "sat"):
        code, _, _ = cli("simulate", out, "--level", "logic", "--spec", bad, "--report", report,
                         "--logic-method", method)
        r = json.loads(report.read_text())
        assert code != 0 and not r["passed"] and r["failure_count"] > 0
        f = r["failures"][0]
        assert f["output"] == "f0" and f["expected"] == 0 and f["got"] == 1
        # the vector lies in the cube turned off (and in no dc cube of f0's)
        row = lines[k].split()[0]
        assert all(c == "-" or int(c) == f["inputs"][f"x{i}"] for i, c in enumerate(row))


def test_sampled_proof_catches_a_netlist_that_lost_a_literal(cli, tmp_path):
    """Type fd: the points where a dropped literal shows are just outside the on-cubes, which
    only the neighbour vectors reach (random vectors almost never fall there)."""
    rng = np.random.default_rng(8)
    text, _spec = make_pla(rng, 28, 1, "fd")
    src = tmp_path / "w.pla"
    src.write_text(text)
    out = tmp_path / "w.json"
    # --no-prove: this design has a static-1 hazard (f0 dips to mid-stroke when x8 moves at
    # one vector) that the kinematic proof's changes chosen to switch every cell find and
    # compile then refuses; the subject here is the logic level
    assert cli("compile", src, "-o", out, *COMPILE, "--no-prove")[0] == 0
    assert cli("simulate", out, "--level", "logic")[0] == 0
    code, stdout, _ = cli("simulate", out, "--level", "kinematic")
    assert code == 1 and "dwell: x8 moving output f0 (expected 1)" in stdout
    design = json.loads(out.read_text())
    cell = next(c for c in design["cells"] if c["type"] == "AND" and len(c["inputs"]) >= 3)
    cell["inputs"] = cell["inputs"][1:]
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps(design))
    report = tmp_path / "r.json"
    for method in ("sampled", "sat"):
        code, _, _ = cli("simulate", bad, "--level", "logic", "--report", report,
                         "--logic-method", method)
        r = json.loads(report.read_text())
        assert code != 0 and not r["passed"] and r["exhaustive"] is False
        assert r["method"] == method
        assert all(f["expected"] == 0 and f["got"] == 1 for f in r["failures"])


def test_wide_pla_proved_by_sat_by_default(cli, tmp_path):
    """Beyond the truth-table limit compile and simulate prove by a SAT miter, and say so."""
    rng = np.random.default_rng(11)
    text, _spec = make_pla(rng, 30, 2, "fr")
    src = tmp_path / "w.pla"
    src.write_text(text)
    out = tmp_path / "w.json"
    code, stdout, _ = cli("compile", src, "-o", out, *COMPILE)
    assert code == 0 and "logic proof: proved, all 2^30 vectors by a SAT miter" in stdout
    report = tmp_path / "r.json"
    code, stdout, _ = cli("simulate", out, "--level", "logic", "--report", report)
    r = json.loads(report.read_text())
    assert code == 0 and r["passed"] and r["method"] == "sat" and r["complete"]
    assert r["cases"] == 1 << 30 and "SAT miter" in stdout
