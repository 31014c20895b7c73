"""The exact minimiser: primes against brute force, covers against brute force and sympy."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
import sympy
from sympy.logic import SOPform

from mechc.frontends.boolfile import parse_bool
from mechc.ir.spec import OutputSpec, Spec
from mechc.logic.cubes import DC, Cube, eval_cover
from mechc.logic.primes import prime_implicants
from mechc.passes.minimise import MinimiseOptions, minimise
from tests.helpers import random_table


def spec_from_tables(tables: dict[str, np.ndarray], n: int) -> Spec:
    inputs = [f"x{i}" for i in range(n)]
    funcs = {}
    for name, t in tables.items():
        funcs[name] = OutputSpec(name, on=[Cube.minterm(int(m), n) for m in np.flatnonzero(t == 1)],
                                 dc=[Cube.minterm(int(m), n) for m in np.flatnonzero(t == DC)])
    return Spec("random", "bool", inputs, list(tables), funcs)


def brute_primes(region: np.ndarray, n: int) -> set[tuple[int, int]]:
    """Every cube inside the region, keep those not inside a cube with one literal fewer."""
    idx = np.arange(1 << n)
    imps = set()
    for lits in itertools.product((0, 1, 2), repeat=n):  # 2 = variable absent
        mask = sum(1 << (n - 1 - k) for k, v in enumerate(lits) if v != 2)
        val = sum(1 << (n - 1 - k) for k, v in enumerate(lits) if v == 1)
        if region[(idx & mask) == val].all():
            imps.add((mask, val))
    return {(m, v) for m, v in imps
            if not any((m & ~(1 << b), v & ~(1 << b)) in imps for b in range(n) if m >> b & 1)}


@pytest.mark.parametrize("seed", range(40))
def test_primes_match_brute_force(seed):
    rng = np.random.default_rng(seed)
    n = int(rng.integers(1, 6))
    region = rng.random(1 << n) < rng.random()
    m, v = prime_implicants(region)
    assert set(zip(m.tolist(), v.tolist())) == brute_primes(region, n)


def brute_min_cost(table: np.ndarray, n: int) -> tuple[int, int]:
    """Minimum (terms, literals) over all covers by primes, by exhaustive search."""
    on = np.flatnonzero(table == 1)
    if len(on) == 0:
        return (0, 0)
    primes = sorted(brute_primes(table != 0, n), key=lambda p: bin(p[0]).count("1"))
    cov = [frozenset(int(x) for x in on if (x & m) == v) for m, v in primes]
    need = frozenset(int(x) for x in on)
    for k in range(1, len(primes) + 1):
        best = None
        for combo in itertools.combinations(range(len(primes)), k):
            if frozenset().union(*(cov[i] for i in combo)) >= need:
                lits = sum(bin(primes[i][0]).count("1") for i in combo)
                best = lits if best is None else min(best, lits)
        if best is not None:
            return (k, best)
    raise AssertionError


@pytest.mark.parametrize("seed", range(25))
def test_cover_is_minimum_terms_then_literals(seed):
    rng = np.random.default_rng(100 + seed)
    n = int(rng.integers(2, 5))
    t = random_table(rng, n, p_on=0.45, p_dc=0.15)
    eq = minimise(spec_from_tables({"f": t}, n), MinimiseOptions(complements=False))
    c = eq.covers["f"]
    assert c.proven
    assert (c.terms, c.literals) == brute_min_cost(t, n)


def sop_cost(expr) -> tuple[int, int]:
    if expr in (sympy.true, sympy.false):
        return (0 if expr == sympy.false else 1, 0)
    terms = expr.args if isinstance(expr, sympy.Or) else (expr,)
    lits = sum(len(t.args) if isinstance(t, sympy.And) else 1 for t in terms)
    return len(terms), lits


@pytest.mark.parametrize("seed", range(30))
def test_random_specs_equivalent_and_no_worse_than_sopform(seed):
    """4-10 inputs, 1-4 outputs, with don't-cares: every care row right (checked here by direct
    evaluation of the printed equation with sympy, independently of mechc's own verifier), and
    literal counts no worse than sympy's SOPform (run where it is fast: n <= 7). SOPform
    minimises each output alone, so the comparison is with the per-output minimiser
    (``multi_output=False``); the multi-output covers are checked in test_multi_output.py."""
    rng = np.random.default_rng(1000 + seed)
    n = int(rng.integers(4, 11))
    m = int(rng.integers(1, 5))
    tables = {f"f{j}": random_table(rng, n, p_on=float(rng.uniform(0.1, 0.6)),
                                    p_dc=float(rng.uniform(0, 0.25))) for j in range(m)}
    spec = spec_from_tables(tables, n)
    eq = minimise(spec, MinimiseOptions(time_limit=4, alt_time_limit=1, multi_output=False))
    syms = sympy.symbols(spec.inputs)
    env = dict(zip(spec.inputs, syms))
    from mechc.ir import expr as ex

    rows = np.arange(1 << n)
    for name, t in tables.items():
        care = t != DC
        got = eval_cover(eq.covers[name].cubes, rows)
        assert (got[care] == (t[care] == 1)).all()
        # the printed equation means the same thing (sympy evaluation on a sample of rows)
        f = sympy.lambdify(syms, ex.to_sympy(eq.expr(name), env), "numpy")
        sample = rows[care][:64]
        bits = [((sample >> (n - 1 - k)) & 1).astype(bool) for k in range(n)]
        vals = np.broadcast_to(np.asarray(f(*bits), dtype=bool), sample.shape)
        assert (vals == (t[sample] == 1)).all()
        if n <= 7:
            on = [list(map(int, format(int(x), f"0{n}b"))) for x in np.flatnonzero(t == 1)]
            dc = [list(map(int, format(int(x), f"0{n}b"))) for x in np.flatnonzero(t == DC)]
            ref = SOPform(syms, on, dc)
            c = eq.covers[name]
            if c.proven:
                assert (c.terms, c.literals) <= sop_cost(ref)
                assert c.literals <= sop_cost(ref)[1] or c.terms < sop_cost(ref)[0]


def test_sorter_minimum_is_the_dissertations_equation():
    spec = parse_bool(open("examples/sorter.bool").read(), "sorter.bool")
    eq = minimise(spec)
    rows = np.arange(16)
    got = eval_cover(eq.covers["Z"].cubes, rows)
    a, b, c, d = [(rows >> (3 - k)) & 1 for k in range(4)]
    want = (c & d) | (a & (1 - b) & d) | ((1 - a) & b & c)
    assert (got == want.astype(bool)).all()  # on all 16 rows, don't-cares included
    assert eq.covers["Z"].proven and eq.covers["Z"].literals == 8


def test_shared_terms_between_outputs():
    # f = ab + c, g = ab + d: the term ab is prime for both and is shared
    spec = parse_bool("inputs a b c d\noutputs f g\nf = a & b | c\ng = a & b | d\n")
    eq = minimise(spec)
    assert eq.shared_terms == 1


def test_constant_functions():
    spec = parse_bool("inputs a b\noutputs z o\nz = minterms()\no = minterms(0,1,2,3)\n")
    eq = minimise(spec)
    assert eq.covers["z"].cubes == []
    assert eq.covers["o"].cubes == [Cube(0, 0)]


def test_time_limit_reports_not_proven():
    rng = np.random.default_rng(7)
    t = random_table(rng, 12, p_on=0.45, p_dc=0.1)
    eq = minimise(spec_from_tables({"f": t}, 12), MinimiseOptions(time_limit=0.2,
                                                                   complements=False))
    c = eq.covers["f"]
    assert not c.proven
    rows = np.arange(1 << 12)
    care = t != DC
    assert (eval_cover(c.cubes, rows)[care] == (t[care] == 1)).all()


def test_too_many_primes_falls_back_to_expansion_and_stays_correct():
    rng = np.random.default_rng(3)
    t = random_table(rng, 10, p_on=0.5, p_dc=0.1)
    eq = minimise(spec_from_tables({"f": t}, 10), MinimiseOptions(prime_limit=50,
                                                                   complements=False))
    c = eq.covers["f"]
    assert c.method == "expand" and not c.proven
    rows = np.arange(1 << 10)
    care = t != DC
    assert (eval_cover(c.cubes, rows)[care] == (t[care] == 1)).all()


def test_wide_complement_is_cubes_not_minterms():
    """The complement of a two-literal product of 15 inputs (24576 minterms) is the two
    one-literal cubes: it used to come back as thousands of minterms (espresso's time ran out
    before EXPAND merged them), and mapping that took minutes and gigabytes."""
    from mechc.frontends.pla import parse_pla

    n = 15
    spec = parse_pla(f".i {n}\n.o 1\n1-------1------ 1\n.e\n", "wide.pla")
    eq = minimise(spec, MinimiseOptions(wall_limit=None))  # complements kept under load
    pts = np.arange(1 << n, dtype=np.int64)
    want = ~(((pts >> (n - 1)) & 1).astype(bool) & ((pts >> (n - 9)) & 1).astype(bool))
    for cover in (eq.complements["f0"], eq.hazard_free_complements["f0"]):
        assert len(cover.cubes) == 2
        got = np.zeros(1 << n, dtype=bool)
        for c in cover.cubes:
            got |= (pts & c.mask) == c.value
        assert np.array_equal(got, want)


def test_mapper_builds_whichever_covers_cost_fewer_parts():
    """Multi-output covers travel with the per-output ones as an alternative; the mapper keeps
    the design with fewer parts (each mapped alone here as the reference) and says which
    equations it built."""
    from dataclasses import replace

    from mechc.cells.library import load_library
    from mechc.frontends.pla import parse_pla_file
    from mechc.passes.map import map_equations

    lib = load_library()

    def parts(m):
        return sum(lib[c.cell].cost(len(c.inputs)) for c in m.netlist.cells.values())

    spec = parse_pla_file("tests/logic/pla/square5.pla")
    eq = minimise(spec)
    assert eq.alternative is not None
    alone = parts(map_equations(replace(eq, alternative=None), lib))
    other = parts(map_equations(eq.alternative, lib))
    got = map_equations(eq, lib)
    assert parts(got) == min(alone, other)
    assert (got.equations is eq.alternative) == (other < alone)


@pytest.mark.parametrize("seed", range(3))
def test_covers_from_the_shared_table_are_correct_and_hazard_free(seed):
    """Every output's primes come from one ternary table: each cover (and the complement's,
    past 8 inputs by espresso) is checked here against the table on every row, and every
    hazard-free cover holds each pair of adjacent care-1 rows inside one cube (enumerated
    here, not by the minimiser's own routine)."""
    rng = np.random.default_rng(4400 + seed)
    n = 9
    tables = {f"f{i}": random_table(rng, n, p_on=0.45, p_dc=0.15) for i in range(3)}
    # no hard end: under load it may leave complements out, and this is about correctness
    eq = minimise(spec_from_tables(tables, n), MinimiseOptions(wall_limit=None))
    rows = np.arange(1 << n)
    for name, t in tables.items():
        care = t != DC
        for cover, want in ((eq.covers[name], t == 1),
                            (eq.complements[name], t == 0),
                            (eq.hazard_free_complements[name], t == 0),
                            (eq.hazard_free[name], t == 1)):
            assert (eval_cover(cover.cubes, rows)[care] == want[care]).all()
        for cover, want in ((eq.hazard_free_complements[name], t == 0),
                            (eq.hazard_free[name], t == 1)):
            for x in range(1 << n):
                for b in range(n):
                    y = x | (1 << b)
                    if y == x or not (want[x] and want[y]):
                        continue
                    assert any((x & c.mask) == c.value and (y & c.mask) == c.value
                               for c in cover.cubes), (name, x, y)


def test_budget_cuts_are_reported_and_covers_stay_correct():
    """With almost no budget left for them the per-output covers run on the smallest time
    limit: every cover that is not proven minimal is named in ``time_limited`` (nothing is
    reported as a minimum that was not proven) and every cover is still right on every
    row; without a budget the same spec's covers are proven, and none has fewer terms."""
    rng = np.random.default_rng(515)
    n = 9
    tables = {f"f{i}": random_table(rng, n, p_on=0.45, p_dc=0.1) for i in range(3)}
    spec = spec_from_tables(tables, n)
    cut = minimise(spec, MinimiseOptions(budget=1e-3, complements=False, multi_output=False,
                                         hazard_free=False))
    full = minimise(spec, MinimiseOptions(budget=None, complements=False, multi_output=False,
                                          hazard_free=False))
    rows = np.arange(1 << n)
    for name, t in tables.items():
        care = t != DC
        c = cut.covers[name]
        assert (eval_cover(c.cubes, rows)[care] == (t[care] == 1)).all()
        if not c.proven:
            assert f"cover of {name}" in cut.time_limited
        assert full.covers[name].proven
        assert full.covers[name].terms <= c.terms
