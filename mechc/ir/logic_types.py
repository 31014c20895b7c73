"""Logic types: the Boolean meaning of a netlist cell, independent of its mechanism.

The logic level of ``simulate`` evaluates cells by these functions; the kinematic and dynamic
levels never look at them (they move the geometry).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from functools import reduce

import numpy as np

Arrays = Sequence[np.ndarray]


@dataclass(frozen=True)
class LogicType:
    name: str
    min_inputs: int
    max_inputs: int | None  # None: any number
    fn: Callable[[Arrays, Mapping], np.ndarray]
    commutative: bool = True
    doc: str = ""


def _and(x, p):
    return reduce(np.logical_and, x)


def _or(x, p):
    return reduce(np.logical_or, x)


def _xor(x, p):
    return reduce(np.logical_xor, x)


def _threshold(x, p):
    s = sum(w * xi.astype(float) for w, xi in zip(p["weights"], x))
    crossed = sum((s >= t).astype(int) for t in p["thresholds"])
    return (crossed % 2 == 1) ^ bool(p.get("below", 0))


def _connector(x, p):
    return ~x[0] if p.get("logic", "identity") == "invert" else x[0]


def _memory(x, p):
    raise TypeError("MEMORY is stateful: evaluate it with the sequential simulator")


def _const(x, p, size=None):
    raise AssertionError("CONST is evaluated by the caller (it has no inputs)")


TYPES: dict[str, LogicType] = {t.name: t for t in [
    LogicType("AND", 2, None, _and, doc="all inputs on"),
    LogicType("OR", 2, None, _or, doc="any input on"),
    LogicType("NOT", 1, 1, lambda x, p: ~x[0], doc="inverter"),
    LogicType("NAND", 2, None, lambda x, p: ~_and(x, p), doc="not all inputs on"),
    LogicType("NOR", 2, None, lambda x, p: ~_or(x, p), doc="no input on"),
    LogicType("AND_NOT", 2, 2, lambda x, p: x[0] & ~x[1], commutative=False,
              doc="first input on and second off (a·b̄)"),
    LogicType("OR_NOT", 2, 2, lambda x, p: x[0] | ~x[1], commutative=False,
              doc="first input on or second off (a + b̄)"),
    LogicType("XOR", 2, 2, _xor, doc="or-exclusive"),
    LogicType("XNOR", 2, 2, lambda x, p: ~_xor(x, p), doc="coincidence"),
    LogicType("THRESHOLD", 1, None, _threshold, commutative=False,
              doc="multithreshold: output flips at each threshold the weighted sum crosses"),
    LogicType("CONNECTOR", 1, 1, _connector, doc="link, shaft or lever: identity or invert"),
    LogicType("AMPLIFIER", 1, 1, lambda x, p: x[0], doc="power amplifier (identity)"),
    LogicType("MEMORY", 2, 2, _memory, commutative=False,
              doc="set/reset memory: Q on after S, off after R, held while both off (stateful)"),
    LogicType("CONST", 0, 0, _const, doc="a terminal fixed at off or on (params.value)"),
]}


def evaluate_type(type_name: str, inputs: Arrays, params: Mapping, size: int) -> np.ndarray:
    if type_name == "CONST":
        return np.full(size, bool(params.get("value", 0)), dtype=bool)
    return np.asarray(TYPES[type_name].fn(list(inputs), params), dtype=bool)
