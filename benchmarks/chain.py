"""Where the timing level's prediction of one change goes wrong, cell by cell: every switching
cell's mid-stroke crossing in the whole scene against the timing level's.

    python benchmarks/chain.py [SPEC_OR_DESIGN] [--levels multi] [--change K]
                               [--iterations N] [--out DIR]

Default: ``examples/multilevel/adder4.v`` built multi-level, the change the timing level
predicts to settle latest. The change runs once in pymunk from rest in its start state (as
``benchmarks/timing.py`` runs each change) with every switching cell's output recorded. Per
cell it prints when its output crosses mid-stroke in the scene and in the prediction (the
closed form's crossing plus the predicted lag), and its own *stage lag*: its crossing after
that of its latest-switching input, in the scene and in the model. Cells are grouped by how
the timing level times them: ``amplifier`` (its table as the design built it), ``follower``
(a bar its own spring moves, :class:`mechc.proofs.timing.Follower`) and ``pushed`` (every
other gate: its alone table). For a follower whose stage lag the model misses, the follower
model is also run on the scene's own waveform of that input, to tell a wrong model from a
wrong input to it. Writes ``chain.csv`` and ``chain.png`` (every switching cell's crossing,
predicted against the scene's) to ``--out`` (default: a temporary directory).
"""

from __future__ import annotations

import argparse
import csv
import tempfile
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from mechc.backends.design_json import design_from_json, load_design_json  # noqa: E402
from mechc.bench.chain import PREFIX, compare  # noqa: E402
from mechc.cells.characterise import crossing  # noqa: E402
from mechc.cells.library import load_library  # noqa: E402
from mechc.frontends import load_spec  # noqa: E402
from mechc.pipeline import CompileOptions, compile_spec  # noqa: E402
from mechc.proofs.timing import followers  # noqa: E402

LIB = load_library()
ROOT = Path(__file__).resolve().parents[1]
#: A stage lag the model misses by more than this (s) is listed.
MISS_S = 0.005


def load(path: str, levels: str | None):
    if path.endswith(".json"):
        return design_from_json(load_design_json(path))
    opts = CompileOptions(levels=levels) if levels else CompileOptions()
    return compile_spec(load_spec(path), opts)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("design", nargs="?", default=str(ROOT / "examples/multilevel/adder4.v"),
                    help="a spec (compiled here) or a compiled design JSON")
    ap.add_argument("--levels", default="multi",
                    help="how a spec is built (compile's --levels; default multi)")
    ap.add_argument("--change", type=int, help="the plan's change K (default: the latest "
                    "predicted settle)")
    ap.add_argument("--iterations", type=int, metavar="N",
                    help="solver iterations of the scene (default: the dynamic proof's)")
    ap.add_argument("--out", help="directory for chain.csv and chain.png")
    args = ap.parse_args()
    out = Path(args.out or tempfile.mkdtemp(prefix="mechc-chain-"))
    out.mkdir(parents=True, exist_ok=True)
    d = load(args.design, args.levels)
    ch = compare(d, LIB, args.change, args.iterations)
    rows = {v["cell"]: v for v in ch.rows}
    order = [v["cell"] for v in ch.rows]
    print(f"{args.design}: {len(d.netlist.cells)} cells, change {ch.change} of {ch.changes} "
          f"({ch.moving} to {ch.to}), {len(rows)} cells switch; scene {ch.scene_seconds:.1f} s")
    print(f"settle (latest switching net): predicted {ch.predicted_settle_s:.4f} s, scene "
          f"{ch.scene_settle_s:.4f} s after the move starts")
    last = ch.rows[-1]
    off = last["model_cross_s"] / last["scene_cross_s"] - 1
    print(f"latest crossing: {last['cell']} at {last['scene_cross_s']:.4f} s in the scene, "
          f"{last['model_cross_s']:.4f} s predicted ({off:+.1%})")
    print("\nstage lag summed over the switching cells, by how each is timed:")
    print(f"  {'timed as':10} {'cells':>5} {'scene s':>8} {'model s':>8}")
    for kind in ("amplifier", "follower", "pushed"):
        got = [v for v in ch.rows if v["timed_as"] == kind and "input" in v]
        print(f"  {kind:10} {len(got):5d} {sum(v['scene_stage_s'] for v in got):8.3f} "
              f"{sum(v['model_stage_s'] for v in got):8.3f}")
    missed = [v for v in ch.rows if "input" in v
              and abs(v["scene_stage_s"] - v["model_stage_s"]) > MISS_S]
    print(f"\n{len(missed)} cells whose stage lag the model misses by more than {MISS_S} s:")
    fol = followers(d, LIB)
    t = ch.t
    for v in missed:
        line = (f"  {v['cell']:6} {v['type']:10} {v['timed_as']:9} after {v['input']:6} scene "
                f"{v['scene_stage_s']:.4f} s, model {v['model_stage_s']:.4f} s")
        if v["timed_as"] == "follower":
            # the follower model driven by the scene's own waveform of that input
            h, x = ch.outputs[PREFIX + v["input"]], ch.outputs[PREFIX + v["cell"]]
            if abs(h[-1] - h[0]) > 0.3:
                bound = x[0] + (x[-1] - x[0]) * (h - h[0]) / (h[-1] - h[0])
                tt, xx = fol[v["cell"]].run(t, bound, float(t[-1]))
                v["follower_on_scene_input_s"] = crossing(tt, xx) - crossing(t, bound)
                line += (f"; follower model on the scene's input: "
                         f"{v['follower_on_scene_input_s']:.4f} s")
        print(line)
    with open(out / "chain.csv", "w", newline="") as f:
        keys = ["cell", "type", "timed_as", "input", "scene_cross_s", "model_cross_s",
                "scene_stage_s", "model_stage_s", "scene_settle_s", "follower_on_scene_input_s"]
        w = csv.DictWriter(f, fieldnames=keys, extrasaction="ignore")
        w.writeheader()
        for c in order:
            w.writerow({k2: (round(v, 6) if isinstance(v, float) else v)
                        for k2, v in rows[c].items()})
    fig, ax = plt.subplots(figsize=(5.5, 5))
    top = max(max(v["scene_cross_s"], v["model_cross_s"]) for v in rows.values()) * 1.05
    ax.plot([0, top], [0, top], color="0.5", lw=1, label="predicted = scene")
    ax.fill_between([0, top], [0, 0.85 * top], [0, 1.15 * top], color="0.9", label="+-15 %")
    for kind, mk in (("amplifier", "s"), ("follower", "^"), ("pushed", "o")):
        got = [rows[c] for c in order if rows[c]["timed_as"] == kind]
        ax.scatter([v["scene_cross_s"] for v in got], [v["model_cross_s"] for v in got],
                   marker=mk, label=f"{kind} ({len(got)})")
    ax.set_xlim(0, top)
    ax.set_ylim(0, top)
    ax.set_xlabel("scene: output crosses mid-stroke (s after the move starts)")
    ax.set_ylabel("timing level: predicted crossing (s)")
    ax.set_title(f"{Path(args.design).name}: change {ch.change}, {ch.moving} moving",
                 fontsize=10)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out / "chain.png", dpi=120)
    print(f"\nwrote {out / 'chain.csv'} and {out / 'chain.png'}")


if __name__ == "__main__":
    main()
