"""The minimiser's time: the hard end of the wall clock, and what comes out when it is hit.

References are independent of mechc's minimiser: each PLA's on and don't-care sets are read
straight from its text (a point is on for an output when an on-row holds it and no
don't-care row of that output does), and the fewest distinct products of a tiny PLA come
from a search over every subset of its multi-output primes, found by listing all 3**n cubes.
"""

from __future__ import annotations

import importlib.util
import itertools
import signal
import threading
import time
from pathlib import Path

import numpy as np
import pytest

from mechc.frontends.pla import parse_pla
from mechc.logic.clock import Clock, WallClockOut, floors_hold, hard_stop
from mechc.logic.cover import min_cover, reduce_dense
from mechc.logic.cubes import Cube, eval_cover
from mechc.passes.minimise import MinimiseOptions, minimise

ROOT = Path(__file__).resolve().parents[1]


def _random_pla_module():
    spec = importlib.util.spec_from_file_location("random_pla",
                                                  ROOT / "benchmarks" / "random_pla.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


random_pla = _random_pla_module()


def pla_sets(text: str) -> tuple[int, np.ndarray, np.ndarray]:
    """(n, on, dc) as (m, 2**n) booleans, read from ``.type fd`` PLA text by hand."""
    lines = [ln for ln in text.splitlines() if ln and not ln.startswith(".")]
    n = int(next(ln.split()[1] for ln in text.splitlines() if ln.startswith(".i ")))
    m = int(next(ln.split()[1] for ln in text.splitlines() if ln.startswith(".o ")))
    on = np.zeros((m, 1 << n), dtype=bool)
    dc = np.zeros((m, 1 << n), dtype=bool)
    pts = np.arange(1 << n)
    for ln in lines:
        cube, outs = ln.split()
        inside = np.ones(1 << n, dtype=bool)
        for k, ch in enumerate(cube):  # input k is bit n-1-k of the point
            bit = (pts >> (n - 1 - k)) & 1
            if ch != "-":
                inside &= bit == int(ch)
        for i, ch in enumerate(outs):
            if ch == "1":
                on[i] |= inside
            elif ch == "-":
                dc[i] |= inside
    return n, on & ~dc, dc


def assert_covers(eq, spec, on: np.ndarray, dc: np.ndarray) -> None:
    """Every output's cover is on at every on-point and off outside on ∪ dc."""
    rows = np.arange(on.shape[1], dtype=np.int64)
    for i, name in enumerate(spec.outputs):
        got = eval_cover(eq.covers[name].cubes, rows)
        assert not (on[i] & ~got).any(), f"{name}: an on-point left out"
        assert not (got & ~(on[i] | dc[i])).any(), f"{name}: an off-point switched on"


def brute_min_products(n: int, on: np.ndarray, dc: np.ndarray) -> int:
    """The fewest distinct products covering every output inside its on ∪ dc, by trying
    every subset of the multi-output primes, smallest first (a minimum cover of primes
    exists: each product can grow to a prime serving the same outputs)."""
    region = on | dc
    m = on.shape[0]
    pts = np.arange(1 << n)
    cubes = []
    for lits in itertools.product((0, 1, 2), repeat=n):
        inside = np.ones(1 << n, dtype=bool)
        for k, v in enumerate(lits):
            if v != 2:
                inside &= ((pts >> (n - 1 - k)) & 1) == v
        outs = frozenset(i for i in range(m) if region[i][inside].all())
        if outs:
            cubes.append((lits, outs, inside))

    def grows(a, b) -> bool:  # b holds a (every literal of b is one of a's)
        return all(y == 2 or x == y for x, y in zip(a, b))

    primes = [(outs, inside) for lits, outs, inside in cubes
              if not any(o2 >= outs and l2 != lits and grows(lits, l2)
                         for l2, o2, _ in cubes)]
    need = [on[i] for i in range(m)]
    for k in range(0, len(primes) + 1):
        for pick in itertools.combinations(primes, k):
            if all(not (need[i] & ~np.logical_or.reduce(
                    [ins for outs, ins in pick if i in outs] or [np.zeros(1 << n, bool)])).any()
                   for i in range(m)):
                return k
    raise AssertionError("no cover")


@pytest.mark.parametrize("seed", range(8))
def test_tiny_random_plas_reach_the_brute_force_minimum(seed):
    rng = np.random.default_rng(500 + seed)
    n, m = int(rng.integers(3, 5)), int(rng.integers(2, 4))
    text = random_pla.random_pla(rng, n, m, int(rng.integers(3, 7)), dc_rows=0.25)
    spec = parse_pla(text)
    n2, on, dc = pla_sets(text)
    eq = minimise(spec)
    assert_covers(eq, spec, on, dc)
    best = brute_min_products(n2, on, dc)
    assert eq.products >= best  # a check of the brute force as much as of mechc
    if eq.proven:
        assert eq.products == best
    else:
        assert eq.products <= best + 1


@pytest.mark.parametrize("seed", range(6))
def test_random_mcnc_shaped_plas_are_covered_on_every_vector(seed):
    rng = np.random.default_rng(900 + seed)
    n, m = int(rng.integers(6, 10)), int(rng.integers(3, 12))
    text = random_pla.random_pla(rng, n, m, int(rng.integers(10, 80)))
    spec = parse_pla(text)
    _, on, dc = pla_sets(text)
    eq = minimise(spec)
    assert_covers(eq, spec, on, dc)
    rows = len([ln for ln in text.splitlines() if ln and not ln.startswith(".")])
    assert eq.products <= rows  # the PLA's own rows are a cover


def test_random_pla_generator_is_seeded_and_feeds_every_output():
    a = random_pla.random_set(3, 7)
    assert a == random_pla.random_set(3, 7)
    for _name, text in a:
        outs = [ln.split()[1] for ln in text.splitlines() if ln and not ln.startswith(".")]
        assert all(any(o[j] == "1" for o in outs) for j in range(len(outs[0])))


def test_the_hard_end_stops_a_hard_case_and_says_so():
    """A 12-input, 30-output PLA that takes seconds of CPU, given 1.5 s of wall clock:
    the call ends soon after, every cover is still right, and the cut is named."""
    rng = np.random.default_rng(4242)
    text = random_pla.random_pla(rng, 12, 30, 400, free=0.45)
    spec = parse_pla(text)
    _, on, dc = pla_sets(text)
    t0 = time.perf_counter()
    eq = minimise(spec, MinimiseOptions(wall_limit=1.5))
    took = time.perf_counter() - t0
    assert took < 1.5 + 2.5, took  # the check and the cut step's exit come after the end
    assert_covers(eq, spec, on, dc)
    assert any("wall clock" in s for s in eq.time_limited), eq.time_limited
    # a cut of an output's own cover ("cover of NAME") takes the proof of its minimality
    # away; a cut of a step after the own covers (sharing products between outputs, the
    # mapper's alternatives, consensus terms) leaves each own cover as proven as it was
    own = [s for s in eq.time_limited if s.startswith("cover of ")]
    if own:
        assert not eq.proven, eq.time_limited


def test_without_a_hard_end_nothing_is_cut_by_the_wall_clock():
    rng = np.random.default_rng(4243)
    text = random_pla.random_pla(rng, 6, 4, 20)
    eq = minimise(parse_pla(text), MinimiseOptions(wall_limit=None))
    assert not any("wall clock" in s for s in eq.time_limited)


def test_hard_stop_raises_inside_the_body_and_restores_the_signal():
    before = signal.getsignal(signal.SIGALRM)
    t0 = time.perf_counter()
    with pytest.raises(WallClockOut):
        with hard_stop(t0 + 0.2) as armed:
            assert armed
            while True:  # pure Python: the alarm lands between bytecodes
                pass
    assert 0.15 < time.perf_counter() - t0 < 1.5
    assert signal.getsignal(signal.SIGALRM) == before
    assert signal.getitimer(signal.ITIMER_REAL)[0] == 0.0
    with hard_stop(time.perf_counter() + 0.2):  # a body that ends in time is not stopped
        x = sum(range(1000))
    time.sleep(0.3)
    assert x == 499500


def test_hard_stop_off_the_main_thread_is_not_armed():
    got = []

    def body():
        with hard_stop(time.perf_counter() + 0.05) as armed:
            got.append(armed)
            time.sleep(0.1)
            got.append(floors_hold())

    t = threading.Thread(target=body)
    t.start()
    t.join()
    assert got == [False, False]  # not armed, but work floors still give way near the end


def test_clock_never_hands_out_more_than_the_wall_clock_left():
    c = Clock(budget=100.0, wall=0.5)
    assert c.left() <= 0.5
    assert c.cap(10.0) <= 0.5
    time.sleep(0.55)
    assert c.left() == 0.0 and c.cap(10.0) == 0.0
    assert c.floor(0.3) == 0.05
    assert Clock(None, None).left() == float("inf")


def test_min_cover_without_time_is_a_greedy_cover():
    n = 6
    rng = np.random.default_rng(3)
    on = np.flatnonzero(rng.random(1 << n) < 0.5).astype(np.int64)
    masks = np.full(len(on), (1 << n) - 1, dtype=np.int64)  # the minterms themselves
    res = min_cover(masks, on.copy(), on, np.zeros(0, dtype=np.int64), n, 0.0)
    assert res.method == "greedy" and not res.proven
    cubes = [Cube(int(masks[k]), int(on[k])) for k in res.chosen]
    assert eval_cover(cubes, on).all()


def test_reduce_dense_past_its_deadline_keeps_the_same_problem():
    """Stopped at once, the reduction returns the problem unreduced (every row, every
    column): still the same covering problem."""
    from scipy import sparse
    rng = np.random.default_rng(11)
    A = sparse.csr_matrix(rng.random((60, 30)) < 0.2)
    A = A[np.flatnonzero(np.asarray(A.sum(axis=1)).ravel() > 0)]
    forced, rows, cols = reduce_dense(A, np.ones(30), deadline=time.perf_counter() - 1)
    covered = np.zeros(A.shape[0], dtype=bool)
    covered[np.flatnonzero(np.asarray(A[:, forced].sum(axis=1)).ravel() > 0)] = True
    assert set(rows.tolist()) | set(np.flatnonzero(covered).tolist()) == set(range(A.shape[0]))
    assert len(cols) + len(forced) >= 1


@pytest.mark.parametrize("seed", range(6))
def test_quick_multi_cover_is_right_on_every_vector(seed):
    """The cover kept in hand for a stopped multi-output step: each output's cubes switch
    on every on-point and nothing outside on ∪ dc (references read from the PLA text), with
    no more products than the PLA's rows it starts from."""
    from mechc.logic.quick_multi import quick_multi_cover
    rng = np.random.default_rng(1300 + seed)
    n, m = int(rng.integers(5, 10)), int(rng.integers(2, 15))
    text = random_pla.random_pla(rng, n, m, int(rng.integers(10, 120)))
    spec = parse_pla(text)
    _, on, dc = pla_sets(text)
    rows_cover = [spec.functions[o].on for o in spec.outputs]
    got = quick_multi_cover(n, on, on | dc, [rows_cover])
    pts = np.arange(1 << n, dtype=np.int64)
    for i in range(m):
        val = eval_cover(got[i], pts)
        assert not (on[i] & ~val).any() and not (val & ~(on[i] | dc[i])).any()
    distinct = {c for cubes in got for c in cubes}
    assert len(distinct) <= len({c for cubes in rows_cover for c in cubes})
    if n <= 4:
        assert len(distinct) >= brute_min_products(n, on, dc)
