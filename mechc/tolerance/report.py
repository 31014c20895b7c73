"""A tolerance run as text for the terminal and as JSON for a file."""

from __future__ import annotations

from mechc.tolerance.montecarlo import ToleranceResult
from mechc.ui import table


def to_json(r: ToleranceResult, source: str, top: int = 30) -> dict:
    s = r.settings
    lo, hi = r.ci
    return {
        "design": source,
        "settings": {"tol_mm": s.tol, "clearance_mm": s.clearance, "spring_tol": s.spring_tol,
                     "samples": s.samples, "seed": s.seed,
                     "proof_tolerance_fraction": s.proof_tolerance, "yield_target": s.yield_level},
        "dimensions": len(r.dims),
        "yield": round(r.yield_, 6), "passed": r.passed, "samples": r.samples,
        "yield_ci95": [round(lo, 6), round(hi, 6)],
        "meets_target": r.yield_ >= s.yield_level,
        "failing_checks": [{"check": f.key.name, "where": f.key.where, "samples": f.count,
                            "fraction": round(f.count / r.samples, 6),
                            "worst": None if f.worst != f.worst or abs(f.worst) == float("inf")
                            else round(f.worst, 6),
                            "limit": f.key.limit, "sense": f.key.sense, "unit": f.key.unit}
                           for f in r.failing],
        "nominal_output_margin_mm": {o: round(v, 6) for o, v in r.nominal_margin_mm.items()},
        "structural_error": [e.to_json() for e in r.structural],
        "interference_bound": {
            "samples_may_touch": r.interference_samples,
            "passing_samples_may_touch": r.interference_passing,
            "pairs": [{"bodies": [p.a, p.b], "plane": p.layer,
                       "nominal_gap_mm": round(p.nominal_gap_mm, 6), "samples": p.samples,
                       "smallest_bound_mm": None if abs(p.worst_mm) == float("inf")
                       else round(p.worst_mm, 6)} for p in r.interference[:top]]},
        "sensitivity": [{"dimension": x.dim.name, "owner": x.dim.owner, "what": x.dim.what,
                         "nominal": round(x.dim.nominal, 6),
                         "position_effect_mm": round(x.position_mm, 6),
                         "margin_regression_mm": round(x.margin_coef, 6)}
                        for x in r.ranked[:top]],
        "sensitivity_by_owner_mm": {k: round(v, 6) for k, v in r.per_owner.items()},
        "seconds": r.seconds,
    }


def summary(r: ToleranceResult, name: str, top: int = 10) -> str:
    s = r.settings
    lo, hi = r.ci
    lines = [f"{name}: {len(r.dims)} dimensions, {r.samples} samples at +-{s.tol} mm, pin "
             f"clearance {s.clearance} mm, springs +-{s.spring_tol:.0%} "
             f"(outputs within {s.proof_tolerance:.0%} of stroke)",
             f"yield {r.yield_:.2%} ({r.passed}/{r.samples}), 95 % interval [{lo:.2%}, {hi:.2%}]"]
    if r.failing:
        rows = [(f.key.name, f.key.where, f.count, f"{f.count / r.samples:.2%}",
                 f"{f.worst:.4g}{' ' + f.key.unit if f.key.unit else ''}",
                 f"{f.key.sense} {f.key.limit:g}") for f in r.failing[:top]]
        lines += ["", "failing checks (most frequent first):",
                  table(rows, ["check", "where", "samples", "of all", "worst", "limit"])]
    rows = [(e.output, f"{e.spread_mm[0]:+.3f} .. {e.spread_mm[1]:+.3f}",
             f"{e.extreme_mm[0]:+.3f} .. {e.extreme_mm[1]:+.3f}", f"{e.lost_mm:.3f}",
             f"{e.mid_margin_mm:.3f}", f"{e.stroke_mm:g}") for e in r.structural]
    if rows:
        lines += ["", f"structural error at rest (mm; central {s.yield_level:.0%} and extremes; "
                  f"margin to mid-stroke kept by {s.yield_level:.0%} of samples):",
                  table(rows, ["output", "spread", "extremes", "lost motion", "mid margin",
                               "stroke"])]
    else:
        lines += ["", "no output is cared for at rest: no structural error"]
    near = [p for p in r.interference if p.samples]
    lines += ["", f"interference (a bound, not counted in the yield): {len(r.interference)} "
              f"pairs on one plane come near enough at nominal for the samples' moves to "
              f"matter; the bound says some may touch in {r.interference_samples} samples, "
              f"{r.interference_passing} of them passing every check"]
    if near:
        rows = [(f"{p.a} / {p.b}", p.layer, f"{p.nominal_gap_mm:.3f}", p.samples,
                 f"{p.worst_mm:.3f}") for p in near[:top]]
        lines.append(table(rows, ["pair", "plane", "gap at nominal", "samples at risk",
                                  "smallest bound"]))
    rows = [(x.dim.name, x.dim.owner, x.dim.what, f"{x.position_mm:.4f}",
             f"{x.margin_coef:+.4f}") for x in r.ranked[:top]]
    lines += ["", "dimensions that matter most (output movement at tolerance, mm; regression "
              "of the output margin over the samples, mm, given at least 5 samples a "
              "dimension):",
              table(rows, ["dimension", "owner", "what", "moves output", "margin"])]
    rows = [(k, f"{v:.4f}") for k, v in list(r.per_owner.items())[:top]]
    lines += ["", "per cell (root-sum-square of its dimensions' effects, mm):",
              table(rows, ["owner", "effect"])]
    verdict = "meets" if r.yield_ >= s.yield_level else "FAILS"
    lines += ["", f"{verdict} the target yield {s.yield_level:.2%} "
              f"({r.seconds.get('total', 0):.2f} s)"]
    return "\n".join(lines)
