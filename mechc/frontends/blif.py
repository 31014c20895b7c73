"""Front end for combinational BLIF (``.model .inputs .outputs .names .end``).

A BLIF model is a network of single-output nodes, each a ``.names`` cover: lines ``CUBE 1``
give the node's on-set, lines ``CUBE 0`` its off-set (the node is 1 outside them), no line
at all makes it constant 0. Up to :data:`MAX_TABLE_INPUTS` primary inputs the network is
evaluated on every input vector (numpy, one boolean array per node) and each output's truth
table is written back as an irredundant cube cover: the same :class:`~mechc.ir.spec.Spec` a
``.pla`` gives. Wider models (a 16-bit adder has 33 inputs) are valued by the network alone
(``Spec.network``): no table is built, the proofs simulate or SAT-encode the nodes, and the
compiler synthesises them multi-level. Sequential and hierarchical constructs
(``.latch``, ``.subckt``, ``.gate``, ``.exdc``, ...) are refused with their line and column.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

import numpy as np

from mechc.errors import SpecError
from mechc.frontends.lexer import Word, read_text
from mechc.ir.network import NamesNode, Network
from mechc.ir.spec import OutputSpec, Spec
from mechc.logic.cubes import MAX_TABLE_INPUTS, Cube, input_matrix

#: Beyond this many primary inputs the spec is valued by its network, not a truth table.
TABLE_MAX_BLIF_INPUTS = MAX_TABLE_INPUTS
_NAME_OK = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")
UNSUPPORTED = {
    ".latch": "latches (sequential BLIF; write the machine as a .fsm or .kiss2 flow table)",
    ".mlatch": "latches (sequential BLIF; write the machine as a .fsm or .kiss2 flow table)",
    ".clock": "clocks (sequential BLIF)",
    ".subckt": "subcircuits (hierarchical BLIF; flatten the model first)",
    ".search": "included files (hierarchical BLIF; flatten the model first)",
    ".gate": "library gates (mapped BLIF; write the logic as .names covers)",
    ".exdc": "external don't-care networks (give don't-cares in a .pla or .bool instead)",
    ".start_kiss": "embedded state tables (put the table in a .kiss2 file)",
}


@dataclass
class Node:
    """One ``.names`` node: fanins, its output and its cover (all on-set or all off-set)."""

    out: Word
    fanins: list[Word]
    cubes: list[str] = field(default_factory=list)
    phase: int | None = None  # 1: cubes are the on-set, 0: the off-set, None: no cube
    phase_word: Word | None = None


def parse_blif_file(path: str) -> Spec:
    return parse_blif(read_text(path), str(path))


def parse_blif(text: str, path: str = "<string>") -> Spec:
    inputs, outputs, nodes = _read(text, path)
    order = _topological(nodes, inputs, outputs, path)
    # every node, dangling ones too, as the author wrote them: what synthesis starts from
    structure = network_of(inputs, outputs, nodes, order, cone_only=False).to_blif()
    network = network_of(inputs, outputs, nodes, order)
    names_in, names_out = [w.text for w in inputs], [w.text for w in outputs]
    if len(inputs) > TABLE_MAX_BLIF_INPUTS:  # valued by the network: no 2**n anything
        funcs = {o.text: OutputSpec(o.text, line=nodes[o.text].out.line) for o in outputs}
        return Spec(path, "pla", names_in, names_out, funcs, structure=structure,
                    network=network)
    mat = input_matrix(len(inputs))
    tables = network.evaluate({x: mat[k] for k, x in enumerate(names_in)})
    funcs = {}
    for o in outputs:
        funcs[o.text] = OutputSpec(o.text, on=table_cover(tables[o.text], len(inputs)),
                                   line=nodes[o.text].out.line)
    return Spec(path, "pla", names_in, names_out, funcs, structure=structure)


def network_of(inputs: list[Word], outputs: list[Word], nodes: dict[str, Node],
               order: list[str], cone_only: bool = True) -> Network:
    """The nodes in evaluation order as the IR's network: those the outputs depend on, or
    with ``cone_only=False`` every node (the clean BLIF text the spec keeps as its
    structure, one line per cube, no comments or continuations)."""
    needed = _cone(nodes, outputs) if cone_only else set(order)
    return Network([w.text for w in inputs], [w.text for w in outputs],
                   [NamesNode(name, tuple(f.text for f in nodes[name].fanins),
                              tuple(nodes[name].cubes),
                              0 if nodes[name].phase == 0 else 1)
                    for name in order if name in needed])


def logical_lines(text: str) -> list[list[Word]]:
    """Non-empty lines as words, ``#`` comments removed and ``\\`` continuations joined."""
    out: list[list[Word]] = []
    cur: list[Word] = []
    for lineno, raw in enumerate(text.split("\n"), start=1):
        line = raw.rstrip("\r")
        cut = line.find("#")
        if cut >= 0:
            line = line[:cut]
        body = line.rstrip()
        cont = body.endswith("\\")
        if cont:
            body = body[:-1]
        cur.extend(Word(m.group(), lineno, m.start() + 1) for m in re.finditer(r"\S+", body))
        if not cont and cur:
            out.append(cur)
            cur = []
    if cur:
        out.append(cur)
    return out


def _read(text: str, path: str) -> tuple[list[Word], list[Word], dict[str, Node]]:
    def err(w: Word, msg: str) -> SpecError:
        return SpecError(path, w.line, w.col, msg)

    inputs: list[Word] = []
    outputs: list[Word] = []
    nodes: dict[str, Node] = {}
    model: Word | None = None
    node: Node | None = None
    ended: Word | None = None
    for words in logical_lines(text):
        head = words[0]
        kw = head.text
        if ended is not None:
            if kw == ".model":
                raise err(head, "a second '.model': mechc reads one model per file "
                          "(hierarchical BLIF is not supported)")
            raise err(head, f"text after '.end' (line {ended.line})")
        if not kw.startswith("."):
            if node is None:
                raise err(head, "a cover line outside '.names' (expected a keyword such as "
                          "'.names', '.inputs' or '.outputs')")
            _cover_line(node, words, err)
            continue
        node = None
        if kw == ".model":
            if model is not None:
                raise err(head, f"'.model' given twice (first on line {model.line}): mechc "
                          "reads one model per file")
            if inputs or outputs or nodes:
                raise err(head, "'.model' must come first")
            model = head
        elif kw in (".inputs", ".outputs"):
            into = inputs if kw == ".inputs" else outputs
            if len(words) == 1:
                raise err(head, f"expected signal names after '{kw}'")
            for w in words[1:]:
                if not _NAME_OK.match(w.text):
                    raise err(w, f"name '{w.text}' is not usable as a primary {kw[1:-1]} name "
                              "(letters, digits and '_', not starting with a digit)")
                if any(v.text == w.text for v in into):
                    raise err(w, f"'{w.text}' is listed twice in '{kw}'")
                into.append(w)
        elif kw == ".names":
            if len(words) == 1:
                raise err(head, "expected signal names after '.names' (fanins, then the "
                          "node's output)")
            out = words[-1]
            if out.text in nodes:
                raise err(out, f"signal '{out.text}' is driven twice (first by the '.names' on "
                          f"line {nodes[out.text].out.line})")
            nodes[out.text] = node = Node(out, words[1:-1])
        elif kw == ".end":
            if len(words) > 1:
                raise err(words[1], "expected end of line after '.end'")
            ended = head
        elif kw in UNSUPPORTED:
            raise err(head, f"'{kw}' is not supported: {UNSUPPORTED[kw]}; mechc reads "
                      "combinational BLIF (.model .inputs .outputs .names .end)")
        else:
            raise err(head, f"unknown keyword '{kw}' (mechc reads combinational BLIF: .model "
                      ".inputs .outputs .names .end)")
    if not inputs:
        w = model or Word("", 1, 1)
        raise err(w, "no '.inputs': a BLIF model needs at least one primary input")
    if not outputs:
        w = model or Word("", 1, 1)
        raise err(w, "no '.outputs': a BLIF model needs at least one primary output")
    in_names = {w.text: w for w in inputs}
    for o in outputs:
        if o.text in in_names:
            raise err(o, f"output '{o.text}' is also a primary input: mechc keeps outputs "
                      f"apart from inputs; drive a new output through a buffer ('.names "
                      f"{o.text} {o.text}_out' then '1 1') and list that")
    for name, nd in nodes.items():
        if name in in_names:
            raise err(nd.out, f"'.names' drives '{name}', which is a primary input")
    return inputs, outputs, nodes


def _cover_line(node: Node, words: list[Word], err) -> None:
    k = len(node.fanins)
    want = 2 if k else 1
    if len(words) != want:
        shape = "an input cube and an output value (e.g. '1-0 1')" if k else \
            "one output value ('1' for a constant 1)"
        raise err(words[0], f"a cover line of '.names ... {node.out.text}' with {k} fanin(s) "
                  f"has {shape}; found {len(words)} field(s)")
    if k:
        cube = words[0]
        for i, ch in enumerate(cube.text):
            if ch not in "01-":
                raise err(Word(ch, cube.line, cube.col + i),
                          f"bad cube character {ch!r}: expected 0 1 -")
        if len(cube.text) != k:
            raise err(cube, f"cube '{cube.text}' has {len(cube.text)} character(s); expected "
                      f"{k} (one per fanin of {node.out.text})")
    ow = words[-1]
    if ow.text not in ("0", "1"):
        raise err(ow, f"expected output value 0 or 1, found '{ow.text}'")
    phase = int(ow.text)
    if node.phase is not None and phase != node.phase:
        raise err(ow, f"output value {phase} but the cover of {node.out.text} gives "
                  f"{node.phase} on line {node.phase_word.line}: a '.names' cover is all "
                  "on-set (1) or all off-set (0)")
    if node.phase is None:
        node.phase, node.phase_word = phase, ow
    node.cubes.append(words[0].text if k else "")


def _topological(nodes: dict[str, Node], inputs: list[Word], outputs: list[Word],
                 path: str) -> list[str]:
    """Nodes in evaluation order (every node, so an undefined signal or a loop anywhere is
    reported); undefined signals and combinational cycles are errors."""
    known = {w.text for w in inputs}
    for o in outputs:
        if o.text not in nodes:
            raise SpecError(path, o.line, o.col, f"output '{o.text}' is never driven (no "
                            "'.names' has it as output)")
    for nd in nodes.values():
        for f in nd.fanins:
            if f.text not in nodes and f.text not in known:
                raise SpecError(path, f.line, f.col, f"signal '{f.text}' is used but never "
                                "defined (not a primary input, and no '.names' drives it)")
    order: list[str] = []
    state: dict[str, int] = {}  # 1 on the current path, 2 done
    for root in nodes:
        if state.get(root):
            continue
        stack = [(root, 0)]
        state[root] = 1
        while stack:
            name, i = stack[-1]
            fanins = nodes[name].fanins
            if i < len(fanins):
                stack[-1] = (name, i + 1)
                f = fanins[i].text
                if f not in nodes or state.get(f) == 2:
                    continue
                if state.get(f) == 1:
                    path_names = [s for s, _ in stack]
                    loop = path_names[path_names.index(f):] + [f]
                    w = nodes[f].out
                    raise SpecError(path, w.line, w.col, "combinational cycle: "
                                    + " -> ".join(loop) + " (each signal is a fanin of the next"
                                    "; BLIF networks must be acyclic)")
                state[f] = 1
                stack.append((f, 0))
            else:
                state[name] = 2
                order.append(name)
                stack.pop()
    return order


def _cone(nodes: dict[str, Node], outputs: list[Word]) -> set[str]:
    """Nodes the outputs depend on."""
    seen: set[str] = set()
    todo = [o.text for o in outputs]
    while todo:
        name = todo.pop()
        if name in seen or name not in nodes:
            continue
        seen.add(name)
        todo.extend(f.text for f in nodes[name].fanins)
    return seen


def table_cover(table: np.ndarray, n: int) -> list[Cube]:
    """An irredundant cover of the 1-entries of a boolean truth table (input 0 is the most
    significant bit of the index).

    Minato–Morreale ISOP, so the spec echo stays close to the size of a hand-written cover
    (an OR of k products comes back as k cubes, not as the 2^k disjoint pieces a plain Shannon
    split gives); the minimiser still does the real work."""
    t = np.asarray(table, dtype=bool)
    return sorted(_isop(t, t, n, 0, 0, 0)[0])


def _isop(lo: np.ndarray, up: np.ndarray, n: int, k: int, mask: int,
          value: int) -> tuple[list[Cube], np.ndarray]:
    """Cubes between ``lo`` and ``up`` (lo <= cover <= up) on the subspace where inputs < k are
    fixed by (mask, value); returns them with the table of their union on that subspace."""
    if not lo.any():
        return [], np.zeros(len(lo), dtype=bool)
    if up.all():
        return [Cube(mask, value)], np.ones(len(lo), dtype=bool)
    half = len(lo) // 2
    l0, l1, u0, u1 = lo[:half], lo[half:], up[:half], up[half:]
    bit = 1 << (n - 1 - k)
    c0, r0 = _isop(l0 & ~u1, u0, n, k + 1, mask | bit, value)  # needs input k = 0
    c1, r1 = _isop(l1 & ~u0, u1, n, k + 1, mask | bit, value | bit)  # needs input k = 1
    rest = (l0 & ~r0) | (l1 & ~r1)
    cs, rs = _isop(rest, u0 & u1, n, k + 1, mask, value)  # independent of input k
    return c0 + c1 + cs, np.concatenate((r0 | rs, r1 | rs))
