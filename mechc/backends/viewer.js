// mechc view: animates a design from its pose traces (data in #mechc-data; see
// mechc/backends/animation.py for the model: bodies, cases, nodes, edges, tour).
// World millimetres, y up; a body's point p stands at R(angle)(p - ref) + ref + (dx, dy).
"use strict";
(function () {
  const D = JSON.parse(document.getElementById("mechc-data").textContent);
  const SVG = "http://www.w3.org/2000/svg";
  const nB = D.bodies.length;
  const el = (tag, attrs, parent, ns) => {
    const e = ns ? document.createElementNS(SVG, tag) : document.createElement(tag);
    for (const k in attrs || {}) e.setAttribute(k, attrs[k]);
    if (parent) parent.appendChild(e);
    return e;
  };
  const txt = (e, s) => { e.textContent = s; return e; };
  const plural = (k, w) => `${k} ${w}${k === 1 ? "" : "s"}`;

  // ---- page -----------------------------------------------------------------------------
  const header = el("header", {}, document.body);
  txt(el("h1", {}, header), D.title || "mechc view");
  const pk = D.proof.kinematic || {};
  const pd = D.proof.dynamic;
  txt(el("div", { class: "sub" }, header),
    `${D.kind} design, ${plural(D.inputs.length, "input")}, ` +
    `${plural(D.outputs.length, "output")}, ` +
    `${nB} bodies, stroke ${D.stroke} mm | poses: ` +
    (pd ? `dynamic proof (pymunk) ${pd.passed ? "passed" : "FAILED"}, ` +
      "the closed form where it did not go" :
      `closed form (kinematic proof ${pk.passed ? "passed" : "FAILED"})`) +
    ` | ${D.generator}`);
  const bar1 = el("div", { class: "bar" }, document.body);
  const gIn = el("div", { class: "group", id: "inputs" }, bar1);
  txt(el("span", { class: "name" }, gIn), "inputs");
  const inButtons = {};
  for (const name of D.inputs) {
    const b = el("button", { class: "input", "data-input": name, "aria-pressed": "false",
      title: `toggle input ${name}` }, gIn);
    b.addEventListener("click", () => toggle(name));
    inButtons[name] = b;
  }
  const gOut = el("div", { class: "group", id: "outputs" }, bar1);
  txt(el("span", { class: "name" }, gOut), "outputs");
  const outBox = {};
  for (const name of D.outputs) {
    const box = el("span", { class: "output", "data-output-box": name }, gOut);
    txt(el("span", {}, box), name);
    const v = el("span", { class: "v", "data-output": name }, box);
    const spec = el("span", { class: "spec", "data-expected": name,
      title: "the value the spec asks for in this state" }, box);
    outBox[name] = { box, v, spec };
  }
  const bar2 = el("div", { class: "bar" }, document.body);
  const gPlay = el("div", { class: "group" }, bar2);
  const playBtn = txt(el("button", { id: "play", title: "play / pause (space)" }, gPlay),
    "▶ play");
  const tourBtn = txt(el("button", { id: "tour", title: "back to the proof's tour, from " +
    "the start" }, gPlay), "↺ tour");
  const slider = el("input", { id: "time", type: "range", min: "0", max: "1",
    step: "0.0001", value: "0" }, gPlay);
  const clock = el("span", { id: "clock" }, gPlay);
  const gSpeed = el("label", { class: "group" }, bar2);
  txt(el("span", { class: "name" }, gSpeed), "speed");
  const speed = el("select", { id: "speed" }, gSpeed);
  for (const [v, t] of [["0.02", "1/50"], ["0.05", "1/20"], ["0.1", "1/10"],
    ["0.25", "1/4"], ["1", "real time"]]) {
    const o = txt(el("option", { value: v }, speed), t);
    if (v === "0.1") o.selected = true;
  }
  const gPl = el("div", { class: "group", id: "planes" }, bar2);
  txt(el("span", { class: "name" }, gPl), "planes");
  const fitBtn = txt(el("button", { id: "fit", title: "zoom to fit (wheel: zoom, " +
    "drag: pan)" }, bar2), "fit");
  const gLeg = el("div", { class: "group legend", id: "legend" }, bar2);
  const present = new Set(D.bodies.map(b => b.cls));
  for (const [cls, name] of [["in", "input slider"], ["L0", "cell slider"], ["L1", "bar"],
    ["L2", "lever"], ["L3", "layer 3"], ["L4", "layer 4+"], ["net", "rod, fan-out bar"],
    ["out", "output (green: on)"]]) {
    if (!present.has(cls)) continue;
    const k = el("span", { class: "key" }, gLeg);
    const sw = el("svg", { width: 22, height: 12, class: cls }, k, true);
    el("path", { d: "M1,2H21V10H1Z" }, sw, true);
    k.appendChild(document.createTextNode(name));
  }
  const status = el("div", { id: "status" }, document.body);
  const main = el("main", {}, document.body);
  const svg = el("svg", { id: "view" }, main, true);
  const world = el("g", { id: "world", transform: "scale(1,-1)" }, svg, true);
  const labels = el("g", { id: "labels" }, svg, true);

  // ---- drawing: cell boxes, bodies (one path per plane), terminals, labels ----------------
  const gBox = el("g", { id: "cells" }, world, true);
  for (const c of D.cells) {
    const [x0, y0, x1, y1] = c.box;
    el("rect", { class: "cellbox", "data-cell": c.id, x: x0 - 2, y: y0 - 2,
      width: x1 - x0 + 4, height: y1 - y0 + 4 }, gBox, true);
    txt(el("text", { class: "lbl cell", x: x0 - 2, y: -y1 - 3 }, labels, true),
      `${c.id} ${c.type}`);
  }
  const gBodies = el("g", { id: "bodies" }, world, true);
  const bodyEl = [];
  const order = D.bodies.map((b, i) => i).sort((a, b) => plane0(a) - plane0(b));
  function plane0(i) { return Math.min(...D.bodies[i].polys.map(p => p.plane)); }
  for (const i of order) {
    const b = D.bodies[i];
    const g = el("g", { class: `body ${b.cls}`, "data-body": b.id, "data-ref": b.ref.join(",") },
      gBodies, true);
    const byPlane = {};
    for (const p of b.polys) {
      byPlane[p.plane] = (byPlane[p.plane] || "") + "M" + p.pts.map(q => q.join(",")).join("L") +
        "Z";
    }
    for (const pl in byPlane) el("path", { class: `p${pl}`, d: byPlane[pl] }, g, true);
    el("title", {}, g, true).textContent = `${b.id} (${b.kind}, ${b.owner})`;
    bodyEl[i] = g;
  }
  const row = {};
  D.bodies.forEach((b, i) => { row[b.id] = i; });
  const termEl = {};
  for (const name of D.outputs) {
    const t = D.terminals.outputs[name];
    termEl[name] = {
      dot: el("circle", { class: "term", r: D.stroke * 0.12, "data-terminal": name }, world,
        true),
      lbl: el("text", { class: "lbl out" }, labels, true),
    };
    termEl[name].t = t;
  }
  const inLbl = {};
  for (const name of D.inputs) inLbl[name] = el("text", { class: "lbl in", "text-anchor": "end" },
    labels, true);
  // planes: one checkbox each; hiding is a class on the svg
  const style = el("style", {}, document.head);
  style.textContent = D.planes.map(p => `svg.hide${p} .p${p}{display:none}`).join("");
  for (const p of D.planes) {
    const l = el("label", { class: "plane" }, gPl);
    const cb = el("input", { type: "checkbox", "data-plane": p }, l);
    cb.checked = true;
    cb.addEventListener("change", () => svg.classList.toggle(`hide${p}`, !cb.checked));
    l.appendChild(document.createTextNode(String(p)));
  }

  // ---- poses ------------------------------------------------------------------------------
  const cases = D.cases.map(c => ({ t: c.t, poses: c.poses }));
  // a case's poses: per body one [dx, dy, a] (it stays put) or one per sample
  function mix(c, lo, hi, w) { // flat [dx, dy, a, ...] between samples lo and hi
    const out = new Array(3 * nB);
    for (let i = 0; i < nB; i++) {
      const e = c.poses[i], many = Array.isArray(e[0]);
      const a = many ? e[lo] : e, b = many ? e[hi] : e;
      for (let j = 0; j < 3; j++) {
        out[3 * i + j] = (a[j] === null || b[j] === null) ? null : a[j] * (1 - w) + b[j] * w;
      }
    }
    return out;
  }
  function poseOf(seg, tau) { // flat [dx, dy, a, ...] tau seconds into seg
    const c = cases[seg.case];
    const t = c.t, n = t.length;
    if (seg.hold) { const k = seg.rev ? 0 : n - 1; return mix(c, k, k, 0); }
    let s = seg.rev ? t[n - 1] - tau : t[0] + tau;
    if (s <= t[0]) return mix(c, 0, 0, 0);
    if (s >= t[n - 1]) return mix(c, n - 1, n - 1, 0);
    let lo = 0, hi = n - 1;
    while (hi - lo > 1) { const m = (lo + hi) >> 1; if (t[m] <= s) lo = m; else hi = m; }
    return mix(c, lo, hi, (s - t[lo]) / Math.max(t[hi] - t[lo], 1e-12));
  }
  function place(i, pose, p) { // world point of body i's design point p
    const dx = pose[3 * i], dy = pose[3 * i + 1], a = pose[3 * i + 2];
    const [rx, ry] = D.bodies[i].ref;
    if (dx === null || dy === null || a === null) return p;
    const c = Math.cos(a), s = Math.sin(a), x = p[0] - rx, y = p[1] - ry;
    return [c * x - s * y + rx + dx, s * x + c * y + ry + dy];
  }
  function signal(t, pose) {
    const [x, y] = place(row[t.body], pose, t.point);
    const [ox, oy] = t.off, [nx, ny] = t.on;
    return ((x - ox) * (nx - ox) + (y - oy) * (ny - oy)) / ((nx - ox) ** 2 + (ny - oy) ** 2);
  }

  // ---- timeline ---------------------------------------------------------------------------
  let segs = [], T = 0, total = 0, playing = false, until = null, last = null;
  function duration(s) {
    const t = cases[s.case].t;
    return s.hold ? D.hold : Math.max(t[t.length - 1] - t[0], 1e-6);
  }
  function setSegs(list) {
    segs = list.map(s => Object.assign({}, s));
    total = 0;
    for (const s of segs) { s.t0 = total; s.dur = duration(s); total += s.dur; }
    slider.max = String(total);
  }
  function segAt(time) {
    let lo = 0, hi = segs.length - 1;
    while (lo < hi) { const m = (lo + hi + 1) >> 1; if (segs[m].t0 <= time) lo = m; else hi = m - 1; }
    return lo;
  }
  function render() {
    if (!segs.length) return;
    const k = segAt(T), s = segs[k];
    const pose = poseOf(s, Math.min(Math.max(T - s.t0, 0), s.dur));
    for (let i = 0; i < nB; i++) {
      const dx = pose[3 * i], dy = pose[3 * i + 1], a = pose[3 * i + 2];
      const g = bodyEl[i];
      if (dx === null || dy === null || a === null) {
        g.setAttribute("transform", "matrix(1,0,0,1,0,0)");
        g.classList.add("nopose");
        continue;
      }
      g.classList.remove("nopose");
      const [rx, ry] = D.bodies[i].ref, c = Math.cos(a), sn = Math.sin(a);
      const e = rx + dx - (c * rx - sn * ry), f = ry + dy - (sn * rx + c * ry);
      g.setAttribute("transform", `matrix(${c},${sn},${-sn},${c},${e},${f})`);
    }
    const atRest = s.hold || T >= s.t0 + s.dur - 1e-9 || T <= s.t0 + 1e-9;
    const cur = here().node, node = D.nodes[cur];
    for (const name of D.outputs) {
      const t = termEl[name].t, sig = signal(t, pose), on = sig > 0.5;
      const o = outBox[name];
      o.v.textContent = on ? "1" : "0";
      o.v.setAttribute("data-signal", sig.toFixed(4));
      const want = node.expected[name];
      o.spec.textContent = !atRest ? "" : want === null || want === undefined ?
        "(spec: don't care)" : `(spec: ${want})`;
      o.box.classList.toggle("on", on);
      o.box.classList.toggle("wrong", atRest && want !== null && want !== undefined &&
        want !== (on ? 1 : 0));
      const [x, y] = place(row[t.body], pose, t.point);
      termEl[name].dot.setAttribute("cx", x);
      termEl[name].dot.setAttribute("cy", y);
      termEl[name].dot.classList.toggle("on", on);
      const l = termEl[name].lbl;
      l.setAttribute("x", x + D.stroke * 0.4);
      l.setAttribute("y", -y);
      l.textContent = `${name} = ${on ? 1 : 0}`;
      l.classList.toggle("on", on);
      bodyEl[row[t.body]].classList.toggle("on", on);
    }
    const ins = [];
    for (const name of D.inputs) {
      const t = D.terminals.inputs[name], sig = signal(t, pose), on = sig > 0.5;
      inButtons[name].setAttribute("aria-pressed", on ? "true" : "false");
      inButtons[name].textContent = `${name} = ${on ? 1 : 0}`;
      inButtons[name].setAttribute("data-signal", sig.toFixed(4));
      const i = row[t.body];
      const xs = D.bodies[i].polys[0].pts.map(p => p[0]);
      const [x, y] = place(i, pose, [Math.min(...xs), t.off[1]]);
      inLbl[name].setAttribute("x", x - D.stroke * 0.2);
      inLbl[name].setAttribute("y", -y);
      inLbl[name].textContent = `${name} = ${on ? 1 : 0}`;
      ins.push(`${name}=${on ? 1 : 0}`);
    }
    const edges = D.edges[String(cur)] || {};
    for (const name of D.inputs) {
      const ok = name in edges;
      inButtons[name].disabled = !ok;
      inButtons[name].title = ok ? `toggle input ${name}` :
        `${name} cannot change here: no specified change of ${name} from this state`;
    }
    slider.value = String(T);
    clock.textContent = `t = ${T.toFixed(3)} / ${total.toFixed(3)} s`;
    const root = document.documentElement.dataset;
    root.inputs = ins.join(" ");
    root.node = String(cur);
    root.busy = playing ? "1" : "0";
    root.state = node.state === null ? "" : node.state;
    root.rest = atRest ? "1" : "0";
  }
  function frame(now) {
    if (!playing) { last = null; return; }
    if (last !== null) T += (now - last) / 1000 * parseFloat(speed.value);
    last = now;
    const end = until === null ? total : until;
    if (T >= end) { T = end; stop(); render(); return; }
    render();
    requestAnimationFrame(frame);
  }
  function start(to) {
    until = to;
    if (T >= (to === null ? total : to) - 1e-12) { if (to === null) T = 0; else return; }
    playing = true; last = null;
    playBtn.textContent = "❚❚ pause";
    document.documentElement.dataset.busy = "1";
    requestAnimationFrame(frame);
  }
  function stop() {
    playing = false; until = null;
    playBtn.textContent = "▶ play";
    document.documentElement.dataset.busy = "0";
  }
  function here() { // the state now: at a move's start its start, else (snapped) its end
    const k = segAt(T), s = segs[k];
    if (!s.hold && T <= s.t0 + 1e-9) return { node: s.start, keep: k, time: s.t0 };
    return { node: s.end, keep: k + 1, time: s.t0 + s.dur };
  }
  function toggle(name) { // move to the state with `name` changed, animated
    const h = here();
    const e = (D.edges[String(h.node)] || {})[name];
    if (!e) { status.textContent = `${name} cannot change from this state.`; return; }
    stop();
    setSegs(segs.slice(0, h.keep).concat([
      { case: e.case, rev: e.reverse, start: h.node, end: e.to, hold: false },
      { case: e.case, rev: e.reverse, start: e.to, end: e.to, hold: true }]));
    T = h.time;
    const n = D.nodes[e.to];
    status.textContent = `${name} → ${n.inputs[name]}: ` +
      (e.level === "dynamic" ? "the dynamic proof's run of this change" :
        "closed-form poses along the change") + (n.state ? `; state ${n.state}` : "");
    start(segs[segs.length - 1].t0 + segs[segs.length - 1].dur);
  }
  playBtn.addEventListener("click", () => { if (playing) { stop(); render(); } else start(null); });
  tourBtn.addEventListener("click", () => { stop(); setSegs(D.tour); T = 0; render(); });
  slider.addEventListener("input", () => { stop(); T = parseFloat(slider.value); render(); });
  document.addEventListener("keydown", ev => {
    if (ev.key === " " && ev.target === document.body) { ev.preventDefault(); playBtn.click(); }
  });

  // ---- zoom and pan: the svg's viewBox ------------------------------------------------------
  let vb = null;
  const fs = () => { // label size: about 13 px on screen at any zoom
    const px = svg.clientWidth / vb[2];
    svg.style.setProperty("--fs", `${13 / Math.max(px, 1e-6)}px`);
  };
  function setVB(v) { vb = v; svg.setAttribute("viewBox", v.join(" ")); fs(); }
  function fit() {
    let x0 = Infinity, y0 = Infinity, x1 = -Infinity, y1 = -Infinity;
    for (const b of D.bodies) for (const p of b.polys) for (const [x, y] of p.pts) {
      x0 = Math.min(x0, x); x1 = Math.max(x1, x); y0 = Math.min(y0, y); y1 = Math.max(y1, y);
    }
    const m = D.stroke * 2.5;
    setVB([x0 - m * 2, -y1 - m, x1 - x0 + m * 4, y1 - y0 + 2 * m]);
  }
  function toWorld(ev) {
    const r = svg.getBoundingClientRect();
    const s = Math.max(vb[2] / r.width, vb[3] / r.height); // preserveAspectRatio meet
    const cx = vb[0] + vb[2] / 2, cy = vb[1] + vb[3] / 2;
    return [cx + (ev.clientX - r.left - r.width / 2) * s, cy + (ev.clientY - r.top - r.height / 2) * s, s];
  }
  svg.addEventListener("wheel", ev => {
    ev.preventDefault();
    const [x, y] = toWorld(ev);
    const k = Math.exp(ev.deltaY * 0.0015);
    setVB([x - (x - vb[0]) * k, y - (y - vb[1]) * k, vb[2] * k, vb[3] * k]);
  }, { passive: false });
  let drag = null;
  svg.addEventListener("pointerdown", ev => {
    drag = { x: ev.clientX, y: ev.clientY, vb: vb.slice(), s: toWorld(ev)[2] };
    svg.setPointerCapture(ev.pointerId);
    svg.classList.add("drag");
  });
  svg.addEventListener("pointermove", ev => {
    if (!drag) return;
    setVB([drag.vb[0] - (ev.clientX - drag.x) * drag.s, drag.vb[1] - (ev.clientY - drag.y) * drag.s,
      drag.vb[2], drag.vb[3]]);
  });
  const endDrag = () => { drag = null; svg.classList.remove("drag"); };
  svg.addEventListener("pointerup", endDrag);
  svg.addEventListener("pointercancel", endDrag);
  fitBtn.addEventListener("click", fit);
  window.addEventListener("resize", fs);

  // ---- start: the tour, paused at its first state -------------------------------------------
  setSegs(D.tour);
  fit();
  render();
  status.textContent = "Click an input to change it; ▶ plays the proof's tour of every state.";
  // for tools and tests: the state of the page, read-only
  window.mechcView = {
    data: D,
    time: () => T,
    total: () => total,
    playing: () => playing,
    pose: () => { const s = segs[segAt(T)]; return poseOf(s, Math.min(Math.max(T - s.t0, 0), s.dur)); },
  };
})();
