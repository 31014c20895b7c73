"""The sequential dynamic proof's walks cut into pieces (``split_walks``) so that processes share
them evenly: every change of every walk is taken once, from the stable state the walk is in
there, and a proof cut finer gives the serial figures case by case on several processes."""

from __future__ import annotations

import itertools
from collections import deque

import pytest

from mechc.cells.library import load_library
from mechc.frontends.fsm import parse_fsm_file
from mechc.ir.seqspec import stable_graph
from mechc.pipeline import compile_spec
from mechc.proofs.parallel import longest_first
from mechc.proofs.seq_logic import expected_after, split_walks, transition_tour
from mechc.proofs.seq_mechanism import prove_sequential_dynamic
from tests.helpers import EXAMPLES

LIB = load_library()
FSMS = ["speedctl", "speedctl_sr", "toggle", "gated_latch", "sequence_detector"]


def _replay(g, spec, seq) -> list:
    """Stable states along ``seq`` on the stable graph's own edges (not the proof's walker)."""
    n = spec.n
    node = g.initial
    out = [node]
    for d in seq[1:]:
        x2 = sum(d[nm] << (n - 1 - k) for k, nm in enumerate(spec.inputs))
        node = dict(g.edges[node])[x2]
        out.append(node)
    return out


def _distances(g) -> dict:
    """Fewest specified changes from power-up to each stable state (breadth first)."""
    dist = {g.initial: 0}
    todo = deque([g.initial])
    while todo:
        u = todo.popleft()
        for _x2, v in g.edges[u]:
            if v not in dist:
                dist[v] = dist[u] + 1
                todo.append(v)
    return dist


@pytest.mark.parametrize("cap", [2, 3, None])
@pytest.mark.parametrize("name", FSMS)
def test_pieces_take_every_change_once_from_the_walks_own_state(name, cap):
    spec = parse_fsm_file(str(EXAMPLES / f"{name}.fsm"))
    g = stable_graph(spec)
    dist = _distances(g)
    walks = transition_tour(spec, seed=1, random_walks=2)
    pieces = split_walks(spec, walks, cap)
    limit = cap if cap is not None else max(4, -(-sum(len(w) - 1 for w in walks) // 8))
    assert [p.walk for p in pieces] == sorted(p.walk for p in pieces)
    for wi, walk in enumerate(walks):
        mine = [p for p in pieces if p.walk == wi]
        # contiguous: the changes 1..len-1 of the walk, each exactly once
        assert [p.start for p in mine] == [0] + [p.end for p in mine[:-1]]
        assert mine[-1].end == len(walk) - 1
        states = _replay(g, spec, walk)
        want = expected_after(spec, walk)
        for p in mine:
            seq = p.sequence
            assert seq[p.prefix + 1:] == walk[p.start + 1:p.end + 1]
            along = _replay(g, spec, seq)  # a valid sequence from power-up ...
            assert along[p.prefix] == states[p.start]  # ... reaching the walk's state
            assert p.prefix == dist[states[p.start]]  # by the shortest way
            assert expected_after(spec, seq)[p.prefix:] == want[p.start:p.end + 1]
            assert len(seq) - 1 <= limit or p.end - p.start == 1


@pytest.mark.parametrize("cap", [3, 5])
def test_the_cut_costs_the_fewest_prefix_changes_brute_force(cap):
    """Every way to cut the speed controller's tour (2^10) tried: none with pieces of at most
    ``cap`` changes (or of one change past its prefix, where the way there is longer) needs
    fewer prefix changes than the chosen one."""
    spec = parse_fsm_file(str(EXAMPLES / "speedctl.fsm"))
    g = stable_graph(spec)
    dist = _distances(g)
    walk = transition_tour(spec)[0]
    states = _replay(g, spec, walk)
    m = len(walk) - 1
    best = None
    for cuts in itertools.product([0, 1], repeat=m - 1):
        starts = [0] + [k for k in range(1, m) if cuts[k - 1]]
        ends = starts[1:] + [m]
        if all(b - a + dist[states[a]] <= cap or b - a == 1 for a, b in zip(starts, ends)):
            cost = sum(dist[states[a]] for a in starts)
            best = cost if best is None else min(best, cost)
    chosen = split_walks(spec, [walk], cap)
    assert best is not None and sum(p.prefix for p in chosen) == best
    assert all(len(p.sequence) - 1 <= cap or p.end - p.start == 1 for p in chosen)


def test_the_heaviest_cases_start_first_ties_in_case_order():
    assert longest_first([1, 3, 2, 3, 1]) == [1, 3, 2, 0, 4]
    assert longest_first([]) == []


@pytest.fixture(scope="module")
def speedctl():
    return compile_spec(parse_fsm_file(EXAMPLES / "speedctl.fsm"))


def test_a_proof_cut_finer_gives_the_serial_figures_on_two_processes(speedctl):
    """Pieces of at most 3 changes (more prefix changes than the default cut): two processes
    give every step's figures, the failures and the report of the serial run."""
    runs = []
    for jobs in (1, 2):
        rec: list = []
        rep = prove_sequential_dynamic(speedctl, speedctl.spec, LIB, random_walks=0,
                                       piece_steps=3, tolerance=1e-4, record=rec, jobs=jobs)
        runs.append((rec, {k: v for k, v in rep.to_json().items() if k != "seconds"}))
    (serial, one), (pooled, two) = runs
    assert one["pieces"] >= 4 and one["prefix_steps"] > 0
    assert len(serial) == one["cases"] + one["prefix_steps"]
    assert one["failure_count"] > 0  # a tolerance no output meets: the failures are compared
    assert pooled == serial and two == one


@pytest.mark.slow
def test_a_piece_from_power_up_is_the_whole_walks_case(speedctl):
    """A piece that starts at power-up without a prefix is the same case as the start of the
    uncut walk (a fresh scene at power-up both times): identical figures; every later step
    ends at the spec's outputs in both."""
    walks = transition_tour(speedctl.spec)[:1]
    whole: list = []
    w = prove_sequential_dynamic(speedctl, speedctl.spec, LIB, sequences=walks, record=whole)
    cut: list = []
    c = prove_sequential_dynamic(speedctl, speedctl.spec, LIB, random_walks=0, piece_steps=3,
                                 record=cut)
    assert w.passed and c.passed and c.cases == w.cases == len(whole)
    first = split_walks(speedctl.spec, walks, 3)[0]
    assert first.start == 0 and first.prefix == 0
    assert cut[:first.end] == whole[:first.end]
    walked = {(r["sequence"], r["step"]): r for r in cut if "prefix" not in r}
    assert sorted(walked) == sorted((r["sequence"], r["step"]) for r in whole)


def _spin(n: int, lib, case: int) -> int:
    """CPU work proportional to ``case`` (a pool case must be a module-level function)."""
    s = 0
    for i in range(n * case):
        s += i
    return s


def test_pool_cpu_counts_each_workers_cpu_seconds_for_the_critical_path():
    """Two processes, cases of 1..6 units: the results are the serial ones, at most two
    workers are counted, and neither did all the work (the longest case first keeps the
    busiest worker near half of it)."""
    from mechc.proofs import parallel

    cases = [1, 2, 3, 4, 5, 6]
    out = parallel.run_cases(_spin, 200_000, cases, LIB, jobs=2, weights=cases)
    assert out == [sum(range(200_000 * c)) for c in cases]
    busy = parallel.pool_cpu
    assert 1 <= len(busy) <= 2 and all(v > 0 for v in busy.values())
    assert max(busy.values()) < 0.9 * sum(busy.values())
