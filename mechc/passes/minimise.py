"""Two-level minimisation of every output of a spec: the ``Spec -> Equations`` stage.

Per output (exact): all prime implicants of on ∪ dc, then a minimum cover by integer
programming. When the primes are too many for that (wide, dense functions) the engine falls back
to expanding each uncovered on-minterm to a prime and covering with those; such results are marked
``proven: false``. Several outputs then share one set of products (``logic/multi.py``): the
fewest distinct products over all outputs, exact where the multi-output primes fit in the time
limit, else an espresso-style heuristic with a covering program. Every step whose time limit
runs out is listed in ``Equations.time_limited``. Every result is checked against the spec on
every care row before it is used.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, replace

import numpy as np

from mechc.errors import MechcError, UsageError
from mechc.ir.equations import Cover, Equations, XorForm
from mechc.ir.spec import Spec
from mechc.logic.clock import Clock, WallClockOut, hard_stop
from mechc.logic.cover import min_cover, share_covers
from mechc.logic.cubes import DC, MAX_TABLE_INPUTS, Cube, eval_cover
from mechc.logic.espresso import check_cover, espresso
from mechc.logic.hazards import hazard_free
from mechc.logic.implicants import own_primes, region_sets, table_fits, ternary_table
from mechc.logic.multi import minimise_multi
from mechc.logic.primes import TooManyPrimes, prime_implicants
from mechc.logic.quick_multi import quick_multi_cover


@dataclass
class MinimiseOptions:
    time_limit: float = 20.0  # seconds per integer program; then the best cover found is used
    prime_limit: int = 20_000  # more primes than this: use the expansion heuristic
    share: bool = True  # share product terms between outputs where that saves cells
    complements: bool = True  # also minimise each output's complement (for the mapper)
    alt_time_limit: float = 3.0  # seconds per program for those alternatives (never reported)
    hazard_free: bool = True  # also derive covers with consensus terms (see logic/hazards.py)
    multi_output: bool = True  # one set of products for all outputs (fewest distinct products)
    multi_time_limit: float = 5.0  # seconds for the multi-output step (at most time_limit)
    hazard_time_limit: float = 2.0  # seconds per output for the consensus terms (ditto)
    # CPU seconds for the whole minimisation of a truth-table spec (see ``_Clock``): the
    # per-output covers share 45 % of what is left, the multi-output step and the sharing
    # program most of the rest (None: each step keeps its own limit only)
    budget: float | None = 7.0
    # wall seconds after which no step of the minimisation of a truth-table spec runs on
    # (``logic/clock.py``: a step still running is stopped and the best answer found before
    # it kept; only the final check comes after): the whole call ends within 10 s even on a
    # loaded machine (None: no hard end)
    wall_limit: float | None = 8.5


def minimise(spec: Spec, opts: MinimiseOptions | None = None) -> Equations:
    opts = opts or MinimiseOptions()
    if not spec.has_table():
        return _minimise_wide(spec, opts)
    n = spec.n
    covers: dict[str, Cover] = {}
    comps: dict[str, Cover] = {}
    prime_sets: dict = {}
    comp_sets: dict = {}
    limited: list[str] = []
    multi = opts.multi_output and len(spec.outputs) > 1 and spec.kind != "fsm"
    m = len(spec.outputs)
    clock = Clock(opts.budget, opts.wall_limit)
    steps_end = clock.end(HAZARD_RESERVE)  # the consensus terms get the last second
    tables = np.array([spec.table(o) for o in spec.outputs])
    own = _own_primes(tables != 0, n)  # every output's primes at once (None: too wide)
    for i, name in enumerate(spec.outputs):
        # under load these keep to a third of the wall clock left, so the multi-output step
        # after them is not cut (ex1010's exact covers took 6 s of 8 at load 8)
        copts = replace(opts, time_limit=min(opts.time_limit, max(
            clock.floor(MIN_STEP_SECONDS, HAZARD_RESERVE),
            COVER_SHARE * clock.left(HAZARD_RESERVE) / (m - i)),
            max(0.05, COVER_WALL_SHARE * clock.wall_left(HAZARD_RESERVE) / (m - i))))
        if opts.wall_limit and clock.elapsed() > COVER_WALL_END * opts.wall_limit:
            copts = replace(copts, time_limit=0.0)  # the rest: greedy covers of their primes
        got = None
        try:
            with hard_stop(steps_end):
                got = _minimise_table(tables[i], n, copts,
                                      primes=own[i] if own is not None else None)
        except WallClockOut:
            pass
        if got is None:  # the wall clock ran out: a quick cover, not a minimum
            got = _quick_cover(spec, name, tables[i], n), None
            limited.append(f"cover of {name} (wall clock: a quick cover)")
        covers[name], prime_sets[name] = got
        if not covers[name].proven and covers[name].method not in ("expand", "quick"):
            limited.append(f"cover of {name}")
    eq = Equations(list(spec.inputs), list(spec.outputs), covers, comps)
    if opts.share and len(spec.outputs) > 1 and not multi:  # the multi-output step shares
        _stopped(steps_end, limited, "shared covers", _share, spec, eq, prime_sets, replace(
            opts, time_limit=max(clock.floor(MIN_STEP_SECONDS, HAZARD_RESERVE),
                                 clock.cap(opts.time_limit, HAZARD_RESERVE))))
    if multi:
        # first after the per-output covers: the product count is what the step is for, so
        # under load the mapper's alternatives below are cut, not it
        per_output = Equations(eq.inputs, eq.outputs, dict(eq.covers), eq.complements,
                               eq.xor_forms)
        # a multi-output cover to keep in hand should the step below be stopped (and one
        # more start for it): the per-output covers' and the PLA's cubes raised to
        # multi-output primes, then a greedy, irredundant cover of them
        quick = _stopped(steps_end, limited, "quick multi-output cover", _quick_multi, spec,
                         eq)
        # its preparation (the primes' table, the covering matrix, the reductions: 1.1 s of
        # CPU on alu4) has no time check, so under load its limit keeps well inside the
        # wall clock left; alu4's 575 products come at a limit of 0.5 s as at 4 s
        mt = min(clock.cap(min(opts.time_limit, opts.multi_time_limit), HAZARD_RESERVE),
                 max(clock.floor(0.5, HAZARD_RESERVE), MULTI_SHARE * clock.left(HAZARD_RESERVE)),
                 max(0.2, MULTI_WALL_SHARE * clock.wall_left(HAZARD_RESERVE)))
        got = _stopped(steps_end, limited, "multi-output cover", _multi_output, spec, eq,
                       replace(opts, time_limit=mt, multi_time_limit=mt), quick)
        if got is not None:
            new, timed = got
            limited.extend(timed)
            eq.covers.update(new)
        if quick is not None and _cover_cost(quick) < _cover_cost(
                [eq.covers[o].cubes for o in spec.outputs]):
            for o, cubes in zip(spec.outputs, quick):
                eq.covers[o] = Cover(cubes, False, "quick multi-output", eq.covers[o].seconds)
        if any(eq.covers[o].cubes != per_output.covers[o].cubes for o in eq.outputs):
            _stopped(steps_end, limited, "shared per-output covers", _share, spec, per_output,
                     prime_sets, replace(opts, time_limit=min(
                         clock.cap(min(opts.time_limit, opts.multi_time_limit), HAZARD_RESERVE),
                         max(clock.floor(MIN_STEP_SECONDS, HAZARD_RESERVE),
                             SHARE_SHARE * clock.left(HAZARD_RESERVE)))), limited)
            for o in eq.outputs:  # not the multi-output minimum, whatever each one is alone
                c = per_output.covers[o]
                per_output.covers[o] = Cover(c.cubes, False, "per-output", c.seconds)
            eq.alternative = per_output
    if opts.complements:
        _alternatives(spec, tables, eq, comp_sets, opts, clock, limited)
    eq.shared_terms = count_shared(eq)
    alt = eq.alternative
    if opts.hazard_free:
        _consensus_terms(spec, eq, comp_sets, prime_sets, opts, clock, limited, multi)
    if alt is not None:
        alt.shared_terms = count_shared(alt)
        alt.hazard_free_complements = eq.hazard_free_complements
        verify(spec, alt)
    if clock.wall_left() < 0:
        limited.append(f"minimisation wall clock ({opts.wall_limit:g} s)")
    eq.time_limited = limited
    if alt is not None:
        alt.time_limited = limited
    verify(spec, eq)
    return eq


def _stopped(until: float | None, limited: list[str], label: str, step, *args):
    """``step(*args)``, or None (and ``label`` noted in ``limited``) when the hard end of the
    wall clock comes first."""
    try:
        with hard_stop(until):
            return step(*args)
    except WallClockOut:
        limited.append(f"{label} (left out: wall clock)")
        return None


def _quick_cover(spec: Spec, name: str, table: np.ndarray, n: int) -> Cover:
    """A valid cover of one output without any search, for when the wall clock is out: a
    PLA's own rows (inside on ∪ dc by definition), else each on-minterm grown greedily."""
    f = spec.functions.get(name)
    if spec.kind == "pla" and f is not None and f.on is not None and not f.off \
            and f.rest == 0:
        cubes = list(dict.fromkeys(f.on))
    else:
        on = np.flatnonzero(table == 1).astype(np.int64)
        cubes = [Cube(int(a), int(b)) for a, b in zip(*expand_primes(table != 0, on, n))]
    return Cover(cubes, False, "quick", 0.0)


def _alternatives(spec: Spec, tables: np.ndarray, eq: Equations, comp_sets: dict,
                  opts: MinimiseOptions, clock: Clock, limited: list[str]) -> None:
    """The mapper's alternative forms of every output (complement covers, XOR forms), in
    what is left of the budget: each output gets an equal share of the wall clock left, and
    once it is out the rest are left without (the mapper then builds the covers
    themselves)."""
    n, m = spec.n, len(spec.outputs)
    end = clock.end(HAZARD_RESERVE)
    comp_own = _stopped(end, [], "", _own_primes, tables != 1, n) \
        if n <= ALT_EXACT_MAX_INPUTS else None
    # the alternatives share one budget, so many outputs do not multiply it
    alt_each = min(opts.alt_time_limit, ALT_BUDGET / m)
    skipped: list[str] = []
    for i, name in enumerate(spec.outputs):
        if clock.wall_left(HAZARD_RESERVE) <= 0:
            skipped.append(name)
            continue
        # stretched by the load seen so far (under load 10 espresso's 3 s ran out on alu4's
        # f7: 517 more parts), never past this output's share of the wall clock left
        t = max(0.05, min(clock.cap(alt_each, HAZARD_RESERVE),
                          ALT_SHARE * clock.wall_left(HAZARD_RESERVE) / (m - i)))
        aopts = replace(opts, alt_time_limit=t, time_limit=min(opts.time_limit, t))
        got = _stopped(end, [], "", _minimise_alt, _complement(tables[i]), n, aopts,
                       comp_own[i] if comp_own is not None else None)
        if got is None:
            skipped.append(name)
            continue
        eq.complements[name], comp_sets[name] = got
        c = eq.complements[name]
        if c.method == "greedy" or c.method.endswith("(time limit)"):
            limited.append(f"complement cover of {name} (a mapper alternative)")
    if skipped:
        limited.append(f"complement covers of {', '.join(skipped)} (mapper alternatives, "
                       "left out: wall clock)")
    skipped = []
    for i, name in enumerate(spec.outputs):
        t = max(0.05, min(clock.cap(alt_each, HAZARD_RESERVE),
                          ALT_SHARE * clock.wall_left(HAZARD_RESERVE) / (m - i)))
        got = _stopped(end, [], "", _xor_form, tables[i], spec.inputs, replace(
            opts, alt_time_limit=t, time_limit=min(opts.time_limit, t))) \
            if clock.wall_left(HAZARD_RESERVE) > 0 else None
        if got is not None:
            eq.xor_forms[name] = got
        elif _has_xor(tables[i], n):
            skipped.append(name)
    if skipped:
        limited.append(f"XOR forms of {', '.join(skipped)} (mapper alternatives, left out: "
                       "wall clock)")


def _consensus_terms(spec: Spec, eq: Equations, comp_sets: dict, prime_sets: dict,
                     opts: MinimiseOptions, clock: Clock, limited: list[str],
                     multi: bool) -> None:
    """Every cover (and complement cover) with the consensus terms that close its hazards,
    in the last second of the wall clock; a cover left without them (the clock is out) is
    named in ``limited`` and the mapper builds the cover itself."""
    n, m = spec.n, len(spec.outputs)
    alt = eq.alternative
    jobs = len(spec.outputs) * (2 if alt is not None else 1)
    hopts = replace(opts, time_limit=max(0.05, min(
        clock.cap(min(opts.time_limit, opts.hazard_time_limit, max(HAZARD_BUDGET / m, 0.2))),
        HAZARD_SHARE * clock.wall_left() / jobs)))
    end = clock.end()
    # products built for some output: closing a hazard with one costs an OR input only
    built = list(dict.fromkeys(c for o in spec.outputs for c in eq.covers[o].cubes)) \
        if multi else []
    skipped: list[str] = []

    def close(cover: Cover, table, primes, copts, label, shared=()) -> Cover | None:
        got = _stopped(end, [], "", _with_consensus, cover, table, n, primes, copts, limited,
                       label, shared)
        if got is None:
            skipped.append(label)
        return got

    for name in spec.outputs:
        table = spec.table(name)
        got = close(eq.covers[name], table, prime_sets[name], hopts, name, built)
        if got is not None:
            eq.hazard_free[name] = got
        if name in eq.complements:
            got = close(eq.complements[name], _complement(table), comp_sets[name], _alt(hopts),
                        f"complement of {name}")
            if got is not None:
                eq.hazard_free_complements[name] = got
    if alt is not None:
        for name in spec.outputs:
            got = close(alt.covers[name], spec.table(name), prime_sets[name], hopts,
                        f"{name} (per-output covers)")
            if got is not None:
                alt.hazard_free[name] = got
    if skipped:
        limited.append(f"hazard-free covers of {', '.join(skipped)} (left out: wall clock)")


def _has_xor(table: np.ndarray, n: int) -> bool:
    """Whether ``_xor_form`` would peel some input (then leaving it out is worth a note)."""
    for k in range(n):
        shaped = table.reshape(1 << k, 2, 1 << (n - 1 - k))
        a, b = shaped[:, 0, :], shaped[:, 1, :]
        both = (a != DC) & (b != DC)
        if both.any() and not (a[both] == b[both]).any():
            return True
    return False


#: Shares of the time budget still left: the per-output covers (together), the multi-output
#: step, the program sharing the per-output covers, the mapper's alternative forms (all
#: outputs together) and the consensus terms (all covers together); no step gets less than
#: ``MIN_STEP_SECONDS`` while the wall clock lasts.
COVER_SHARE = 0.45
MULTI_SHARE = 0.6
MULTI_WALL_SHARE = 0.35
COVER_WALL_SHARE = 0.45
#: Past this share of the wall clock the per-output covers left are greedy (no program).
COVER_WALL_END = 0.45
SHARE_SHARE = 0.5
ALT_SHARE = 0.6
HAZARD_SHARE = 0.5
MIN_STEP_SECONDS = 0.3
#: Wall seconds before the hard end kept for the consensus terms (every step before them
#: ends by then).
HAZARD_RESERVE = 1.0


def _quick_multi(spec: Spec, eq: Equations) -> list[list[Cube]] | None:
    """``quick_multi.quick_multi_cover`` from the per-output covers and a PLA's own rows."""
    tables = np.array([spec.table(o) for o in spec.outputs])
    starts = [[eq.covers[o].cubes for o in spec.outputs]]
    if spec.kind == "pla":
        starts.append([spec.functions[o].on for o in spec.outputs])
    return quick_multi_cover(spec.n, tables == 1, tables != 0, starts)


def _multi_output(spec: Spec, eq: Equations, opts: MinimiseOptions,
                  quick: list[list[Cube]] | None = None
                  ) -> tuple[dict[str, Cover], list[str]]:
    """The multi-output covers that replace the per-output ones when they have fewer
    distinct products (then literals plus OR inputs); every output's ``proven`` then says
    whether the multi-output minimum is proven. Returns (covers, the steps whose time limit
    ran out); ``eq`` is left as it is."""
    n = spec.n
    tables = np.array([spec.table(o) for o in spec.outputs])
    on, region = tables == 1, tables != 0
    start = [eq.covers[o].cubes for o in spec.outputs]
    dc = [spec.functions[o].dc for o in spec.outputs] if spec.kind == "pla" else None
    seeds = [[spec.functions[o].on for o in spec.outputs]] if spec.kind == "pla" else []
    if quick is not None:
        seeds.append(quick)
    res = minimise_multi(n, on, region, start, dc, min(opts.time_limit, opts.multi_time_limit),
                         opts.prime_limit, seeds=seeds)
    old = _cover_cost([eq.covers[o].cubes for o in spec.outputs])
    new = _cover_cost([res.output_cubes(i) for i in range(len(spec.outputs))])
    covers = {}
    for i, o in enumerate(spec.outputs):
        c = eq.covers[o]
        cubes = res.output_cubes(i) if new < old else c.cubes
        covers[o] = Cover(cubes, res.proven, res.method if new < old
                          else c.method, c.seconds + res.seconds / len(spec.outputs))
    return covers, res.time_limited


def _cover_cost(covers: list[list[Cube]]) -> tuple[int, int]:
    """(distinct products, their literals + OR inputs): the parts the mapper builds, products
    first (each one is a cell with its own fan-out)."""
    distinct = {c for cubes in covers for c in cubes}
    return len(distinct), sum(c.literals() for c in distinct) + sum(len(x) for x in covers)


#: Every output's primes come from one ternary table (``implicants.own_primes``) up to this
#: many cubes (3**16: 43 million entries, within the table's byte cap for up to 16 outputs);
#: beyond, per output by the Shannon recursion of ``primes.py``. At 16 inputs the table
#: halved the per-output covers' CPU on a random 11-output PLA (3.8 s against 7.3 s).
OWN_TABLE_MAX_CUBES = 3 ** 16


def _own_primes(regions: np.ndarray, n: int) -> list | None:
    """Each row's primes from one ternary table, or None when the table would be too big."""
    m = regions.shape[0]
    if 3 ** n > OWN_TABLE_MAX_CUBES or not table_fits(n, m):
        return None
    return own_primes(ternary_table(region_sets(regions), n, m), n, m)


def _minimise_table(table: np.ndarray, n: int, opts: MinimiseOptions, deadline: bool = False,
                    primes: tuple[np.ndarray, np.ndarray] | None = None):
    """Exact cover of one output (primes, then the covering program). With ``deadline`` the
    time limit also bounds the prime generation (a start for the multi-output step), past
    which primes are grown from the on-minterms instead (method ``expand``). ``primes``: the
    output's primes already known (from ``_own_primes``)."""
    t0 = time.perf_counter()
    on = np.flatnonzero(table == 1).astype(np.int64)
    dc = np.flatnonzero(table == DC).astype(np.int64)
    if len(on) == 0:
        return Cover([], True, "exact", time.perf_counter() - t0), None
    region = table != 0
    method_note = None
    if primes is not None and len(primes[0]) <= opts.prime_limit:
        masks, values = primes
    else:
        try:
            if primes is not None:
                raise TooManyPrimes(len(primes[0]))
            masks, values = prime_implicants(region, limit=opts.prime_limit,
                                             deadline=t0 + opts.time_limit if deadline
                                             else None)
        except TooManyPrimes:
            masks, values = expand_primes(region, on, n)
            method_note = "expand"
    # candidates that cover at least one on-minterm
    masks, values = _useful(masks, values, on)
    res = min_cover(masks, values, on, dc, n, opts.time_limit)
    cubes = [Cube(int(masks[i]), int(values[i])) for i in res.chosen]
    proven = res.proven and method_note is None
    method = method_note or res.method
    return Cover(cubes, proven, method, time.perf_counter() - t0), (masks, values, on, dc)


def _with_consensus(cover: Cover, table: np.ndarray, n: int, primes, opts,
                    limited: list[str] | None = None, label: str = "",
                    shared: list[Cube] = ()) -> Cover:
    if primes is None:
        return cover
    masks, values, _on, _dc = primes
    timed: list[str] = []
    cubes = hazard_free(cover.cubes, table, n, masks, values, opts.time_limit, timed, shared)
    if timed and limited is not None:
        limited.append(f"hazard-free cover of {label}")
    if len(cubes) == len(cover.cubes):
        return cover
    return Cover(cubes, False, cover.method + "+consensus", cover.seconds)


#: Up to this many inputs the mapper's alternative forms are minimised exactly; beyond, by the
#: espresso-style heuristic (at 10 inputs the exact complement took 1-3 s against 0.1 s).
ALT_EXACT_MAX_INPUTS = 8
#: Seconds the mapper's alternative forms of all outputs may take together (per output at most
#: ``alt_time_limit``): 14 outputs at 3 s each made table3's minimisation take 19 s, while 2 s
#: over alu4's 8 outputs gave complements that cost 528 more parts (13096 against 12568).
ALT_BUDGET = 24.0
#: Seconds the consensus-term programs of all outputs take together (per output at most
#: ``hazard_time_limit``).
HAZARD_BUDGET = 2.0


def _useful(masks: np.ndarray, values: np.ndarray, on: np.ndarray):
    """The candidate cubes that cover at least one on-minterm."""
    if len(masks) == 0:
        return masks, values
    keep = np.zeros(len(masks), dtype=bool)
    step = max(1, 4_000_000 // len(masks))
    for a in range(0, len(on), step):
        keep |= ((on[a:a + step, None] & masks[None, :]) == values[None, :]).any(axis=0)
    return masks[keep], values[keep]


def _minimise_alt(table: np.ndarray, n: int, opts: MinimiseOptions,
                  primes: tuple[np.ndarray, np.ndarray] | None = None):
    """A cover for one of the mapper's alternatives (complement, XOR residual): exact when
    small (``primes``: its primes, when already known), otherwise espresso's loop (these are
    never reported as the minimum). Covering all the complement's primes by local search
    instead gave fewer terms but more parts (apex4 17,020 against 16,933, sao2 1,075
    against 1,044): espresso's larger cubes map cheaper."""
    if n <= ALT_EXACT_MAX_INPUTS:
        return _minimise_table(table, n, _alt(opts), primes=primes)
    t0 = time.perf_counter()
    onm = np.flatnonzero(table == 1).astype(np.int64)
    if not len(onm):
        return Cover([], True, "exact", 0.0), None
    # espresso starts from cubes, not minterms: greedy primes of the on-set (inside on ∪ dc)
    # and of the dc-set (inside dc). From 24576 minterms (the complement of a two-literal
    # product of 15 inputs) its 3 s ran out before EXPAND had merged them, and the mapper
    # was handed thousands of minterms.
    on = [Cube(int(m), int(v)) for m, v in zip(*expand_primes(table != 0, onm, n))]
    dcm = np.flatnonzero(table == DC).astype(np.int64)
    dc = [Cube(int(m), int(v)) for m, v in zip(*expand_primes(table == DC, dcm, n))]
    res = espresso(n, on, dc, (), 0, time_limit=min(opts.time_limit, opts.alt_time_limit))
    masks = np.array([c.mask for c in res.cubes], dtype=np.int64)
    values = np.array([c.value for c in res.cubes], dtype=np.int64)
    method = "espresso" if res.complete else "espresso (time limit)"
    return (Cover(list(res.cubes), False, method, time.perf_counter() - t0),
            (masks, values, onm, dcm))


def _alt(opts: MinimiseOptions) -> MinimiseOptions:
    """Options for the alternative forms the mapper may try (shorter time limit)."""
    return replace(opts, time_limit=min(opts.time_limit, opts.alt_time_limit))


def _complement(table: np.ndarray) -> np.ndarray:
    return np.where(table == DC, DC, 1 - table).astype(np.int8)


def _xor_form(table: np.ndarray, inputs: list[str], opts: MinimiseOptions) -> XorForm | None:
    """Peel inputs x with f = x ⊕ g (g independent of x on the care set), greedily in order."""
    n = len(inputs)
    peeled: list[str] = []
    t = table.copy()
    for k in range(n):
        shaped = t.reshape(1 << k, 2, 1 << (n - 1 - k))
        a, b = shaped[:, 0, :], shaped[:, 1, :]
        both = (a != DC) & (b != DC)
        if not both.any() or (a[both] == b[both]).any():
            continue
        g = np.where(a != DC, a, np.where(b != DC, 1 - b, DC)).astype(np.int8)
        shaped[:, 0, :] = g
        shaped[:, 1, :] = g
        t = shaped.reshape(-1)
        peeled.append(inputs[k])
    if not peeled:
        return None
    care = t != DC
    if not care.any() or (t[care] == t[care][0]).all():
        return XorForm(peeled, None, None, int(t[care][0]) if care.any() else 0)
    res, rp = _minimise_alt(t, n, opts)
    comp, cp = _minimise_alt(_complement(t), n, opts)
    if opts.hazard_free:
        res = _with_consensus(res, t, n, rp, opts)
        comp = _with_consensus(comp, _complement(t), n, cp, opts)
    return XorForm(peeled, res, comp)


def expand_primes(region: np.ndarray, on: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Some primes: each still-uncovered on-minterm expanded greedily, literal by literal."""
    covered = np.zeros(len(region), dtype=bool)
    masks, values = [], []
    full = (1 << n) - 1
    for start in on.tolist():
        if covered[start]:
            continue
        mask, value = full, start
        for k in range(n):
            bit = 1 << (n - 1 - k)
            m2 = mask & ~bit
            if _cube_inside(region, m2, value & m2, n):
                mask, value = m2, value & m2
        masks.append(mask)
        values.append(value)
        covered[_cube_points(mask, value, n)] = True
    return np.array(masks, dtype=np.int64), np.array(values, dtype=np.int64)


def _cube_points(mask: int, value: int, n: int) -> np.ndarray:
    free = [1 << (n - 1 - k) for k in range(n) if not mask >> (n - 1 - k) & 1]
    pts = np.array([value], dtype=np.int64)
    for b in free:
        pts = np.concatenate([pts, pts | b])
    return pts


def _cube_inside(region: np.ndarray, mask: int, value: int, n: int) -> bool:
    return bool(region[_cube_points(mask, value, n)].all())


def _share(spec: Spec, eq: Equations, prime_sets, opts: MinimiseOptions,
           limited: list[str] | None = None) -> None:
    names = [nm for nm in spec.outputs if prime_sets[nm] is not None]
    if len(names) < 2:
        return
    # is any prime a candidate of two outputs?
    seen: dict[tuple[int, int], int] = {}
    for nm in names:
        masks, values, _on, _dc = prime_sets[nm]
        for key in set(zip(masks.tolist(), values.tolist())):
            seen[key] = seen.get(key, 0) + 1
    if max(seen.values()) < 2:
        return
    before = {(c.mask, c.value) for nm in names for c in eq.covers[nm].cubes}
    cands = [(prime_sets[nm][0], prime_sets[nm][1]) for nm in names]
    chosen = share_covers(cands, [prime_sets[nm][2] for nm in names],
                          [prime_sets[nm][3] for nm in names],
                          [(eq.covers[nm].terms, eq.covers[nm].literals) for nm in names],
                          spec.n, opts.time_limit)
    if chosen is None:
        if limited is not None:
            limited.append("shared per-output covers")
        return
    new = {nm: [Cube(int(cands[i][0][j]), int(cands[i][1][j])) for j in chosen[i]]
           for i, nm in enumerate(names)}
    after = {(c.mask, c.value) for cubes in new.values() for c in cubes}
    if len(after) >= len(before):
        return
    for nm in names:
        old = eq.covers[nm]
        eq.covers[nm] = Cover(new[nm], old.proven, old.method, old.seconds)


def count_shared(eq: Equations) -> int:
    """Product terms (with at least two literals) used by more than one output."""
    counts: dict[Cube, int] = {}
    for cover in eq.covers.values():
        for c in set(cover.cubes):
            if c.literals() >= 2:
                counts[c] = counts.get(c, 0) + 1
    return sum(1 for v in counts.values() if v > 1)


class VerificationError(MechcError):
    exit_code = 3


def _minimise_wide(spec: Spec, opts: MinimiseOptions) -> Equations:
    """Specs beyond the truth-table limit: espresso-style heuristic on cubes, per output (no
    complement or XOR forms, no multi-output sharing beyond identical cubes), each result
    checked exactly on cubes."""
    covers: dict[str, Cover] = {}
    for name in spec.outputs:
        f = spec.functions[name]
        if f.expr is not None:
            raise UsageError(f"{spec.path}: output {name} is an expression over {spec.n} inputs; "
                             f"beyond {MAX_TABLE_INPUTS} inputs only cube lists (PLA) are "
                             "supported")
        res = espresso(spec.n, f.on, f.dc, f.off, f.rest, time_limit=opts.time_limit)
        covers[name] = Cover(res.cubes, False, "espresso", res.seconds)
    eq = Equations(list(spec.inputs), list(spec.outputs), covers)
    eq.shared_terms = count_shared(eq)
    verify_wide(spec, eq)
    return eq


def verify_wide(spec: Spec, eq: Equations) -> None:
    """Exact check of every cover against the spec's cubes (any number of inputs)."""
    for name in spec.outputs:
        f = spec.functions[name]
        fault = check_cover(spec.n, eq.covers[name].cubes, f.on, f.dc, f.off, f.rest)
        if fault is not None:
            raise VerificationError(f"internal error: minimised {name}: {fault}")


def verify(spec: Spec, eq: Equations) -> None:
    """Exhaustive check of every cover against the spec on every care row."""
    rows = np.arange(1 << spec.n, dtype=np.int64)
    for name in spec.outputs:
        table = spec.table(name)
        care = table != DC
        for label, cover, want in (
                ("", eq.covers.get(name), table == 1),
                ("complement of ", eq.complements.get(name), table == 0),
                ("hazard-free ", eq.hazard_free.get(name), table == 1),
                ("hazard-free complement of ", eq.hazard_free_complements.get(name),
                 table == 0)):
            if cover is None:
                continue
            got = eval_cover(cover.cubes, rows)
            bad = np.flatnonzero(care & (got != want))
            if len(bad):
                raise VerificationError(
                    f"internal error: minimised {label}{name} differs from the spec at input "
                    f"{Cube.minterm(int(bad[0]), spec.n).to_string(spec.n)}")
