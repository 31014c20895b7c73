"""Write docs/builder-api.md, the reference of :class:`mechc.cells.builder.Builder`, from the
code's own signatures and docstrings, so the reference cannot drift from the code.

    python -m mechc.cells.api_doc           # rewrite docs/builder-api.md
    python -m mechc.cells.api_doc --check   # exit 1 if the file is not what the code gives

A test runs the check, and checks that every public Builder method is in it with its signature.
"""

from __future__ import annotations

import argparse
import inspect
import sys
from pathlib import Path

from mechc.cells import builder

DOC = Path(__file__).resolve().parents[2] / "docs" / "builder-api.md"

HEADER = """\
# Builder API reference

Generated from the docstrings of `mechc/cells/builder.py` by `python -m mechc.cells.api_doc`;
do not edit by hand (a test fails when this file and the code disagree). How to write a cell
with these calls: docs/write-a-cell.md.

Conventions: lengths in mm, forces in N; `S` is `ctx.stroke`; every position is at the design
pose (every signal at half stroke); `Point` is an `(x, y)` tuple; a `Demand(right, left)` is the
force a signal must deliver each way.
"""


def public_methods() -> list[tuple[str, object]]:
    """Builder's public methods in source order."""
    out = [(n, f) for n, f in vars(builder.Builder).items()
           if inspect.isfunction(f) and not n.startswith("_")]
    return sorted(out, key=lambda nf: inspect.getsourcelines(nf[1])[1])


def signature(f, drop_self: bool = True) -> str:
    sig = inspect.signature(f, eval_str=True)
    params = list(sig.parameters.values())[1 if drop_self else 0:]
    return str(sig.replace(parameters=params)).replace("typing.", "")


def render() -> str:
    parts = [HEADER]
    parts.append("## Helpers\n")
    parts.append(f"### `rect{signature(builder.rect, False)}`\n\n"
                 f"{inspect.getdoc(builder.rect)}\n")
    sig_sig = signature(builder.Sig, False).removesuffix(" -> None")
    parts.append(f"### `Sig{sig_sig}`\n\n{inspect.getdoc(builder.Sig)}\n")
    parts.append(f"## `Builder{signature(builder.Builder.__init__)}`\n\n"
                 f"{inspect.getdoc(builder.Builder)}\n")
    parts.append("| method | first line |\n|---|---|")
    for n, f in public_methods():
        first = (inspect.getdoc(f) or "").split("\n\n")[0].replace("\n", " ")
        parts.append(f"| [`{n}`](#{n.replace('_', '-')}) | {first} |")
    parts.append("")
    for n, f in public_methods():
        doc = inspect.getdoc(f) or "(no docstring)"
        parts.append(f"### {n}\n\n```python\nb.{n}{signature(f)}\n```\n\n{doc}\n")
    return "\n".join(parts).rstrip("\n") + "\n"


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--check", action="store_true", help="exit 1 if the file is out of date")
    args = p.parse_args(argv)
    text = render()
    if args.check:
        ok = DOC.exists() and DOC.read_text(encoding="utf-8") == text
        print(f"{DOC}: {'up to date' if ok else 'out of date: run python -m mechc.cells.api_doc'}")
        return 0 if ok else 1
    DOC.write_text(text, encoding="utf-8")
    print(f"wrote {DOC}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
