"""Cubes (product terms) and truth tables over n ordered inputs.

Bit convention everywhere: input 0 (the first declared) is the most significant bit of a
minterm number, so minterm ``m`` has input ``k`` equal to ``(m >> (n - 1 - k)) & 1``.
A cube is ``(mask, value)``: the bits in ``mask`` are the literals it fixes, ``value`` their
values (``value & ~mask == 0``). Truth tables are int8 arrays of length 2**n holding
0, 1 or DC.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import numpy as np

DC = 2
#: Largest input count for which mechc works on full truth tables (2**20 rows per output).
MAX_TABLE_INPUTS = 20


@dataclass(frozen=True, order=True)
class Cube:
    mask: int
    value: int

    def literals(self) -> int:
        return self.mask.bit_count()

    def contains(self, other: Cube) -> bool:
        """True if every minterm of ``other`` lies in this cube."""
        return (other.mask & self.mask) == self.mask and (other.value & self.mask) == self.value

    def intersects(self, other: Cube) -> bool:
        common = self.mask & other.mask
        return (self.value & common) == (other.value & common)

    def to_string(self, n: int) -> str:
        out = []
        for k in range(n):
            bit = 1 << (n - 1 - k)
            out.append("-" if not self.mask & bit else ("1" if self.value & bit else "0"))
        return "".join(out)

    @staticmethod
    def from_string(text: str) -> Cube:
        n = len(text)
        mask = value = 0
        for k, ch in enumerate(text):
            bit = 1 << (n - 1 - k)
            if ch == "1":
                mask |= bit
                value |= bit
            elif ch == "0":
                mask |= bit
            elif ch != "-":
                raise ValueError(f"bad cube character {ch!r}")
        return Cube(mask, value)

    @staticmethod
    def minterm(m: int, n: int) -> Cube:
        return Cube((1 << n) - 1, m)

    def literal_list(self, n: int) -> list[tuple[int, bool]]:
        """(input index, positive?) for each literal, in input order."""
        return [
            (k, bool(self.value >> (n - 1 - k) & 1))
            for k in range(n)
            if self.mask >> (n - 1 - k) & 1
        ]


def cube_table(cubes: Iterable[Cube], n: int) -> np.ndarray:
    """Boolean array of length 2**n: which minterms lie in the union of ``cubes``."""
    idx = np.arange(1 << n, dtype=np.int64)
    out = np.zeros(1 << n, dtype=bool)
    for c in cubes:
        out |= (idx & c.mask) == c.value
    return out


def table_from_sets(n: int, on: np.ndarray, dc: np.ndarray | None = None,
                    off: np.ndarray | None = None) -> np.ndarray:
    """Truth table from boolean on/dc arrays, or on/off arrays (rest don't care)."""
    if off is not None:
        table = np.full(1 << n, DC, dtype=np.int8)
        table[off] = 0
        table[on] = 1
        return table
    table = np.zeros(1 << n, dtype=np.int8)
    table[on] = 1
    if dc is not None:
        table[dc] = DC
    return table


def minterms_of(table: np.ndarray, value: int) -> np.ndarray:
    return np.flatnonzero(table == value)


def input_matrix(n: int, rows: np.ndarray | None = None) -> np.ndarray:
    """Boolean matrix (n, len(rows)): row k holds input k's value for each minterm."""
    if rows is None:
        rows = np.arange(1 << n, dtype=np.int64)
    shifts = np.arange(n - 1, -1, -1, dtype=np.int64)[:, None]
    return ((rows[None, :] >> shifts) & 1).astype(bool)


def eval_cover(cubes: Sequence[Cube], rows: np.ndarray) -> np.ndarray:
    out = np.zeros(len(rows), dtype=bool)
    for c in cubes:
        out |= (rows & c.mask) == c.value
    return out


def sort_cubes(cubes: list[Cube], n: int) -> list[Cube]:
    """Print order: fewer literals first, then by literal pattern (deterministic)."""
    return sorted(cubes, key=lambda c: (c.literals(), c.to_string(n).replace("-", "2")))
