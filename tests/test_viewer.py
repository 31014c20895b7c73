"""``mechc view``: the page, opened in real headless Chromium (the Debian package, driven by
playwright; tests/conftest.py installs it when missing), loads without a console error or a
request, and clicking its inputs moves every output to the value the spec gives.

References are independent of the page: output values come from the spec's own evaluation
(``Spec.values_at`` for a truth table, the flow table's walk ``expected_after`` for a
sequential spec), and body poses from mechc's closed form (``physics.evaluate`` and each part
kind's ``position``) compared with the transforms the page's DOM holds.

``MECHC_VIEWER_SHOT=docs/viewer.png pytest tests/test_viewer.py -k sorter_every`` also saves
the screenshot in docs/.
"""

from __future__ import annotations

import os
import re

import numpy as np
import pytest

from mechc.backends.design_json import design_from_json, load_design_json
from mechc.cells.library import load_library
from mechc.frontends import load_spec
from mechc.parts.base import position
from mechc.physics.evaluate import evaluate
from mechc.proofs.seq_logic import expected_after, expected_states
from tests.helpers import EXAMPLES

VIEW = {"width": 1400, "height": 800}


@pytest.fixture(scope="module")
def pages(tmp_path_factory):
    """Compiled designs and their pages, made by the command line."""
    from mechc.cli.main import main

    d = tmp_path_factory.mktemp("view")
    out = {}
    for name in ("sorter", "full_adder"):
        design = d / f"{name}.json"
        assert main(["compile", str(EXAMPLES / f"{name}.bool"), "-o", str(design)]) == 0
        assert main(["view", str(design), "-o", str(d / f"{name}.html")]) == 0
        out[name] = (design, d / f"{name}.html")
    assert main(["view", str(EXAMPLES / "toggle.fsm"), "-o", str(d / "toggle.html")]) == 0
    out["toggle"] = (None, d / "toggle.html")
    return out


def open_page(browser, path, errors: list, bypass_csp: bool = True):
    """A page on ``path``; console errors, page errors and every request but the file go to
    ``errors``. The page forbids eval (its Content-Security-Policy), which playwright's
    wait_for_function needs: tests that wait bypass it, one test loads the page as it is."""
    ctx = browser.new_context(viewport=VIEW, bypass_csp=bypass_csp)
    page = ctx.new_page()
    page.on("console", lambda m: errors.append(f"console {m.type}: {m.text}")
            if m.type in ("error", "warning") else None)
    page.on("pageerror", lambda e: errors.append(f"page error: {e}"))
    url = path.resolve().as_uri()
    page.on("request", lambda r: errors.append(f"request: {r.url}") if r.url != url else None)
    page.goto(url)
    return page


def wait_idle(page) -> None:
    page.wait_for_function("() => document.documentElement.dataset.busy === '0'",
                           timeout=20_000)


def dom_outputs(page) -> dict[str, int]:
    return {el.get_attribute("data-output"): int(el.inner_text())
            for el in page.query_selector_all("[data-output]")}


def dom_inputs(page) -> dict[str, int]:
    return {k: int(v) for k, v in (item.split("=") for item in
                                   page.evaluate("document.documentElement.dataset.inputs")
                                   .split())}


def click_to(page, want: dict[str, int], after_each=None) -> None:
    """Click the inputs that differ from ``want``, one at a time, each change animated."""
    for name, v in want.items():
        if dom_inputs(page)[name] != v:
            page.click(f'button[data-input="{name}"]')
            wait_idle(page)
            if after_each is not None:
                after_each()


def dom_transforms(page) -> dict[str, np.ndarray]:
    """Each body's transform as the DOM holds it: a 2x3 matrix (world mm)."""
    got = page.eval_on_selector_all(
        "g.body", "els => els.map(e => [e.dataset.body, e.getAttribute('transform')])")
    out = {}
    for bid, tr in got:
        m = re.fullmatch(r"matrix\(([^)]*)\)", tr)
        a, b, c, d, e, f = (float(v) for v in m.group(1).split(","))
        out[bid] = np.array([[a, c, e], [b, d, f]])
    return out


def spec_values(spec, state: dict[str, int]) -> dict[str, int | None]:
    bits = np.array([[bool(state[n])] for n in spec.inputs])
    vals = spec.values_at(bits)
    return {o: (int(v[0]) if int(v[0]) in (0, 1) else None) for o, v in vals.items()}


def closed_form(design_path, states: list[dict[str, int]]):
    """Every body's closed-form pose in each state (mechc's kinematics, not the trace)."""
    design = design_from_json(load_design_json(str(design_path)), str(design_path))
    mech = design.mechanism
    types = {c.id: c.cell for c in design.netlist.cells.values()}
    values = {n: np.array([float(s[n]) for s in states]) for n in design.netlist.inputs}
    return mech, evaluate(mech, load_library(), types, values)


def test_page_is_one_file_that_loads_with_no_error_and_fetches_nothing(browser, pages):
    design, html = pages["sorter"]
    text = html.read_text()
    assert not re.search(r"""(src|href)\s*=\s*["'](https?:)?//""", text)  # nothing external
    errors: list[str] = []
    page = open_page(browser, html, errors, bypass_csp=False)  # the page's own policy holds
    page.wait_for_selector("g.body")
    names = [b.get_attribute("data-input") for b in page.query_selector_all("[data-input]")]
    assert names == ["A", "B", "C", "D"]
    assert set(dom_outputs(page)) == {"Z"}
    assert len(page.query_selector_all("g.body")) == len(
        page.query_selector_all("#bodies > g"))
    page.click('button[data-input="C"]')
    page.wait_for_selector('html[data-busy="0"][data-inputs="A=0 B=0 C=1 D=0"]',
                           state="attached", timeout=20_000)
    assert errors == []
    page.context.close()


@pytest.mark.parametrize("name", ["sorter", "full_adder"])
def test_clicking_inputs_gives_every_output_the_spec_value_every_state(browser, pages, name):
    design, html = pages[name]
    spec = load_spec(EXAMPLES / f"{name}.bool")
    n = len(spec.inputs)
    states = [{k: (m >> (n - 1 - i)) & 1 for i, k in enumerate(spec.inputs)}
              for m in range(1 << n)]
    mech, poses = closed_form(design, states)
    bodies = mech.body_index()
    errors: list[str] = []
    page = open_page(browser, html, errors)
    page.select_option("#speed", "1")  # real time: 0.08 s a change
    checked = {"outputs": 0, "bodies": 0}
    seen = set()

    def check() -> None:
        now = dom_inputs(page)
        m = sum(now[k] << (n - 1 - i) for i, k in enumerate(spec.inputs))
        want = spec_values(spec, now)
        got = dom_outputs(page)
        for o, v in want.items():
            if v is not None:
                assert got[o] == v, (now, o, got[o], v)
                checked["outputs"] += 1
                seen.add(v)
        # each body where the closed form puts it: its reference point and one vertex
        for bid, M in dom_transforms(page).items():
            b = bodies[bid]
            for p in (b.outline[0][0], b.outline[0][2]):
                x, y = position(b, poses, (np.array(p[0]), np.array(p[1])))
                xy = [np.broadcast_to(np.asarray(v, dtype=float), (len(states),))[m]
                      for v in (x, y)]
                np.testing.assert_allclose(M @ [p[0], p[1], 1.0], xy, atol=2e-3,
                                           err_msg=f"{bid} in {now}")
            checked["bodies"] += 1

    check()
    for state in states[1:] + [states[0]]:  # counting order: several clicks some steps
        click_to(page, state, after_each=check)
    assert seen == {0, 1}
    assert checked["outputs"] >= len(states) * len(spec.outputs) * 0.5
    assert checked["bodies"] >= len(states) * len(bodies)
    if name == "sorter" and os.environ.get("MECHC_VIEWER_SHOT"):
        click_to(page, {"A": 0, "B": 1, "C": 1, "D": 0})
        page.select_option("#speed", "0.1")  # the default, as a user first sees it
        page.screenshot(path=os.environ["MECHC_VIEWER_SHOT"])
    assert errors == []
    page.context.close()


def test_sequential_toggle_follows_its_flow_table(browser, pages):
    _, html = pages["toggle"]
    spec = load_spec(EXAMPLES / "toggle.fsm")
    errors: list[str] = []
    page = open_page(browser, html, errors)
    page.select_option("#speed", "1")
    seq = [dom_inputs(page)]
    for _ in range(6):  # press, release, press, release, press, release
        page.click('button[data-input="T"]')
        wait_idle(page)
        seq.append(dom_inputs(page))
        assert seq[-1]["T"] != seq[-2]["T"]
        want = expected_after(spec, seq)[-1]
        assert dom_outputs(page) == {o: v for o, v in want.items()}, seq
        state = page.evaluate("document.documentElement.dataset.state")
        assert state == expected_states(spec, seq)[-1]
    assert {v["Q"] for v in expected_after(spec, seq)} == {0, 1}
    assert errors == []
    page.context.close()


def test_slider_play_planes_zoom_and_pan(browser, pages):
    _, html = pages["sorter"]
    errors: list[str] = []
    page = open_page(browser, html, errors)
    total = page.evaluate("window.mechcView.total()")
    assert total > 0.5  # 16 states and 15 changes
    # the tour's first change (input D, Gray order) half done: D's slider is halfway
    tour = page.evaluate("window.mechcView.data.tour")
    first = next(i for i, s in enumerate(tour) if not s["hold"])
    t_half = page.evaluate(f"""() => {{ const d = window.mechcView.data;
        const c = d.cases[d.tour[{first}].case]; return d.hold + (c.t[c.t.length - 1] - c.t[0]) / 2;
        }}""")
    page.fill("#time", str(t_half))
    sig = float(page.get_attribute('button[data-input="D"]', "data-signal"))
    assert 0.3 < sig < 0.7
    # play moves time on, pause stops it
    page.click("#play")
    page.wait_for_function(f"() => window.mechcView.time() > {t_half} + 0.01")
    page.click("#play")
    t1 = page.evaluate("window.mechcView.time()")
    assert t1 > t_half and not page.evaluate("window.mechcView.playing()")
    page.wait_for_timeout(200)
    assert page.evaluate("window.mechcView.time()") == t1
    # a plane hidden: its paths are not displayed, the others are
    planes = [c.get_attribute("data-plane") for c in page.query_selector_all("[data-plane]")]
    assert len(planes) > 1
    page.uncheck(f'[data-plane="{planes[-1]}"]')
    shown = page.eval_on_selector_all(
        "g.body path", "ps => ps.map(p => [p.getAttribute('class'), "
        "getComputedStyle(p).display !== 'none'])")
    assert {c for c, vis in shown if not vis} == {f"p{planes[-1]}"}
    assert any(vis for _, vis in shown)
    # wheel zooms in (the view box narrows), a drag pans it
    vb0 = [float(v) for v in page.get_attribute("#view", "viewBox").split()]
    page.mouse.move(700, 500)
    page.mouse.wheel(0, -400)
    page.wait_for_timeout(100)
    vb1 = [float(v) for v in page.get_attribute("#view", "viewBox").split()]
    assert vb1[2] < 0.8 * vb0[2]
    page.mouse.down()
    page.mouse.move(500, 500, steps=5)
    page.mouse.up()
    vb2 = [float(v) for v in page.get_attribute("#view", "viewBox").split()]
    assert vb2[0] > vb1[0] and vb2[2] == pytest.approx(vb1[2])
    assert errors == []
    page.context.close()


def test_gif_shows_the_spec_output_in_every_state_of_the_tour(tmp_path, pages):
    """The GIF, re-read with pillow: one long frame per input state of the Gray-code tour,
    and the output body is drawn green ('on') exactly where the spec says Z = 1."""
    from PIL import Image

    from mechc.backends.gif import COLOURS, HOLD_MS
    from mechc.cli.main import main

    design, _ = pages["sorter"]
    out = tmp_path / "sorter.gif"
    assert main(["view", str(design), "--gif", str(out)]) == 0
    assert not (tmp_path / "sorter.html").exists()  # only the GIF was asked for
    assert out.stat().st_size < 1.5e6
    spec = load_spec(EXAMPLES / "sorter.bool")
    green = np.array([int(COLOURS["out_on"][0][k:k + 2], 16) for k in (1, 3, 5)])
    im = Image.open(out)
    holds = []
    for k in range(im.n_frames):
        im.seek(k)
        if im.info["duration"] >= HOLD_MS:
            rgb = np.asarray(im.convert("RGB"), dtype=float)
            holds.append(int((np.linalg.norm(rgb - green, axis=2) < 30).sum()))
    assert len(holds) == 16
    seen = set()
    for i, px in enumerate(holds):
        g = i ^ (i >> 1)  # the tour's order: reflected Gray code from every input off
        state = {n: (g >> (3 - j)) & 1 for j, n in enumerate(spec.inputs)}
        want = spec_values(spec, state)["Z"]
        if want is not None:
            seen.add(want)
            assert (px > 50) == (want == 1), (state, px)
    assert seen == {0, 1}


@pytest.mark.slow
def test_dynamic_page_plays_the_pymunk_run_and_clicks_still_give_the_spec(browser, pages,
                                                                           tmp_path):
    from mechc.cli.main import main

    design, _ = pages["sorter"]
    html = tmp_path / "dyn.html"
    assert main(["view", str(design), "--dynamic", "--cases", "0", "-o", str(html)]) == 0
    spec = load_spec(EXAMPLES / "sorter.bool")
    errors: list[str] = []
    page = open_page(browser, html, errors)
    data = page.evaluate("window.mechcView.data")
    assert data["level"] == "dynamic" and data["proof"]["dynamic"]["passed"]
    # the tour is the dynamic run: 15 Gray-code changes, each sampled every 2 ms
    moves = [s for s in data["tour"] if not s["hold"]]
    assert len(moves) == 15
    assert all(len(data["cases"][s["case"]]["t"]) > 21 for s in moves)
    page.select_option("#speed", "1")
    page.click('button[data-input="D"]')  # the run's first change: played from the run
    wait_idle(page)
    assert "dynamic proof's run" in page.inner_text("#status")
    n = len(spec.inputs)
    for m in list(range(1 << n)) + [0]:
        state = {k: (m >> (n - 1 - i)) & 1 for i, k in enumerate(spec.inputs)}
        click_to(page, state)
        want = spec_values(spec, state)["Z"]
        if want is not None:
            assert dom_outputs(page)["Z"] == want, state
    assert errors == []
    page.context.close()


def test_bad_input_is_refused_with_exit_2_and_nothing_written(cli, tmp_path, pages):
    design, _ = pages["sorter"]
    before = design.read_bytes()
    code, _, err = cli("view", design, "-o", design)  # would overwrite the design
    assert code == 2 and "mechc: error" in err and design.read_bytes() == before
    code, _, err = cli("view", design, "--gif", tmp_path / "x.png")
    assert code == 2 and ".gif" in err and not (tmp_path / "x.png").exists()
    code, _, err = cli("view", tmp_path / "missing.json", "-o", tmp_path / "m.html")
    assert code == 2 and "missing.json" in err and not (tmp_path / "m.html").exists()
    code, _, err = cli("view", design, "--fps", "0", "-o", tmp_path / "f.html")
    assert code == 2 and "--fps" in err and not (tmp_path / "f.html").exists()
