"""The positions file: prescribed positions for ``mechc synth dyad|triad``.

A plain-text table, one position per line, '#' starts a comment::

    # Figure 4 of Mather & Erdman (2023): a dyad in four positions
    x     y     alpha   beta
    0     0     0       0
    1.75  1     -50     -110
    3.5   2     -90     ?
    5.5   1     -110    ?

* The header names the columns: ``x`` and ``y`` (the precision point, any length unit) and the
  rotation of each link from position 1 in degrees -- ``beta`` (first link W), ``alpha``
  (second link Z) and, for a triad, ``gamma`` (third link V).  A dyad has beta and alpha, a
  triad all three.
* ``?`` marks an unknown angle.  Unknowns may appear in one angle column only: that link is the
  free link, and its given values (after position 1) are the free choices.  A column left
  entirely as ``?`` after position 1 asks mechc to search for the free choices.
* An optional directive line ``free NAME`` names the free link when no column has unknowns.
* Row 1 is the reference position: its angles must be 0 (or ``?``).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from mechc.errors import SpecError, UsageError
from mechc.linkage_synthesis.mk_circles import (
    ANGLE_NAMES,
    ChainProblem,
    SynthesisError,
    chain_problem,
)

UNKNOWN = {"?", "*"}


def parse_positions(text: str, path: str = "<positions>") -> ChainProblem:
    header: list[str] | None = None
    free: str | None = None
    rows: list[tuple[int, list[str]]] = []
    for ln, raw in enumerate(text.splitlines(), start=1):
        line = raw.split("#", 1)[0]
        if not line.strip():
            continue
        toks = line.split()
        cols = _token_cols(line)
        col = cols[0]
        if toks[0].lower() == "free":
            if len(toks) != 2 or toks[1].lower() not in ANGLE_NAMES:
                raise SpecError(path, ln, col, "expected 'free beta', 'free alpha' or "
                                "'free gamma'")
            free = toks[1].lower()
            continue
        if header is None:
            names = [t.lower() for t in toks]
            bad = [t for t in names if t not in ("x", "y", *ANGLE_NAMES)]
            if bad:
                raise SpecError(path, ln, cols[names.index(bad[0])], f"unknown column "
                                f"'{bad[0]}': expected x, y, beta, alpha, gamma")
            if len(set(names)) != len(names):
                raise SpecError(path, ln, col, "a column name appears twice")
            if "x" not in names or "y" not in names:
                raise SpecError(path, ln, col, "the header must name the columns x and y")
            header = names
            continue
        if len(toks) != len(header):
            raise SpecError(path, ln, col, f"expected {len(header)} values "
                            f"({' '.join(header)}), found {len(toks)}")
        rows.append((ln, toks, cols))
    if header is None:
        raise SpecError(path, 1, 1, "empty positions file: expected a header line "
                        "such as 'x y alpha beta'")
    if not rows:
        raise SpecError(path, 1, 1, "no positions after the header")
    points, angles = [], {n: [] for n in header if n in ANGLE_NAMES}
    for ln, toks, cols in rows:
        vals = dict(zip(header, toks))
        where = dict(zip(header, cols))
        xy = []
        for name in ("x", "y"):
            try:
                xy.append(float(vals[name]))
            except ValueError:
                raise SpecError(path, ln, where[name], f"{name}: expected a number, got "
                                f"'{vals[name]}'") from None
        points.append(complex(*xy))
        for name in angles:
            v = vals[name]
            if v in UNKNOWN:
                angles[name].append(None)
                continue
            try:
                angles[name].append(float(v))
            except ValueError:
                raise SpecError(path, ln, where[name],
                                f"{name}: expected degrees or '?', got '{v}'") from None
    try:
        return chain_problem(points, angles, free=free)
    except SynthesisError as e:
        raise SpecError(path, rows[0][0], 1, str(e)) from None


def _token_cols(line: str) -> list[int]:
    """1-based column of each whitespace-separated token."""
    cols, i = [], 0
    for tok in line.split():
        i = line.index(tok, i)
        cols.append(i + 1)
        i += len(tok)
    return cols


def load_positions(path: str) -> ChainProblem:
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise UsageError(f"{path}: no such positions file") from None
    except (OSError, UnicodeDecodeError) as e:
        raise UsageError(f"{path}: cannot read: {e}") from None
    return parse_positions(text, str(path))


def format_positions(problem: ChainProblem, comment: str = "") -> str:
    """The problem as a positions file (inverse of :func:`parse_positions`)."""
    names = list(ANGLE_NAMES[: problem.k])
    lines = [f"# {comment}"] if comment else []
    lines.append(f"free {ANGLE_NAMES[problem.free_link]}")
    lines.append("\t".join(["x", "y", *names]))
    for j, p in enumerate(problem.points):
        row = [repr(float(p.real)), repr(float(p.imag))]
        for l in range(problem.k):
            a = problem.angles[l, j]
            row.append("?" if np.isnan(a) else repr(float(np.degrees(a))))
        lines.append("\t".join(row))
    return "\n".join(lines) + "\n"
