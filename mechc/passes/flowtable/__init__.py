"""Flow-table synthesis: a fundamental-mode flow table becomes SET/RESET equations of MEMORY
elements and output equations (``001_…`` Appendix B, done by program).

Steps, each a plain function in its own module, run in this order by ``synthesise.py``:

0. ``reach.reachable`` / ``reach.prune_table``: rows never visited from the initial state
   (specified single-input changes, chains of unstable entries followed) are dropped, with a
   warning naming them (``SeqEquations.warnings``; compile prints them on stderr).
1. ``compatibles.compatibility``: the implication table (pairs of rows that may share a state).
2. ``compatibles.closed_cover``: a minimum closed cover of compatibles (exact by integer
   programming over the prime compatibles for small tables; over the maximal compatibles, not
   proven, beyond).
3. ``reduce.reduce_table``: the merged (reduced) table, outputs attached to stable total states.
4. ``assign.assign_states``: secondary codes without critical races: Tracey's
   single-transition-time assignment (every pair of transitions in a column that go to
   different states is separated by a variable that stays constant in both), minimum variables
   exact up to 10 merged rows. Each transition then moves inside its own subcube, which no
   other transition of the column touches, so every order in which the changing memories switch
   ends in the same state. (``assign.given_assignment`` takes the spec's ``assign`` instead.)
5. ``excite.excitation``: next state, SET/RESET and outputs per total state, with don't-cares
   (``excite.next_state_map`` reports critical races).
6. ``equations.excitation_equations``: exact minimisation of SET, then RESET with zeros where
   the built SET is on (so S·R = 0 on every total state, reachable or not; the other order is
   tried too and the cheaper kept), consensus terms against static-1 hazards;
   ``hazards.double_changes`` pins outputs so they change at most once per transition.
7. ``check.check_equations``: every reachable total state checked for S·R = 0, races and
   outputs.

Essential hazards (``hazards.essential_hazards``; Unger: a single input change applied three
times ends elsewhere than applied once) are reported with the ordering they need: they cannot be
removed by the logic. A set/reset spec skips steps 1-6 (``synthesise.setreset_equations``);
``synthesise.derive_equations`` picks the form.
"""

from mechc.passes.flowtable.assign import Assignment, assign_states, given_assignment
from mechc.passes.flowtable.check import check_equations
from mechc.passes.flowtable.compatibles import (
    CoverResult,
    brute_force_min_cover,
    closed_cover,
    compatibility,
)
from mechc.passes.flowtable.equations import SeqEquations, expr_of
from mechc.passes.flowtable.excite import Excitation, excitation, next_state_map
from mechc.passes.flowtable.hazards import essential_hazards
from mechc.passes.flowtable.options import SynthOptions
from mechc.passes.flowtable.reduce import ReducedTable, reduce_table
from mechc.passes.flowtable.synthesise import (
    derive_equations,
    setreset_equations,
    synthesise_table,
)

__all__ = [
    "Assignment",
    "CoverResult",
    "Excitation",
    "ReducedTable",
    "SeqEquations",
    "SynthOptions",
    "assign_states",
    "brute_force_min_cover",
    "check_equations",
    "closed_cover",
    "compatibility",
    "derive_equations",
    "essential_hazards",
    "excitation",
    "expr_of",
    "given_assignment",
    "next_state_map",
    "reduce_table",
    "setreset_equations",
    "synthesise_table",
]
