"""Precision-position synthesis of dyads and triads with M/K(/T) circles.

Method of Mather & Erdman, "Expansion of MK Circle Theory for Dyads and Triads" (Machines 2023,
seed ``004_…``).  A chain of k links (k = 2: dyad W, Z; k = 3: triad W, Z, V) reaches n prescribed
positions when the *standard form* holds for every position j = 2..n::

    sum_l  L_l (exp(i theta_lj) - 1) = delta_j,      delta_j = PP_j - PP_1

with theta_lj the rotation of link l from position 1 (beta, alpha, gamma for W, Z, V).  All
rotations are prescribed except those of one *free link* u (beta for a motion-generation dyad;
alpha in the paper's triad examples).

Why circles: fixing theta_uj at k - 1 positions makes those equations linear, leaving a
one-complex-parameter family X(t) = X0 + t X1 of chains.  Each further position j then demands
|L_u(t)| = |R_j(t)| -- the free link must still reach -- and that locus is a circle in the
t-plane.  Every pivot is affine in t, so its image is the paper's M (ground), K (first moving)
or T (second moving) circle for positions {fixed ones, j}.  Hence:

* one circle position  -> the circle itself is the solution set (3-position dyad, 4-position
  triad);
* two                  -> their intersections (4-position dyad for a chosen beta2, ...);
* three                -> a free choice is *searched* until the third circle passes through an
  intersection of the first two (5-position dyad, 6-position triad);
* four                 -> two free choices are searched (7-position triad).

Every root found is polished by Newton's method on the full standard-form system and its
residual is reported; nothing is returned that does not satisfy the equations.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import brentq, minimize_scalar

from mechc.linkage_synthesis.circles import (
    Circle,
    apollonius,
    gcircle_to_circle,
    intersect_gcircles,
    reflect,
    rotation_centre,
)

LINK_NAMES = ("W", "Z", "V")
ANGLE_NAMES = ("beta", "alpha", "gamma")
PIVOT_NAMES = ("M", "K", "T")  # ground, first moving pivot, second moving pivot
RESIDUAL_TOL = 1e-9  # relative; a root that does not reach it is discarded and counted


class SynthesisError(ValueError):
    """The problem as stated cannot be solved by this method (says which number failed)."""


@dataclass(frozen=True)
class ChainProblem:
    """n prescribed positions for a k-link chain.

    ``angles[l, j]`` is the rotation (rad) of link l from position 1 to position j+1, NaN where
    unknown; column 0 is zero.  Only ``free_link`` may have NaNs; its known entries are the free
    choices.
    """

    points: np.ndarray  # (n,) complex
    angles: np.ndarray  # (k, n) float
    free_link: int

    @property
    def k(self) -> int:
        return self.angles.shape[0]

    @property
    def n(self) -> int:
        return self.points.shape[0]

    @property
    def deltas(self) -> np.ndarray:
        return self.points - self.points[0]

    @property
    def scale(self) -> float:
        return float(max(np.max(np.abs(self.deltas)), 1e-300))

    def free_name(self, j: int) -> str:
        """Paper notation, e.g. 'beta2' for the free link's rotation at 0-based position j."""
        return f"{ANGLE_NAMES[self.free_link]}{j + 1}"


def chain_problem(points, angles_deg: dict[str, list], free: str | None = None) -> ChainProblem:
    """Build a problem from paper-style data: ``angles_deg`` maps 'beta'/'alpha'/'gamma' to a
    list of n values in degrees (None = unknown; the first may be omitted as 0).  A dyad uses
    beta and alpha, a triad beta, alpha and gamma.  ``free`` names the free link's angle; by
    default the one that has unknowns (or beta if none does)."""
    pts = np.asarray([complex(p) for p in points])
    n = len(pts)
    names = [a for a in ANGLE_NAMES if a in angles_deg]
    if names == ["beta", "alpha"] or set(names) == {"beta", "alpha"}:
        k = 2
    elif set(names) == {"beta", "alpha", "gamma"}:
        k = 3
    else:
        raise SynthesisError(f"angle columns {sorted(angles_deg)}: a dyad needs beta and alpha, "
                             "a triad beta, alpha and gamma")
    unknown = ANGLE_NAMES[:k]
    ang = np.full((k, n), np.nan)
    for l, name in enumerate(unknown):
        vals = list(angles_deg[name])
        if len(vals) == n - 1:
            vals = [0.0, *vals]
        if len(vals) != n:
            raise SynthesisError(f"{name}: {len(vals)} values for {n} positions")
        for j, v in enumerate(vals):
            ang[l, j] = np.nan if v is None else np.radians(float(v))
    if not np.isnan(ang[:, 0]).all() and np.nanmax(np.abs(ang[:, 0])) > 1e-12:
        raise SynthesisError("rotations are measured from position 1: the first must be 0")
    ang[:, 0] = 0.0
    with_nan = [l for l in range(k) if np.isnan(ang[l]).any()]
    if len(with_nan) > 1:
        raise SynthesisError("only one link may have unknown rotations, got unknowns in "
                             + ", ".join(ANGLE_NAMES[l] for l in with_nan))
    if free is not None:
        if free not in unknown:
            raise SynthesisError(f"free link '{free}' is not one of {', '.join(unknown)}")
        u = unknown.index(free)
        if with_nan and with_nan[0] != u:
            raise SynthesisError(f"'{ANGLE_NAMES[with_nan[0]]}' has unknowns but the free link "
                                 f"is '{free}'")
    else:
        u = with_nan[0] if with_nan else 0
    if n < k + 1:
        raise SynthesisError(f"a {k}-link chain needs at least {k + 1} positions, got {n}")
    return ChainProblem(pts, ang, u)


@dataclass
class ChainSolution:
    links: np.ndarray  # (k,) complex: W, Z(, V) in position 1
    angles: np.ndarray  # (k, n) rad, all known
    points: np.ndarray  # (n,) complex
    residual: float  # max relative standard-form residual over positions
    searched: dict[str, float] = field(default_factory=dict)  # degrees

    @property
    def ground(self) -> complex:
        return complex(self.points[0] - self.links.sum())

    @property
    def pivots(self) -> list[complex]:
        """Ground pivot M, then the moving pivots K (and T), in position 1."""
        out = [self.ground]
        for L in self.links[:-1]:
            out.append(out[-1] + L)
        return out

    def pose(self, j: int) -> list[complex]:
        """Joint positions (ground, moving pivots..., precision point) in position j."""
        out = [self.ground]
        for l, L in enumerate(self.links):
            out.append(out[-1] + L * np.exp(1j * self.angles[l, j]))
        return out

    def to_json(self) -> dict:
        d = {name: [float(L.real), float(L.imag)] for name, L in zip(LINK_NAMES, self.links)}
        d["pivots"] = {n: [float(p.real), float(p.imag)] for n, p in zip(PIVOT_NAMES,
                                                                        self.pivots)}
        d["angles_deg"] = {ANGLE_NAMES[l]: [float(np.degrees(a)) for a in self.angles[l]]
                           for l in range(len(self.links))}
        d["residual"] = self.residual
        if self.searched:
            d["searched_deg"] = dict(self.searched)
        return d


@dataclass
class PivotCircles:
    """The pivot circles of one circle position (0-based index ``position``)."""

    position: int
    circles: dict[str, Circle | None]  # 'M', 'K', 'T' -> circle (None: a straight line)


@dataclass
class ChainResult:
    mode: str  # linear | circle | intersection | family | search
    problem: ChainProblem
    solutions: list[ChainSolution]
    circles: list[PivotCircles]
    message: str
    rejected: int = 0  # roots discarded because their polished residual exceeded RESIDUAL_TOL
    family: list[ChainSolution] = field(default_factory=list)  # sampled members (family mode)


# --- poles (dyad theory, paper eqs. 2-9) -----------------------------------------------------


def pole(problem: ChainProblem, j: int, k: int, link: int = 1) -> complex:
    """Pole P_jk of the body carrying link ``link`` (absolute coordinates), eqs. 2-3.

    The body point fixed by the displacement from position j to k; infinite (raises) for a pure
    translation.
    """
    th = problem.angles[link]
    if np.isnan(th[j]) or np.isnan(th[k]):
        raise SynthesisError("pole of a link whose rotation is unknown")
    ej, ek = np.exp(1j * th[j]), np.exp(1j * th[k])
    if abs(ej - ek) < 1e-12:
        raise SynthesisError(f"pole P{j + 1}{k + 1} is at infinity (no rotation between the "
                             "positions)")
    dj, dk = problem.deltas[j], problem.deltas[k]
    return complex(problem.points[0] + (dj * ek - dk * ej) / (ek - ej))


def image_pole(problem: ChainProblem, j: int = 1, k: int = 2) -> complex:
    """Image pole P'_jk: P_jk mirrored in the line P_1j P_1k (paper, text before eq. 2)."""
    return reflect(pole(problem, j, k), pole(problem, 0, j), pole(problem, 0, k))


def dyad_circles_from_poles(problem: ChainProblem, beta2: float) -> tuple[Circle, Circle]:
    """M and K circles of a 3-position dyad from the poles alone (paper eqs. 6-9).

    The M circle passes through P13 and P23 and its centre sees the chord P13->P23 turned by
    +beta2; the K circle passes through P13 and P23' and its centre turns P13 onto P23' by
    beta2 - alpha2 (the paper's eq. 7 states the magnitude alpha2 - beta2; measured in the same
    sense as eq. 6 the turn is the opposite one, because P23' is a mirror image).
    """
    a2 = problem.angles[1, 1]
    p13, p23, p23i = pole(problem, 0, 2), pole(problem, 1, 2), image_pole(problem, 1, 2)
    cm = rotation_centre(p13, p23, beta2)
    ck = rotation_centre(p13, p23i, beta2 - a2)
    d = abs(p23 - p13)
    rm = d / (2 * abs(np.sin(beta2 / 2)))  # eq. 8 with theta_M = beta2/2
    rk = abs(p23i - p13) / (2 * abs(np.sin((a2 - beta2) / 2)))  # eq. 9
    return Circle(cm, float(rm)), Circle(ck, float(rk))


# --- the reduction to the t-plane ------------------------------------------------------------


def _coefs(problem: ChainProblem, theta_u: np.ndarray) -> np.ndarray:
    """(N, k, n) complex: exp(i theta) - 1 with the free link's row taken from theta_u (N, n)."""
    ang = np.broadcast_to(problem.angles, (theta_u.shape[0],) + problem.angles.shape).copy()
    ang[:, problem.free_link, :] = theta_u
    return np.exp(1j * ang) - 1.0


def _reduce(problem: ChainProblem, theta_u: np.ndarray, lin: list[int]):
    """Solve the linear rows ``lin`` (k-1 positions whose free angle is known) for each of N
    choices of the free angles: returns X0 (N, k), X1 (N, k) (unit null vector) and the
    singular-value ratio (conditioning) of each system."""
    co = _coefs(problem, theta_u)  # (N, k, n)
    Mrows = np.transpose(co[:, :, lin], (0, 2, 1))  # (N, k-1, k)
    rhs = problem.deltas[lin]  # (k-1,)
    U, s, Vh = np.linalg.svd(Mrows)  # full_matrices: Vh (N, k, k)
    X1 = np.conj(Vh[:, -1, :])  # null vector
    # min-norm particular solution: V_r S^-1 U^H rhs
    r = len(lin)
    Uh_b = np.einsum("nij,i->nj", np.conj(U), rhs)  # (N, r)
    inv_s = np.where(s > 0.0, 1.0 / np.where(s > 0.0, s, 1.0), 0.0)
    X0 = np.einsum("nij,nj->ni", np.conj(np.transpose(Vh[:, :r, :], (0, 2, 1))), Uh_b * inv_s)
    cond = s[:, -1] / np.maximum(s[:, 0], 1e-300)
    return X0, X1, cond, co


def _reach_terms(problem: ChainProblem, co: np.ndarray, X0, X1, j: int):
    """a + b t (what the free link must reach at position j) and c + d t (the free link)."""
    u = problem.free_link
    r = -co[:, :, j].copy()
    r[:, u] = 1.0
    a = problem.deltas[j] + np.einsum("nl,nl->n", r, X0)
    b = np.einsum("nl,nl->n", r, X1)
    return a, b, X0[:, u], X1[:, u]


def _plan(problem: ChainProblem):
    """Which positions are linear (free angle known), searched, or circle positions."""
    th = problem.angles[problem.free_link]
    known = [j for j in range(1, problem.n) if not np.isnan(th[j])]
    k = problem.k
    if len(known) >= k - 1:
        lin, searched = known[: k - 1], []
        checks = known[k - 1:]
    else:
        unknown = [j for j in range(1, problem.n) if np.isnan(th[j])]
        searched = unknown[: k - 1 - len(known)]
        lin = sorted(known + searched)
        checks = []
    circ = [j for j in range(1, problem.n) if j not in lin and j not in checks]
    return lin, searched, circ, checks


# --- solving ---------------------------------------------------------------------------------


def residual(problem: ChainProblem, links: np.ndarray, angles: np.ndarray) -> float:
    """Max over positions of |sum_l L_l (e^{i theta} - 1) - delta_j|, relative to the problem
    size -- the paper's own equations (eq. 1 / 15 / A1)."""
    co = np.exp(1j * angles) - 1.0
    lhs = np.einsum("l,lj->j", links, co)
    return float(np.max(np.abs(lhs - problem.deltas)) / problem.scale)


def _complete(problem: ChainProblem, links: np.ndarray, theta_u: np.ndarray) -> np.ndarray:
    """All angles: the free link's unknown rotations follow from where it must reach."""
    ang = problem.angles.copy()
    u = problem.free_link
    ang[u] = theta_u
    Lu = links[u]
    for j in range(1, problem.n):
        if np.isnan(ang[u, j]):
            others = sum(links[l] * (np.exp(1j * ang[l, j]) - 1.0) for l in range(problem.k)
                         if l != u)
            ang[u, j] = np.angle((problem.deltas[j] - others + Lu) / Lu)
    return ang


def polish(problem: ChainProblem, links: np.ndarray, angles: np.ndarray,
           fixed: np.ndarray | None = None, iters: int = 30):
    """Gauss-Newton on the full standard form: unknowns are the links and every free-link angle
    not in ``fixed`` (bool (n,), True = prescribed free choice).  Returns (links, angles)."""
    u = problem.free_link
    if fixed is None:
        fixed = ~np.isnan(problem.angles[u])
    var = [j for j in range(1, problem.n) if not fixed[j]]
    k = problem.k
    L = links.astype(complex).copy()
    ang = angles.copy()
    for _ in range(iters):
        co = np.exp(1j * ang) - 1.0
        F = np.einsum("l,lj->j", L, co)[1:] - problem.deltas[1:]
        if np.max(np.abs(F)) < 1e-15 * problem.scale:
            break
        m = problem.n - 1
        J = np.zeros((2 * m, 2 * k + len(var)))
        for l in range(k):
            c = co[l, 1:]
            J[:m, 2 * l], J[m:, 2 * l] = c.real, c.imag  # d/d Re(L_l)
            J[:m, 2 * l + 1], J[m:, 2 * l + 1] = -c.imag, c.real  # d/d Im(L_l)
        for q, j in enumerate(var):
            dj = 1j * L[u] * np.exp(1j * ang[u, j])
            J[j - 1, 2 * k + q], J[m + j - 1, 2 * k + q] = dj.real, dj.imag
        rhs = -np.concatenate([F.real, F.imag])
        step = np.linalg.lstsq(J, rhs, rcond=None)[0]
        L = L + step[0:2 * k:2] + 1j * step[1:2 * k:2]
        for q, j in enumerate(var):
            ang[u, j] += step[2 * k + q]
        if np.max(np.abs(step)) < 1e-16 * max(1.0, problem.scale):
            break
    ang[u] = np.angle(np.exp(1j * ang[u]))
    return L, ang


def _make_solution(problem, X, theta_u, searched, fixed) -> ChainSolution:
    ang = _complete(problem, X, theta_u)
    L, ang = polish(problem, X, ang, fixed=fixed)
    res = residual(problem, L, ang)
    return ChainSolution(L, ang, problem.points, res,
                         {problem.free_name(j): float(np.degrees(theta_u[j])) for j in searched})


def _pivot_circles(problem, X0, X1, A, B, C, j) -> PivotCircles:
    """Image of the t-plane circle for position j under each pivot's affine map."""
    base = gcircle_to_circle(float(A), complex(B), float(C))
    out: dict[str, Circle | None] = {}
    for p in range(problem.k):
        # pivot p (0 = ground) = PP1 - sum_{l >= p} X_l
        off = problem.points[0] - X0[p:].sum()
        lin = -X1[p:].sum()
        out[PIVOT_NAMES[p]] = (None if base is None else
                               Circle(complex(off + lin * base.centre), float(abs(lin)
                                                                            * base.radius)))
    return PivotCircles(j, out)


def _theta_grid(problem, searched, values):
    th = np.tile(problem.angles[problem.free_link], (len(values), 1))
    for q, j in enumerate(searched):
        th[:, j] = values[:, q]
    return th


def _intersections(problem, theta_u, lin, circ):
    """t-plane intersections of the first two circle positions for each row of theta_u."""
    X0, X1, cond, co = _reduce(problem, theta_u, lin)
    terms = [_reach_terms(problem, co, X0, X1, j) for j in circ]
    A1, B1, C1 = apollonius(*terms[0])
    A2, B2, C2 = apollonius(*terms[1])
    hi, lo, ok = intersect_gcircles(A1, B1, C1, A2, B2, C2)
    return X0, X1, terms, hi, lo, ok & (cond > 1e-12)


def _extra_residuals(problem, terms, t):
    """Signed reach residual |R_j(t)| - |L_u(t)| of the circle positions after the second."""
    out = []
    for a, b, c, d in terms[2:]:
        out.append((np.abs(a + b * t) - np.abs(c + d * t)) / problem.scale)
    return out


def solve_chain(problem: ChainProblem, grid: int = 1440) -> ChainResult:
    """Synthesise every chain that reaches the positions (see module docstring for the modes).

    ``grid`` is the number of samples per searched angle; roots between samples are refined by
    Brent's method (1 searched angle) or Newton (2), then polished on the full equations.
    """
    k, n, u = problem.k, problem.n, problem.free_link
    lin, searched, circ, checks = _plan(problem)
    fixed = np.zeros(n, bool)
    fixed[[j for j in range(1, n) if not np.isnan(problem.angles[u, j])]] = True
    th0 = problem.angles[u]
    need = max(len(circ) - 2, 0)
    if len(circ) == 0 or checks:
        return _solve_linear(problem)  # k or more free angles known: linear, rest are checks
    if len(circ) == 1 and len(searched) == 1:
        return _circle_sets(problem, lin, searched, circ)
    if len(searched) > need and not (len(circ) == 2 and len(searched) == 1):
        names = ", ".join(problem.free_name(j) for j in searched[need:])
        raise SynthesisError(f"{n} positions leave a {len(searched) - need}-parameter family "
                             f"of {'dyads' if k == 2 else 'triads'}: give {names}")
    extra_checks = len(circ) - 2 - len(searched)
    if len(circ) == 1:
        X0, X1, cond, co = _reduce(problem, th0[None, :], lin)
        if cond[0] < 1e-12:
            raise SynthesisError("the fixed positions make the linear equations singular "
                                 f"(singular-value ratio {cond[0]:.2e})")
        A, B, C = apollonius(*_reach_terms(problem, co, X0, X1, circ[0]))
        pc = _pivot_circles(problem, X0[0], X1[0], A[0], B[0], C[0], circ[0])
        return ChainResult("circle", problem, [], [pc],
                           f"{n} positions: every point of the circles is a solution; give "
                           f"{problem.free_name(circ[0])} to pick one")
    if not searched:
        return _solve_intersection(problem, lin, circ, fixed, extra_checks)
    if len(circ) == 2 and len(searched) == 1:
        return _solve_family(problem, lin, searched, circ, fixed, grid)
    if len(searched) == 1:
        return _solve_search1(problem, lin, searched, circ, fixed, grid)
    if len(searched) == 2:
        return _solve_search2(problem, lin, searched, circ, fixed, max(grid // 4, 180))
    raise SynthesisError(f"{n} positions need {len(searched)} searched angles; at most 2 are "
                         "supported")


def _keep(problem, sols):
    """Drop duplicates and anything whose residual fails; count the failures."""
    out, rejected = [], 0
    for s in sols:
        if not np.isfinite(s.residual) or s.residual > RESIDUAL_TOL:
            rejected += 1
            continue
        if any(np.max(np.abs(s.links - o.links)) < 1e-7 * problem.scale for o in out):
            continue
        out.append(s)
    return out, rejected


def _solve_linear(problem: ChainProblem) -> ChainResult:
    u = problem.free_link
    th = problem.angles[u]
    known = [j for j in range(1, problem.n) if not np.isnan(th[j])]
    co = _coefs(problem, th[None, :])[0]
    Mrows = co[:, known].T
    X, *_ = np.linalg.lstsq(Mrows, problem.deltas[known], rcond=None)
    fixed = ~np.isnan(th)
    sol = _make_solution(problem, X, th, [], fixed)
    sols, rej = _keep(problem, [sol])
    msg = (f"linear solution, residual {sol.residual:.2e}" if sols else
           f"no chain: the over-determined linear equations leave residual {sol.residual:.2e}")
    return ChainResult("linear", problem, sols, [], msg, rej)


def _circle_sets(problem, lin, searched, circ, count: int = 6) -> ChainResult:
    """One set of circles per sampled value of the missing free choice (as the paper's Figs. 2
    and 6: six values 60 deg apart; from 30 deg, since 0 would freeze the free link)."""
    vals = np.radians(30.0 + np.arange(count) * 360.0 / count)
    vals = np.angle(np.exp(1j * vals))
    X0, X1, cond, co = _reduce(problem, _theta_grid(problem, searched, vals[:, None]), lin)
    A, B, C = apollonius(*_reach_terms(problem, co, X0, X1, circ[0]))
    pcs = [_pivot_circles(problem, X0[i], X1[i], A[i], B[i], C[i], circ[0])
           for i in range(count) if cond[i] > 1e-12]
    name = problem.free_name(searched[0])
    return ChainResult("circle", problem, [], pcs,
                       f"{problem.n} positions leave two free choices: circles drawn for "
                       f"{name} = " + ", ".join(f"{np.degrees(v):g}" for v in vals)
                       + f" deg; give {name} and {problem.free_name(circ[0])} to pick a "
                       "solution")


def _solve_intersection(problem, lin, circ, fixed, extra_checks) -> ChainResult:
    th = problem.angles[problem.free_link][None, :]
    X0, X1, terms, hi, lo, ok = _intersections(problem, th, lin, circ)
    pcs = []
    for j, tm in zip(circ, terms):
        A, B, C = apollonius(*tm)
        pcs.append(_pivot_circles(problem, X0[0], X1[0], A[0], B[0], C[0], j))
    sols = []
    if ok[0]:
        for t in (hi[0], lo[0]):
            sols.append(_make_solution(problem, X0[0] + t * X1[0], th[0].copy(), [], fixed))
    kept, rej = _keep(problem, sols)
    names = " and ".join(problem.free_name(j) for j in circ[:2])
    if not ok[0]:
        msg = f"the circles for {names} do not intersect: no chain for these free choices"
    else:
        msg = f"{len(kept)} chain(s) at the intersections of the circles"
    if extra_checks and ok[0] and not kept:
        msg = "the intersections do not satisfy the remaining positions (over-determined)"
    return ChainResult("intersection", problem, kept, pcs, msg, rej)


def _scan1(problem, lin, searched, circ, values):
    th = _theta_grid(problem, searched, values[:, None])
    X0, X1, terms, hi, lo, ok = _intersections(problem, th, lin, circ)
    return X0, X1, terms, hi, lo, ok


def _solve_family(problem, lin, searched, circ, fixed, grid) -> ChainResult:
    vals = np.linspace(-np.pi, np.pi, grid, endpoint=False)
    X0, X1, terms, hi, lo, ok = _scan1(problem, lin, searched, circ, vals)
    fam = []
    step = max(1, grid // 180)
    for i in range(0, grid, step):
        if not ok[i]:
            continue
        for t in (hi[i], lo[i]):
            X = X0[i] + t * X1[i]
            th = _theta_grid(problem, searched, vals[i:i + 1, None])[0]
            fam.append(_make_solution(problem, X, th, searched, fixed))
    fam, rej = _keep(problem, fam)
    name = problem.free_name(searched[0])
    return ChainResult("family", problem, [], [], f"{problem.n} positions with these free "
                       f"choices leave a one-parameter family: give {name} to pick one "
                       f"({len(fam)} members sampled)", rej, fam)


def family_member_near(problem: ChainProblem, target_links, grid: int = 720) -> ChainSolution:
    """The exact member of a one-parameter family closest (max |link difference|) to
    ``target_links`` -- used to compare a printed answer with an exact one."""
    lin, searched, circ, checks = _plan(problem)
    if not (len(circ) == 2 and len(searched) == 1):
        raise SynthesisError("family_member_near: the problem is not a one-parameter family")
    target = np.asarray(target_links, complex)
    fixed = np.zeros(problem.n, bool)
    fixed[[j for j in range(1, problem.n) if not np.isnan(problem.angles[problem.free_link,
                                                                           j])]] = True

    def dist(v, which):
        X0, X1, terms, hi, lo, ok = _scan1(problem, lin, searched, circ, np.atleast_1d(v))
        t = np.where(which, hi, lo)
        X = X0 + t[:, None] * X1
        d = np.max(np.abs(X - target[None, :]), axis=1)
        return np.where(ok, d, np.inf)

    vals = np.linspace(-np.pi, np.pi, grid, endpoint=False)
    best = None
    for which in (True, False):
        d = dist(vals, which)
        i = int(np.argmin(d))
        if not np.isfinite(d[i]):
            continue
        h = 2 * np.pi / grid
        r = minimize_scalar(lambda v, w=which: float(dist(v, w)[0]), bounds=(vals[i] - h,
                            vals[i] + h), method="bounded", options={"xatol": 1e-13})
        if best is None or r.fun < best[0]:
            best = (r.fun, r.x, which)
    if best is None:
        raise SynthesisError("the family is empty: the circles never intersect")
    _, v, which = best
    X0, X1, terms, hi, lo, ok = _scan1(problem, lin, searched, circ, np.array([v]))
    t = hi[0] if which else lo[0]
    th = _theta_grid(problem, searched, np.array([[v]]))[0]
    return _make_solution(problem, X0[0] + t * X1[0], th, searched, fixed)


def _boundary(problem, lin, searched, circ, bad: float, good: float, rounds: int = 12) -> float:
    """Where the circles start to meet between ``bad`` (they miss) and ``good`` (they meet):
    32 samples per round narrow the interval 31-fold, so 12 rounds reach rounding level."""
    for _ in range(rounds):
        v = np.linspace(bad, good, 33)
        ok = _scan1(problem, lin, searched, circ, v)[5]
        first = int(np.argmax(ok))  # ok[-1] is True (good), so a True exists
        if first == 0:
            return float(v[0])
        bad, good = v[first - 1], v[first]
    return float(good)


def _solve_search1(problem, lin, searched, circ, fixed, grid) -> ChainResult:
    """Circles beyond the third only filter the roots (through the full residual)."""
    vals = np.linspace(-np.pi, np.pi, grid + 1)
    X0, X1, terms, hi, lo, ok = _scan1(problem, lin, searched, circ, vals)

    def g_at(v, lab):
        X0_, X1_, terms_, hi_, lo_, ok_ = _scan1(problem, lin, searched, circ, np.array([v]))
        t = hi_ if lab else lo_
        return float(_extra_residuals(problem, terms_, t)[0][0]) if ok_[0] else np.nan

    edges: dict[int, float] = {}  # tangency located inside step i (shared by both labels)
    cands = []
    for lab, T in ((True, hi), (False, lo)):
        g = _extra_residuals(problem, terms, T)[0]
        g = np.where(ok, g, np.nan)
        for i in range(grid):
            if np.isfinite(g[i]) and np.isfinite(g[i + 1]):
                if g[i] == 0.0 or g[i] * g[i + 1] < 0.0:
                    cands.append((vals[i], vals[i + 1], lab))
            elif np.isfinite(g[i]) != np.isfinite(g[i + 1]):
                # the circles start or stop meeting inside this step (tangency): a root may
                # lie between the tangency and the sample, so bracket from the tangency itself
                k = i + 1 if np.isfinite(g[i + 1]) else i
                if i not in edges:
                    edges[i] = _boundary(problem, lin, searched, circ, vals[2 * i + 1 - k],
                                         vals[k])
                good = edges[i]
                ge = g_at(good, lab)
                if np.isfinite(ge) and ge * g[k] <= 0.0:
                    cands.append((min(good, vals[k]), max(good, vals[k]), lab))

    def f(v, lab):
        X0_, X1_, terms_, hi_, lo_, ok_ = _scan1(problem, lin, searched, circ, np.array([v]))
        t = hi_ if lab else lo_
        return float(_extra_residuals(problem, terms_, t)[0][0])

    sols = []
    for a, b, lab in cands:
        try:
            v = brentq(f, a, b, args=(lab,), xtol=1e-15, rtol=4 * np.finfo(float).eps)
        except ValueError:
            continue
        X0_, X1_, terms_, hi_, lo_, ok_ = _scan1(problem, lin, searched, circ, np.array([v]))
        if not ok_[0]:
            continue
        t = hi_[0] if lab else lo_[0]
        th = _theta_grid(problem, searched, np.array([[v]]))[0]
        sols.append(_make_solution(problem, X0_[0] + t * X1_[0], th, searched, fixed))
    kept, rej = _keep(problem, sols)
    pcs = []
    if kept:
        th_s = kept[0].angles[problem.free_link][searched]
        X0_, X1_, cond, co = _reduce(problem, _theta_grid(problem, searched, th_s[None, :]), lin)
        for j in circ:
            A, B, C = apollonius(*_reach_terms(problem, co, X0_, X1_, j))
            pcs.append(_pivot_circles(problem, X0_[0], X1_[0], A[0], B[0], C[0], j))
    name = problem.free_name(searched[0])
    msg = (f"{len(kept)} chain(s): {name} searched over {grid} samples for concurrent circles"
           if kept else f"no value of {name} makes the circles concurrent ({grid} samples "
           "searched; a root closer than one sample to a tangency may be missed)")
    return ChainResult("search", problem, kept, pcs, msg, rej)


def _solve_search2(problem, lin, searched, circ, fixed, grid) -> ChainResult:
    """Two searched angles: sign changes of the two extra reach residuals on a grid, then Newton
    on the full system from each candidate cell."""
    v = np.linspace(-np.pi, np.pi, grid + 1)
    V1, V2 = np.meshgrid(v, v, indexing="ij")
    vals = np.stack([V1.ravel(), V2.ravel()], axis=1)
    th = _theta_grid(problem, searched, vals)
    X0, X1, terms, hi, lo, ok = _intersections(problem, th, lin, circ)
    cands = []
    for T in (hi, lo):
        g3, g4 = _extra_residuals(problem, terms, T)[:2]
        g3 = np.where(ok, g3, np.nan).reshape(V1.shape)
        g4 = np.where(ok, g4, np.nan).reshape(V1.shape)
        c3 = _cell_sign_change(g3)
        c4 = _cell_sign_change(g4)
        Tg = T.reshape(V1.shape)
        X0g = X0.reshape(V1.shape + (problem.k,))
        X1g = X1.reshape(V1.shape + (problem.k,))
        for i, jj in zip(*np.nonzero(c3 & c4)):
            X = X0g[i, jj] + Tg[i, jj] * X1g[i, jj]
            thv = _theta_grid(problem, searched, np.array([[v[i], v[jj]]]))[0]
            cands.append((X, thv))
    sols = []
    for X, thv in cands:
        ang = _complete(problem, X, thv)
        L, ang = polish(problem, X, ang, fixed=fixed, iters=60)
        res = residual(problem, L, ang)
        sols.append(ChainSolution(L, ang, problem.points, res,
                                  {problem.free_name(j): float(np.degrees(ang[problem.free_link,
                                                                              j]))
                                   for j in searched}))
    kept, rej = _keep(problem, sols)
    names = " and ".join(problem.free_name(j) for j in searched)
    msg = (f"{len(kept)} chain(s): {names} searched on a {grid}x{grid} grid"
           if kept else f"no values of {names} make the circles concurrent ({grid}x{grid} "
           "grid searched)")
    return ChainResult("search", problem, kept, [], msg, rej)


def _cell_sign_change(g: np.ndarray) -> np.ndarray:
    """Grid cells (i, j) whose four corners are finite and include both signs."""
    c = np.stack([g[:-1, :-1], g[1:, :-1], g[:-1, 1:], g[1:, 1:]])
    fin = np.all(np.isfinite(c), axis=0)
    c = np.where(np.isfinite(c), c, 0.0)
    return fin & (c.max(axis=0) >= 0) & (c.min(axis=0) <= 0)


# --- conveniences ----------------------------------------------------------------------------


def dyad(points, alpha_deg, beta_deg=None, **kw) -> ChainResult:
    """Motion-generation dyad: body rotations alpha prescribed, ground-link rotations beta free
    (give beta2 for 4 positions, nothing for 5)."""
    n = len(points)
    beta = list(beta_deg) if beta_deg is not None else [0.0] + [None] * (n - 1)
    beta = beta + [None] * (n - len(beta))
    return solve_chain(chain_problem(points, {"alpha": alpha_deg, "beta": beta},
                                     free="beta"), **kw)
