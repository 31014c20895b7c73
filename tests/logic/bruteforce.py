"""Brute-force references for the wide-engine tests: random cubes and their truth tables."""

from __future__ import annotations

import numpy as np

from mechc.logic.cubes import DC, Cube


def rand_cubes(rng: np.random.Generator, n: int, k: int, p_free: float) -> list[Cube]:
    out = []
    for _ in range(k):
        fixed = rng.random(n) > p_free
        bits = rng.random(n) < 0.5
        mask = sum(1 << j for j in range(n) if fixed[j])
        value = sum(1 << j for j in range(n) if fixed[j] and bits[j])
        out.append(Cube(mask, value))
    return out


def truth(cubes: list[Cube], n: int) -> np.ndarray:
    """Which of the 2**n points lie in some cube."""
    idx = np.arange(1 << n, dtype=np.int64)
    out = np.zeros(1 << n, dtype=bool)
    for c in cubes:
        out |= (idx & c.mask) == c.value
    return out


def spec_table(n, on, dc, off, rest) -> np.ndarray:
    """OutputSpec semantics: dc over on over off; a point in none takes ``rest``."""
    t = np.full(1 << n, rest, dtype=np.int8)
    t[truth(off, n)] = 0
    t[truth(on, n)] = 1
    t[truth(dc, n)] = DC
    return t
