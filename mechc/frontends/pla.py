"""Front end for espresso PLA files (``.i .o .ilb .ob .p .type .e``), read as espresso reads them.

Input plane: ``1`` true, ``0`` complemented, ``-``/``2`` absent, ``?`` an empty term.
Output plane: ``1``/``4`` on-set, ``0``/``3`` off-set, ``-``/``2`` don't-care set, ``~`` nothing;
each character counts only if ``.type`` includes that set (default ``fd``, as in espresso).
"""

from __future__ import annotations

import re

import numpy as np

from mechc.errors import SpecError
from mechc.frontends.lexer import read_text, shorten
from mechc.ir.spec import OutputSpec, Spec
from mechc.logic.cubes import DC, MAX_TABLE_INPUTS, Cube, cube_table

TYPES = {"f", "r", "fd", "fr", "dr", "fdr"}
UNSUPPORTED = {"mv", "kiss", "phase", "pair", "symbolic", "symbolic-output", "label"}
_NAME_OK = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")
#: What espresso accepts as a name: any printable token (``di<11>``, ``x[3]``, ``a.b``).
_NAME_CHARS = re.compile(r"^[!-~]+$")
#: ASCII digits only: str.isdigit() also accepts '²' (which int() refuses) and '٣' (which it reads).
_WHOLE = re.compile(r"^[0-9]+$")


def parse_pla_file(path: str) -> Spec:
    return parse_pla(read_text(path), str(path))


def parse_pla(text: str, path: str = "<string>") -> Spec:
    n = m = None
    ilb = ob = None
    pla_type = "fd"
    # (line, column of each output character, cube or None for an empty term, output plane)
    terms: list[tuple[int, tuple[int, ...], Cube | None, str]] = []
    ended = False
    saw_term_line = None

    def err(line, col, msg):
        return SpecError(path, line, col, msg)

    for lineno, raw in enumerate(text.split("\n"), start=1):
        line = raw.rstrip("\r")
        stripped = line.strip()
        if not stripped or stripped.startswith("#"):
            continue
        col0 = len(line) - len(line.lstrip()) + 1
        if ended:
            raise err(lineno, col0, "text after '.e' (end of PLA)")
        if stripped.startswith("."):
            parts = stripped.split()
            kw = parts[0][1:]
            args = parts[1:]
            if kw in ("i", "o"):
                if (n if kw == "i" else m) is not None:
                    raise err(lineno, col0, f"'.{kw}' given twice")
                if len(args) != 1 or not _WHOLE.match(args[0]) or len(args[0]) > 6:
                    raise err(lineno, col0 + len(kw) + 2 if args else col0,
                              f"expected one whole number after '.{kw}'")
                val = int(args[0])
                if kw == "i":
                    if val < 1:
                        raise err(lineno, col0, "'.i' must be at least 1")
                    n = val
                else:
                    if n is None:
                        raise err(lineno, col0, "'.o' must come after '.i'")
                    if val < 1:
                        raise err(lineno, col0, "'.o' must be at least 1")
                    m = val
            elif kw in ("ilb", "ob"):
                count = n if kw == "ilb" else m
                if count is None:
                    raise err(lineno, col0, f"'.{kw}' must come after '.i' and '.o'")
                if len(args) != count:
                    raise err(lineno, col0, f"'.{kw}' lists {len(args)} names, expected {count}")
                for a in args:
                    if not _NAME_CHARS.match(a):
                        raise err(lineno, line.find(a) + 1,
                                  f"name {shorten(a)} has a character espresso does not "
                                  "accept in a name")
                if len(set(args)) != len(args):
                    raise err(lineno, col0, f"duplicate name in '.{kw}'")
                if kw == "ilb":
                    ilb = args
                else:
                    ob = args
            elif kw == "p":
                if len(args) != 1 or not _WHOLE.match(args[0]):
                    raise err(lineno, col0, "expected one whole number after '.p'")
            elif kw == "type":
                if len(args) != 1 or args[0] not in TYPES:
                    raise err(lineno, col0, f"expected one of {' '.join(sorted(TYPES))} after "
                              "'.type'")
                if saw_term_line is not None:
                    raise err(lineno, col0, "'.type' must come before the product terms")
                pla_type = args[0]
            elif kw in ("e", "end"):
                ended = True
            elif kw in UNSUPPORTED:
                raise err(lineno, col0, f"'.{kw}' is not supported by mechc (binary-valued "
                          "PLAs with .i/.o only)")
            else:
                raise err(lineno, col0, f"unknown keyword {shorten('.' + kw)}: expected one of "
                          ".i .o .ilb .ob .p .type .e")
            continue
        # a product term
        if n is None or m is None:
            raise err(lineno, col0, "product term before '.i' and '.o'")
        saw_term_line = saw_term_line or lineno
        chars = [(i + 1, ch) for i, ch in enumerate(line) if ch not in " \t|"]
        if len(chars) != n + m:
            raise err(lineno, col0, f"product term has {len(chars)} characters, expected "
                      f"{n} inputs + {m} outputs = {n + m}")
        mask = value = 0
        empty = False
        for k, (col, ch) in enumerate(chars[:n]):
            bit = 1 << (n - 1 - k)
            if ch == "1":
                mask |= bit
                value |= bit
            elif ch == "0":
                mask |= bit
            elif ch == "?":
                empty = True
            elif ch not in "-2":
                raise err(lineno, col, f"bad input-plane character {ch!r}: expected 0 1 - 2 ?")
        out_chars = chars[n:]
        for col, ch in out_chars:
            if ch not in "01234-~":
                raise err(lineno, col, f"bad output-plane character {ch!r}: expected "
                          "1 4 0 3 - 2 ~")
        outs = "".join(ch for _, ch in out_chars)
        terms.append((lineno, tuple(c for c, _ in out_chars), None if empty else Cube(mask, value),
                      outs))

    if n is None:
        raise err(1, 1, "empty PLA: expected '.i' (number of inputs)" if not text.strip()
                  else "missing '.i' (number of inputs)")
    if m is None:
        raise err(1, 1, "missing '.o' (number of outputs)")
    inputs = ilb or [f"x{k}" for k in range(n)]
    outputs = ob or [f"f{k}" for k in range(m)]
    clash = set(inputs) & set(outputs)
    if clash:
        raise err(1, 1, f"name used for both an input and an output: {sorted(clash)[0]}")
    safe = safe_names(inputs + outputs)
    display = {safe[a]: a for a in inputs + outputs if safe[a] != a}
    inputs = [safe[a] for a in inputs]
    outputs = [safe[a] for a in outputs]
    funcs = {name: OutputSpec(name) for name in outputs}
    rest = {"f": 0, "fd": 0, "fr": DC, "fdr": DC, "r": 1, "dr": 1}[pla_type]
    for f in funcs.values():
        f.rest = rest
    for _lineno, _col, cube, outs in terms:
        if cube is None:
            continue
        for j, ch in enumerate(outs):
            f = funcs[outputs[j]]
            if ch in "14" and "f" in pla_type:
                f.on.append(cube)
            elif ch in "03" and "r" in pla_type:
                f.off.append(cube)
            elif ch in "2-" and "d" in pla_type:
                f.dc.append(cube)
    _check_on_off(path, n, funcs, terms, outputs, display)
    return Spec(path, "pla", inputs, outputs, funcs, display)


def safe_names(names: list[str]) -> dict[str, str]:
    """Each name -> an identifier (letters, digits, '_', not starting with a digit), unique
    among them: ``di<11>`` -> ``di_11``, ``x[3]`` -> ``x_3``; names already safe stay."""
    out: dict[str, str] = {}
    taken = {a for a in names if _NAME_OK.match(a)}
    for a in names:
        if _NAME_OK.match(a):
            out[a] = a
            continue
        base = re.sub(r"[^A-Za-z0-9_]+", "_", a).strip("_") or "s"
        if base[0].isdigit():
            base = "s" + base
        cand, k = base, 2
        while cand in taken:
            cand, k = f"{base}_{k}", k + 1
        taken.add(cand)
        out[a] = cand
    return out


def _check_on_off(path, n, funcs, terms, outputs, display) -> None:
    """Espresso refuses a PLA whose on-set and off-set meet; so do we, naming both lines."""
    for j, name in enumerate(outputs):
        f = funcs[name]
        if not f.on or not f.off:
            continue
        if n <= MAX_TABLE_INPUTS:
            clash = cube_table(f.on, n) & cube_table(f.off, n) & ~cube_table(f.dc, n)
            if not clash.any():
                continue
            point = Cube.minterm(int(np.flatnonzero(clash)[0]), n)
        else:
            point = None
        for lineno, cols, cube, outs in terms:
            if cube is None or outs[j] not in "14":
                continue
            for lineno2, _c2, cube2, outs2 in terms:
                if cube2 is None or outs2[j] not in "03":
                    continue
                if point is not None:
                    if not (cube.contains(point) and cube2.contains(point)):
                        continue
                    meet = point
                else:
                    if not cube.intersects(cube2):
                        continue
                    meet = Cube(cube.mask | cube2.mask, cube.value | cube2.value)
                    if any(d.contains(meet) for d in f.dc):
                        continue
                raise SpecError(path, lineno, cols[j],
                                f"output '{display.get(name, name)}': this on-set term meets "
                                f"the off-set term of line {lineno2} "
                                f"(at input {meet.to_string(n)})")
