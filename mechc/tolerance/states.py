"""The states a tolerance run proves each sample in: those of the kinematic proof
(``mechc.proofs.kinematic``), every input vector at rest and ``samples`` points along every
single-input change, with what the spec asks of each output there."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mechc.errors import UsageError
from mechc.ir.spec import Spec
from mechc.logic.cubes import DC
from mechc.proofs.cases import bits, single_changes
from mechc.proofs.kinematic import EXHAUSTIVE_MAX_INPUTS


@dataclass
class States:
    names: list[str]  # inputs, in the spec's order
    values: np.ndarray  # (inputs, S): rest states first, then each change's samples
    n_rest: int
    e_k: np.ndarray  # the moving input of each change
    samples: int  # points along each change
    rest_want: dict[str, np.ndarray]  # output -> 0 / 1 / DC per rest state
    lo: dict[str, np.ndarray]  # output -> its value before each change
    hold: dict[str, np.ndarray]  # output -> the change must leave it where it is (dwell)

    @property
    def size(self) -> int:
        return self.values.shape[1]

    @property
    def n_edges(self) -> int:
        return len(self.e_k)


def proof_states(spec: Spec, samples: int = 21) -> States:
    """Every input vector and every single-input change, as the kinematic proof takes them."""
    names = list(spec.inputs)
    n = len(names)
    if n > EXHAUSTIVE_MAX_INPUTS:
        raise UsageError(f"a tolerance run proves every input state: {n} inputs is more than "
                         f"{EXHAUSTIVE_MAX_INPUTS}")
    rest_bits = bits(np.arange(1 << n, dtype=np.int64), n).astype(bool)
    e_rows, e_k = single_changes(n)
    edge_bits = bits(e_rows, n).astype(bool)
    vals = np.repeat(edge_bits.astype(float), samples, axis=1)
    vals[np.repeat(e_k, samples), np.arange(vals.shape[1])] = np.tile(
        np.linspace(0.0, 1.0, samples), len(e_k))
    hi_bits = edge_bits.copy()
    hi_bits[e_k, np.arange(len(e_k))] = True
    rest_want = spec.values_at(rest_bits)
    lo = spec.values_at(edge_bits)
    hi = spec.values_at(hi_bits)
    hold = {o: (lo[o] == hi[o]) & (lo[o] != DC) for o in spec.outputs}
    return States(names, np.hstack([rest_bits.astype(float), vals]), rest_bits.shape[1], e_k,
                  samples, rest_want, lo, hold)
