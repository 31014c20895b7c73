"""``mechc draw``: the SVG is valid XML, to scale, shows each state's pose and output values, and
the command fails cleanly (exit 2, one line, nothing overwritten) on bad input.

References are independent of the drawing code: output values come from the spec's own minterm
lists and from binary addition; distances come from the design JSON and from rigid-body facts
(an input or output slider travels one stroke from off to on, a lever pin keeps its radius).
"""

from __future__ import annotations

import json
import math
import re
import xml.etree.ElementTree as ET

import numpy as np
import pytest

from mechc.backends.design_json import design_to_json, dumps
from mechc.backends.svg import SCALE_BAR_MM, draw_svg, parse_state
from mechc.errors import UsageError
from mechc.frontends import load_spec
from mechc.pipeline import compile_spec
from tests.helpers import EXAMPLES

NS = "{http://www.w3.org/2000/svg}"

# examples/sorter.bool: A is the most significant bit of A B C D
SORTER_ON = {3, 6, 9, 15}
SORTER_DC = {4, 7, 8, 11}


@pytest.fixture(scope="module")
def sorter():
    return compile_spec(load_spec(str(EXAMPLES / "sorter.bool")))


@pytest.fixture(scope="module")
def adder():
    return compile_spec(load_spec(str(EXAMPLES / "full_adder.bool")))


@pytest.fixture
def sorter_json(sorter, tmp_path):
    p = tmp_path / "sorter.json"
    p.write_text(dumps(design_to_json(sorter)))
    return p


def _state(names, m):
    n = len(names)
    return {k: (m >> (n - 1 - i)) & 1 for i, k in enumerate(names)}


def _outputs(svg: str) -> dict[str, int]:
    """Output values as the drawing's labels state them."""
    root = ET.fromstring(svg)
    out = {}
    for t in root.iter(f"{NS}text"):
        m = re.fullmatch(r"(\w+) = ([01]) \((on|off)\)", (t.text or "").strip())
        if m and "halo" not in t.get("class", ""):
            assert (m.group(2) == "1") == (m.group(3) == "on")
            out[m.group(1)] = int(m.group(2))
    return out


def _body_polys(svg: str, body: str) -> list[np.ndarray]:
    """Polygons (px) of a body's own outline (not the fan-out bars added to it)."""
    root = ET.fromstring(svg)
    for g in root.iter(f"{NS}g"):
        if g.get("data-body") == body and g.get("class") != "cn":
            d = next(p for p in g if p.get("class") == "f").get("d")
            return [np.array([[float(v) for v in xy.split(",")] for xy in sub.split("L")])
                    for sub in re.findall(r"M([^MZ]+)Z", d)]
    raise AssertionError(f"body {body} not drawn")


def _cell_box(svg: str, cid: str) -> tuple[str, ...]:
    r = next(r for r in ET.fromstring(svg).iter(f"{NS}rect") if r.get("data-cell") == cid)
    return tuple(r.get(k) for k in ("x", "y", "width", "height"))


def _circle(svg: str, cls: str, key: str, value: str) -> np.ndarray:
    root = ET.fromstring(svg)
    for c in root.iter(f"{NS}circle"):
        if c.get("class") == cls and c.get(key) == value:
            return np.array([float(c.get("cx")), float(c.get("cy"))])
    raise AssertionError(f"no {cls} circle for {value}")


def test_valid_xml_and_every_body_drawn(sorter, adder):
    for design in (sorter, adder):
        for m in (0, (1 << len(design.netlist.inputs)) - 1):
            svg = draw_svg(design, _state(design.netlist.inputs, m))
            root = ET.fromstring(svg)
            assert root.tag == f"{NS}svg"
            assert float(root.get("width")) > 0 and float(root.get("height")) > 0
            drawn = {g.get("data-body") for g in root.iter(f"{NS}g") if g.get("data-body")}
            assert drawn == set(design.mechanism.body_index())
            cells = {r.get("data-cell") for r in root.iter(f"{NS}rect") if r.get("data-cell")}
            assert cells == set(design.netlist.cells)
            assert len(svg) < 200_000  # a few dozen parts: tens of KB, not megabytes


def test_sorter_outputs_match_spec_in_every_state(sorter):
    for m in range(16):
        if m in SORTER_DC:
            continue
        svg = draw_svg(sorter, _state(["A", "B", "C", "D"], m))
        assert _outputs(svg) == {"Z": int(m in SORTER_ON)}, m


def test_full_adder_outputs_are_binary_sum(adder):
    names = list(adder.netlist.inputs)
    for m in range(8):
        st = _state(names, m)
        total = st["a"] + st["b"] + st["cin"]
        assert _outputs(draw_svg(adder, st)) == {"s": total & 1, "cout": total >> 1}


def test_state_change_moves_output_by_one_stroke(sorter):
    scale = 2.0
    S = sorter.mechanism.ctx.stroke
    off = draw_svg(sorter, {}, scale)
    on = draw_svg(sorter, {"C": 1, "D": 1}, scale)  # minterm 3 = 0011: Z on (sorter.bool)
    assert off != on
    assert _outputs(off) == {"Z": 0} and _outputs(on) == {"Z": 1}
    # ground does not move: the two drawings share one frame (pivots, cell boxes)
    for cid in sorter.netlist.cells:
        assert _cell_box(off, cid) == _cell_box(on, cid)
    owner, pin = sorter.mechanism.outputs["Z"]
    body = sorter.mechanism.owner_part(owner).terminals[pin].body
    for b in (body, "in:C.slider", "in:D.slider"):
        for p0, p1 in zip(_body_polys(off, b), _body_polys(on, b)):
            # off -> on is one stroke to the right (SVG x) and no vertical motion; 0.1 px rounding
            assert np.allclose(p1[:, 0] - p0[:, 0], S * scale, atol=0.11), b
            assert np.allclose(p1[:, 1], p0[:, 1], atol=0.11), b
    # inputs not named stay put
    for p0, p1 in zip(_body_polys(off, "in:A.slider"), _body_polys(on, "in:A.slider")):
        assert np.allclose(p0, p1)


@pytest.mark.parametrize("scale", [1.0, 2.0, 3.5])
def test_scale_bar_and_geometry_to_scale(sorter, scale):
    svg = draw_svg(sorter, {}, scale)
    bar = ET.fromstring(svg).find(f".//{NS}line[@id='scalebar']")
    assert float(bar.get("x2")) - float(bar.get("x1")) == pytest.approx(SCALE_BAR_MM * scale,
                                                                        abs=0.01)
    # a drawn part has its JSON size times the scale (independent of the bar)
    body = sorter.mechanism.inputs["A"].bodies[0]
    mm = np.array(body.outline[0])
    px = _body_polys(svg, body.id)[0]
    assert np.ptp(px[:, 0]) == pytest.approx(np.ptp(mm[:, 0]) * scale, abs=0.11)
    assert np.ptp(px[:, 1]) == pytest.approx(np.ptp(mm[:, 1]) * scale, abs=0.11)


def _joint_ends(root, jid: str, tag: str, cls: str) -> tuple[np.ndarray, np.ndarray]:
    el = next(e for e in root.iter(f"{NS}{tag}") if e.get("data-joint") == jid
              and e.get("class") == cls)
    return (np.array([float(el.get("x1")), float(el.get("y1"))]),
            np.array([float(el.get("x2")), float(el.get("y2"))]))


@pytest.mark.parametrize("which", ["sorter", "adder"])
def test_joints_hold_in_every_state(which, request):
    """In every drawn state: each rod keeps its length, each groove's pin lies on its slot,
    and each point pinned to a lever stays at its design distance from the pivot (the lever is
    rigid). Tolerances cover the 0.1 px rounding of the SVG."""
    design = request.getfixturevalue(which)
    scale = 2.0
    mech = design.mechanism
    joints = [j for p in mech.all_parts() for j in p.joints if j.kind in ("rod", "groove")]
    bodies = mech.body_index()
    assert joints
    names = list(design.netlist.inputs)
    for m in range(1 << len(names)):
        svg = draw_svg(design, _state(names, m), scale)
        root = ET.fromstring(svg)
        for j in joints:
            if j.kind == "rod":
                a, b = _joint_ends(root, j.id, "line", "rod")
                assert np.hypot(*(b - a)) == pytest.approx(j.length * scale, abs=0.2), j.id
                ends = [(j.a, j.pa, a), (j.b, j.pb, b)]
            else:
                pin = _circle(svg, "pin", "data-joint", j.id)
                a, b = _joint_ends(root, j.id, "line", "slo")
                d = (b - a) / np.hypot(*(b - a))
                assert abs(np.cross(d, pin - a)) < 0.2, j.id  # on the slot's line
                assert -0.2 <= np.dot(d, pin - a) <= np.hypot(*(b - a)) + 0.2, j.id
                ends = [(j.b, j.q, pin)]
            for bid, design_pt, drawn in ends:
                lever = bodies.get(bid)
                if lever is None or lever.kind != "lever":
                    continue
                piv = _circle(svg, "pv", "data-body", bid)
                r_mm = math.hypot(design_pt[0] - lever.pivot[0], design_pt[1] - lever.pivot[1])
                assert np.hypot(*(drawn - piv)) == pytest.approx(r_mm * scale, abs=0.2), j.id


def test_no_labels(sorter):
    root = ET.fromstring(draw_svg(sorter, {}, labels=False))
    classes = {t.get("class") for t in root.iter(f"{NS}text")}
    assert not classes & {"lc", "ln", "li0", "li1", "lo0", "lo1"}
    assert "tt" in classes  # the title stays


@pytest.mark.parametrize("state, word", [({"Q": 1}, "Q"), ({"A": 2}, "A")])
def test_draw_svg_rejects_bad_state(sorter, state, word):
    with pytest.raises(UsageError, match=word):
        draw_svg(sorter, state)


def test_parse_state():
    assert parse_state("A=1, B=off C=on", ["A", "B", "C", "D"]) == {"A": 1, "B": 0, "C": 1,
                                                                     "D": 0}
    for bad in ("A", "A=1,A=0", "=1", "E=1", "A=yes"):
        with pytest.raises(UsageError):
            parse_state(bad, ["A", "B"])


@pytest.mark.parametrize("args, word", [
    (["--state", "Q=1"], "unknown input 'Q'"),
    (["--state", "A=2"], "must be 0 or 1"),
    (["--state", "A"], "expected NAME=0"),
    (["--scale", "0"], "--scale"),
])
def test_cli_bad_input_exit_2_one_line_file_untouched(cli, sorter_json, tmp_path, args, word):
    out = tmp_path / "out.svg"
    out.write_text("precious\n")
    code, stdout, err = cli("draw", sorter_json, "-o", out, *args)
    assert code == 2
    assert len(err.strip().splitlines()) == 1 and word in err
    assert "Traceback" not in err
    assert out.read_text() == "precious\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.svg", "sorter.json"]


def test_cli_missing_file_and_no_geometry(cli, sorter_json, tmp_path):
    code, _, err = cli("draw", tmp_path / "nope.json")
    assert code == 2 and "not found" in err and len(err.strip().splitlines()) == 1
    obj = json.loads(sorter_json.read_text())
    del obj["mechanism"]
    for c in obj["cells"]:
        c.pop("geometry", None)
    bare = tmp_path / "bare.json"
    bare.write_text(json.dumps(obj))
    code, _, err = cli("draw", bare)
    assert code == 2 and "no mechanism geometry" in err
    assert not (tmp_path / "bare.svg").exists()


def test_cli_writes_default_name_and_replaces(cli, sorter_json, tmp_path):
    out = tmp_path / "sorter.svg"
    out.write_text("old\n")
    code, stdout, err = cli("draw", sorter_json, "--state", "C=1,D=1")
    assert code == 0, err
    assert "Z=1" in stdout
    assert _outputs(out.read_text()) == {"Z": 1}
    assert not [p for p in tmp_path.iterdir() if p.name.endswith(".tmp")]


def test_cli_compiles_a_spec(cli, tmp_path, monkeypatch):
    """A spec's drawing goes to the current directory, never into the folder of the spec."""
    src, run = tmp_path / "src", tmp_path / "run"
    src.mkdir()
    run.mkdir()
    spec = src / "fa.bool"
    spec.write_text((EXAMPLES / "full_adder.bool").read_text())
    monkeypatch.chdir(run)
    code, stdout, err = cli("draw", spec, "--state", "a=1,b=1")
    assert code == 0, err
    assert _outputs((run / "fa.svg").read_text()) == {"s": 0, "cout": 1}  # 1+1+0 = 10b
    assert [p.name for p in src.iterdir()] == ["fa.bool"]


def test_unsolved_body_is_shown_and_fails(cli, sorter, sorter_json, tmp_path, monkeypatch):
    """If the solver reports a body it could not pose, the drawing says so (and does not
    claim an output value from it) and the command exits 1."""
    import mechc.backends.svg as ev  # the drawing's own name for the solver

    owner, pin = sorter.mechanism.outputs["Z"]
    body = sorter.mechanism.owner_part(owner).terminals[pin].body
    real = ev.evaluate

    def broken(mech, lib, types, values):
        poses = real(mech, lib, types, values)
        poses.bad[body] = np.ones(1, dtype=bool)
        return poses

    monkeypatch.setattr(ev, "evaluate", broken)
    out = tmp_path / "x.svg"
    code, _, err = cli("draw", sorter_json, "-o", out)
    assert code == 1 and body in err
    svg = out.read_text()
    root = ET.fromstring(svg)
    assert any(g.get("data-body") == body and g.get("class") == "bad"
               for g in root.iter(f"{NS}g"))
    texts = [t.text or "" for t in root.iter(f"{NS}text")]
    assert any("NOT SOLVED" in t for t in texts)
    assert "Z = ? (not solved)" in texts and _outputs(svg) == {}


# ---- drawings that read at any size -----------------------------------------------------------

@pytest.fixture(scope="module")
def big():
    """A compiled design of about a hundred cells (a random spec, grown to size)."""
    from mechc.bench.circuits import random_compiled

    d = random_compiled(100, seed=1)
    assert 75 <= len(d.netlist.cells) <= 125
    return d


def _font_px(style: str, selector: str) -> float:
    m = re.search(r"(?:^|\})" + re.escape(selector) + r"\{font-size:([\d.]+)px", style)
    assert m, selector
    return float(m.group(1))


def _body_x_extent(root) -> tuple[float, float]:
    xs = []
    for g in root.iter(f"{NS}g"):
        if g.get("data-body"):
            for p in g:
                if p.get("class") == "f":
                    xs += [float(v) for v in re.findall(r"[ML]([-\d.]+),", p.get("d"))]
    return min(xs), max(xs)


@pytest.mark.parametrize("which", ["sorter", "big"])
def test_drawing_reads_on_one_screen(which, request):
    """Shown at its default size (at most one 1600 px screen wide), the input and output
    labels are at least 16 px tall and the cell names 11 px; every cell has its box and its
    name by it; the inputs are named in a column left of every part, the outputs right of
    every part, one label each, not on top of each other; the legend names the cells' boxes."""
    design = request.getfixturevalue(which)
    svg = draw_svg(design, {})
    root = ET.fromstring(svg)
    shown = float(root.get("width"))
    assert 200 <= shown <= 1600
    d = shown / float(root.get("viewBox").split()[2])  # screen px per drawing unit
    if which == "big":
        assert d < 0.5  # a design this size is shown shrunk: the text must be sized for it
    style = root.find(f"{NS}style").text
    io_px, cell_px = _font_px(style, ".io text") * d, _font_px(style, "text") * d
    assert io_px >= 16 and cell_px >= 11, (io_px, cell_px)
    texts = [t for t in root.iter(f"{NS}text") if "halo" not in (t.get("class") or "")]
    # every cell: a box, and its name at the box's top left
    rects = {r.get("data-cell"): r for r in root.iter(f"{NS}rect") if r.get("data-cell")}
    assert set(rects) == set(design.netlist.cells)
    fs = cell_px / d
    for cid, r in rects.items():
        x, y = float(r.get("x")), float(r.get("y"))
        lab = [t for t in texts if (t.text or "").startswith(f"{cid} ")
               and t.get("class") == "lc"]
        assert len(lab) == 1, cid
        assert lab[0].text == f"{cid} {design.netlist.cells[cid].type}"
        lx, ly = float(lab[0].get("x")), float(lab[0].get("y"))
        assert abs(lx - x) < fs and y - 6 * fs <= ly <= y + float(r.get("height")), cid
    # inputs and outputs at the edges, one label each
    x0, x1 = _body_x_extent(root)
    io = [t for t in texts if "iol" in (t.get("class") or "") or "ior" in (t.get("class") or "")]
    left = {t.text.split()[0]: t for t in io if "iol" in t.get("class")}
    right = {t.text.split()[0]: t for t in io if "ior" in t.get("class")}
    assert set(left) == set(design.netlist.inputs)
    assert set(right) == set(design.mechanism.outputs)
    for t in left.values():
        assert t.get("text-anchor") == "end" and float(t.get("x")) < x0
    for t in right.values():
        assert t.get("text-anchor") == "start" and float(t.get("x")) > x1
    fio = io_px / d
    for side in (left, right):
        ys = sorted(float(t.get("y")) for t in side.values())
        assert all(b - a >= 1.1 * fio for a, b in zip(ys, ys[1:]))
    legend = " ".join(t.text or "" for g in root.iter(f"{NS}g") if g.get("class") == "legend"
                      for t in g.iter(f"{NS}text"))
    assert "input slider" in legend and "cell: id TYPE" in legend


def test_natural_size_keeps_scale_and_small_drawings_are_not_blown_up(sorter):
    """--width 0 (None): the drawing's own size, scale px per mm; a drawing narrower than the
    width is shown at its own size too (never enlarged)."""
    nat = ET.fromstring(draw_svg(sorter, {}, 2.0, width=None))
    assert float(nat.get("width")) == float(nat.get("viewBox").split()[2])
    small = ET.fromstring(draw_svg(sorter, {}, 0.5))
    assert float(small.get("width")) == float(small.get("viewBox").split()[2]) < 1600


@pytest.mark.parametrize("which", ["sorter", "big"])
def test_drawing_as_chromium_shows_it(which, request, browser, tmp_path):
    """The SVG opened in a real browser at its own size (what a person sees at 100 % zoom):
    the input and output labels render at least 16 px tall and the cell names 10 px, no text
    is cut off by the picture's edge, the io labels do not overlap one another, and the parts
    lie between the input column and the output column."""
    design = request.getfixturevalue(which)
    path = tmp_path / "d.svg"
    path.write_text(draw_svg(design, {}))
    root = ET.fromstring(path.read_text())
    w, h = float(root.get("width")), float(root.get("height"))
    page = browser.new_page(viewport={"width": int(w) + 1, "height": int(h) + 1})
    page.goto(path.resolve().as_uri())
    got = page.evaluate("""() => {
        const r = e => { const b = e.getBoundingClientRect();
                         return [b.left, b.top, b.right, b.bottom]; };
        const texts = [...document.querySelectorAll('text')]
            .filter(t => !t.classList.contains('halo'))
            .map(t => [t.getAttribute('class') || '', t.textContent, ...r(t)]);
        const bodies = [...document.querySelectorAll('g[data-body]')].map(r);
        return {texts, bodies};
    }""")
    page.close()
    texts, bodies = got["texts"], got["bodies"]
    for _cls, text, x0, y0, x1, y1 in texts:
        assert -0.5 <= x0 and x1 <= w + 0.5 and -0.5 <= y0 and y1 <= h + 0.5, (text, x0, x1)
    io = [t for t in texts if "iol" in t[0] or "ior" in t[0]]
    cells = [t for t in texts if t[0] == "lc"]
    assert len(io) == len(design.netlist.inputs) + len(design.mechanism.outputs)
    assert len(cells) == len(design.netlist.cells)
    assert min(t[5] - t[3] for t in io) >= 16
    assert min(t[5] - t[3] for t in cells) >= 10
    for i, a in enumerate(io):
        for b in io[i + 1:]:
            assert a[4] <= b[2] or b[4] <= a[2] or a[5] <= b[3] or b[5] <= a[3], (a[1], b[1])
    left = min(b[0] for b in bodies)
    right = max(b[2] for b in bodies)
    assert max(t[4] for t in io if "iol" in t[0]) < left
    assert min(t[2] for t in io if "ior" in t[0]) > right
