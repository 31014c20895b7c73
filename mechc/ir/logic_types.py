"""Logic types: the Boolean meaning of a netlist cell, independent of its mechanism.

The logic level of ``simulate`` evaluates cells by these functions; the kinematic and dynamic
levels never look at them (they move the geometry).

The built-in types are listed in ``TYPES`` below. A cell file may declare a new one (a truth
table or an expression over its pins, see docs/write-a-cell.md): the library loader turns it
into a table with :func:`table_from_function` / :func:`table_from_truth` and registers it with
:func:`declare_type`, so everything that evaluates a type finds it here without a compiler edit.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from functools import reduce

import numpy as np

from mechc.errors import UsageError

Arrays = Sequence[np.ndarray]


@dataclass(frozen=True)
class LogicType:
    name: str
    min_inputs: int
    max_inputs: int | None  # None: any number
    fn: Callable[[Arrays, Mapping], np.ndarray]
    commutative: bool = True
    doc: str = ""
    table: tuple[int, ...] | None = None  # a declared type: output per row (input 0 the MSB)
    source: str = ""  # a declared type: the cell file that declared it first


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


#: The built-in type names (a cell file may not redefine one, only restate it).
BUILTIN = frozenset(TYPES)


def evaluate_type(type_name: str, inputs: Arrays, params: Mapping, size: int) -> np.ndarray:
    if type_name == "CONST":
        return np.full(size, bool(params.get("value", 0)), dtype=bool)
    t = TYPES.get(type_name)
    if t is None:
        raise UsageError(f"unknown logic type '{type_name}': a new type is declared by the cell "
                         "file that uses it, which is not loaded (pass --cells DIR)")
    return np.asarray(t.fn(list(inputs), params), dtype=bool)


# ---- types declared by cell files --------------------------------------------------------------
def table_rows(n: int) -> list[np.ndarray]:
    """The 2**n input rows as n boolean arrays, input 0 the most significant bit."""
    r = np.arange(1 << n)
    return [((r >> (n - 1 - i)) & 1).astype(bool) for i in range(n)]


def table_from_truth(truth, n: int) -> tuple[int, ...]:
    """A declared ``truth``: a string of 2**n '0'/'1' (spaces and '_' ignored) or a sequence
    of 2**n 0/1, the output for input rows 0..2**n-1 (first pin the most significant bit)."""
    if isinstance(truth, str):
        bits = [c for c in truth if c not in " _"]
        if any(c not in "01" for c in bits):
            raise ValueError(f"truth {truth!r}: expected only the characters 0 and 1")
        vals = [int(c) for c in bits]
    else:
        vals = list(truth)
        if any(v not in (0, 1, True, False) for v in vals):
            raise ValueError(f"truth {truth!r}: expected only 0 and 1")
        vals = [int(v) for v in vals]
    if len(vals) != 1 << n:
        raise ValueError(f"truth has {len(vals)} rows; {n} inputs need {1 << n} "
                         "(row k: the output when the inputs, first pin most significant, "
                         "spell k in binary)")
    return tuple(vals)


def table_from_function(text: str, pins: list[str], where: str) -> tuple[int, ...]:
    """A declared ``function``: an expression in the .bool syntax (``& | ^ ~``, parentheses)
    over the cell's input pin names, as a truth table."""
    from mechc.frontends.boolfile import parse_expression_text  # the one expression parser
    from mechc.ir.expr import evaluate

    e = parse_expression_text(text, pins, where)
    n = len(pins)
    env = dict(zip(pins, table_rows(n)))
    return tuple(int(v) for v in evaluate(e, env, 1 << n))


def builtin_table(type_name: str, n: int) -> tuple[int, ...] | None:
    """The table of built-in type ``type_name`` with ``n`` inputs (None: it needs parameters,
    state, or does not take ``n`` inputs)."""
    t = TYPES[type_name]
    if type_name in ("CONST", "MEMORY", "THRESHOLD") or n < t.min_inputs \
            or (t.max_inputs is not None and n > t.max_inputs):
        return None
    return tuple(int(v) for v in np.asarray(t.fn(table_rows(n), {}), dtype=bool))


def _lookup(table: tuple[int, ...], n: int) -> Callable[[Arrays, Mapping], np.ndarray]:
    tab = np.asarray(table, dtype=bool)

    def fn(x, p):
        idx = 0
        for i in range(n):
            idx = idx + (np.asarray(x[i]).astype(np.int64) << (n - 1 - i))
        return tab[idx]
    return fn


def declare_type(name: str, table: tuple[int, ...], source: str, doc: str = "") -> LogicType:
    """Register a type a cell file declares (``table`` over its n inputs, 2**n rows). A built-in
    name must mean the same function; a name already declared by another file must have the
    same table. Raises ValueError saying what differs."""
    n = (len(table) - 1).bit_length()
    if len(table) != 1 << n:
        raise ValueError(f"type {name}: a truth table needs a power-of-two number of rows")
    if name in BUILTIN:
        want = builtin_table(name, n)
        if want is None:
            raise ValueError(f"type {name} is built in and cannot be declared with {n} inputs "
                             "by a table")
        if tuple(table) != want:
            return _differ(name, table, want, "the built-in type")
        return TYPES[name]
    old = TYPES.get(name)
    if old is not None and old.source != source:  # the same file, edited and loaded again: new
        if len(old.table) != len(table):
            raise ValueError(f"type {name} has {old.min_inputs} inputs in {old.source}, "
                             f"{n} here")
        if old.table != tuple(table):
            return _differ(name, table, old.table, f"the type declared in {old.source}")
        return old
    perms = all(tuple(table) == _permuted(table, n, k) for k in range(n - 1))
    t = LogicType(name, n, n, _lookup(tuple(table), n), commutative=perms,
                  doc=doc or f"declared in {source}", table=tuple(table), source=source)
    TYPES[name] = t
    return t


def _permuted(table, n: int, k: int) -> tuple[int, ...]:
    """The table with inputs k and k+1 swapped (all adjacent swaps equal: symmetric)."""
    rows = table_rows(n)
    rows[k], rows[k + 1] = rows[k + 1], rows[k]
    idx = sum(r.astype(np.int64) << (n - 1 - i) for i, r in enumerate(rows))
    return tuple(int(table[j]) for j in idx)


def _differ(name: str, got, want, what: str):
    n = (len(got) - 1).bit_length()
    row = next(r for r in range(len(got)) if got[r] != want[r])
    bits = format(row, f"0{n}b") if n else "-"
    raise ValueError(f"type {name}: this declaration gives {got[row]} for inputs {bits} (first "
                     f"pin first), {what} gives {want[row]}")
