"""Which dimensions matter: finite differences of the closed forms at the nominal design, and
a regression of the samples' margin on their perturbations.

Finite differences: every geometric dimension moved by ``h`` (a batch of one-dimension
samples, solved together) gives the change of every output's position in every proof state per
mm; times the dimension's tolerance it is how far that dimension alone moves an output (the
ranking). The same derivatives give the lost motion of pin clearance: a pin in a hole with
diametral play ``c`` may sit anywhere within ``c/2`` of the hole's centre, which moves an output
by at most ``c/2`` times the length of its gradient with respect to that pin's position; summed
over every pin, taken up the worst way in every state (a bound, first order in the play).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mechc.tolerance.batch import Batch
from mechc.tolerance.dimensions import Dim
from mechc.tolerance.sequential import SequentialBatch

H_MM = 1e-3  # finite-difference step: far above rounding (1e-12 mm), far below any tolerance
MIN_SAMPLES_PER_DIM = 5  # fewer samples than this per dimension: no regression (it over-fits)


@dataclass
class Jacobian:
    """d(output signal)/d(dimension) per state, fraction of stroke per mm (or per unit of a
    fraction for springs, which move no output: zero)."""

    dims: list[Dim]
    d: dict[str, np.ndarray]  # output -> (D, S)


def jacobian(batch: Batch | SequentialBatch, chunk_states: int = 1 << 16,
             per: int | None = None) -> Jacobian:
    """``per``: dimensions moved in one evaluation (default: ``chunk_states`` states)."""
    D, S = len(batch.dims), batch.size
    base = batch.signals(np.zeros((1, D)))
    out = {o: np.zeros((D, S)) for o in base}
    geo = batch.geo
    per = per or max(1, chunk_states // S)
    for s in range(0, len(geo), per):
        ks = geo[s:s + per]
        delta = np.zeros((len(ks), D))
        delta[np.arange(len(ks)), ks] = H_MM
        sig = batch.signals(delta)
        for o, v in sig.items():
            out[o][ks] = (v - base[o]) / H_MM
    for o in out:  # a state the nominal design cannot solve has no derivative
        out[o] = np.where(np.isfinite(out[o]), out[o], 0.0)
        if isinstance(batch, SequentialBatch):
            # only where the walks judge the output (at rest, or holding): mid-switch a
            # MEMORY's throw is a jump, whose finite difference says when, not how far
            out[o][:, ~batch.judged(o)] = 0.0
    return Jacobian(batch.dims, out)


def lost_motion(jac: Jacobian, clearance: float) -> dict[str, np.ndarray]:
    """Per output and state, the most the pins' play moves it (fraction of stroke)."""
    pins: dict[str, list[int]] = {}
    for k, d in enumerate(jac.dims):
        if d.pin:
            pins.setdefault(d.pin, []).append(k)
    out = {}
    for o, J in jac.d.items():
        lost = np.zeros(J.shape[1])
        for ks in pins.values():
            lost += np.sqrt((J[ks] ** 2).sum(axis=0))
        out[o] = lost * clearance / 2.0
    return out


@dataclass
class Ranked:
    dim: Dim
    position_mm: float  # the most it alone moves an output, at its tolerance (FD)
    margin_coef: float  # regression: change of the sample margin (mm) over its tolerance


def rank(jac: Jacobian, tols: np.ndarray, stroke: float, deltas: np.ndarray | None = None,
         margin: np.ndarray | None = None) -> list[Ranked]:
    """Dimensions by how far each alone moves an output at its tolerance (largest first); the
    regression of the samples' margin on their deltas alongside, where samples are given."""
    D = len(jac.dims)
    pos = np.zeros(D)  # no derivatives (none given): zero, ranked by regression
    for J in jac.d.values():
        pos = np.maximum(pos, np.abs(J).max(axis=1) * tols * stroke)
    coef = np.zeros(D)
    if deltas is not None and margin is not None and len(margin) > 2:
        ok = np.isfinite(margin)
        if ok.sum() < max(3, MIN_SAMPLES_PER_DIM * D):
            ok[:] = False  # too few samples for D coefficients: no regression (zeros)
        X = deltas[ok]
        used = np.flatnonzero(X.std(axis=0) > 0) if len(X) else np.array([], int)
        if len(used) and ok.sum() > len(used) + 1:
            # normal equations: the deltas are drawn independently, so X'X is well conditioned
            # (and a D x D solve is far cheaper than a QR of the N x D samples)
            A = np.hstack([X[:, used], np.ones((X.shape[0], 1))])
            b = np.linalg.solve(A.T @ A + 1e-12 * np.eye(A.shape[1]), A.T @ margin[ok])
            coef[used] = b[:-1] * tols[used]
    order = sorted(range(D), key=lambda k: (-pos[k], -abs(coef[k]), k))
    return [Ranked(jac.dims[k], float(pos[k]), float(coef[k])) for k in order]


def by_owner(ranked: list[Ranked]) -> dict[str, float]:
    """Per cell (or net, or input): the root-sum-square of its dimensions' position effects
    (mm), largest first: how much of the outputs' scatter comes from there."""
    acc: dict[str, float] = {}
    for r in ranked:
        acc[r.dim.owner] = acc.get(r.dim.owner, 0.0) + r.position_mm ** 2
    return dict(sorted(((k, float(np.sqrt(v))) for k, v in acc.items()),
                       key=lambda kv: -kv[1]))
