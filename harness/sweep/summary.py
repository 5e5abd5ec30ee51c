"""The sweep's summary: the JSON document and its text (counts by status, the mean c
per grid point, the parts set aside and why)."""

from __future__ import annotations

import math

from ..text import impact_law_text


def _f(x):
    if x is None:
        return None
    x = float(x)
    return x if math.isfinite(x) else None


def summarise(config, df, store, statuses_now, n_before, n_missing, refused_now=0) -> dict:
    """The JSON document: grid, counts by status, mean c per grid point, where things are."""
    from .stats import STATUSES, grid_stats

    stats = grid_stats(df, config)
    counts = {s: int((df["status"] == s).sum()) for s in STATUSES} if len(df) else {}
    points = [
        {
            "restitution": float(r.restitution),
            "gyration": float(r.gyration),
            "runs": int(r.runs),
            "n_c": int(r.n_c),
            "mean_c": _f(r.mean_c),
            "std_c": _f(r.std_c),
            "median_c": _f(r.median_c),
            "frac_simultaneous": _f(r.frac_simultaneous),
            "status": {s: int(getattr(r, s)) for s in STATUSES},
        }
        for r in stats.itertuples()
    ]
    failed = df[df["status"] == "failed"] if len(df) else df
    return {
        "command": "sweep exponent",
        "engine": config.engine,
        "impact_law": config.impact_law,
        "simultaneity_window": config.simultaneity_window,
        "n": config.n,
        "out": str(store.root),
        "dir": str(store.dir),
        "parts": {"dir": str(store.parts_dir), "count": len(store.part_paths())},
        "manifest": config.to_dict(),
        "grid": {
            "restitution": [float(x) for x in config.gamma_values],
            "gyration": [float(x) for x in config.rho_values],
            "samples": config.samples,
            "seed": config.seed,
        },
        "tasks": {
            "total": config.n_tasks,
            "stored_before": n_before,
            "computed": n_missing,
            "rows": int(len(df)),
            "missing": int(config.n_tasks - len(df)),
            "duplicates_dropped": 0,
            "refused_parts": int(refused_now),
        },
        # parts set aside when the store was opened (harness.sweep.parts): why each
        "set_aside": list(getattr(store, "notes", [])),
        "counts": counts,
        "counts_this_run": dict(statuses_now),
        "mean_c": _f(df["c"].mean()) if len(df) else None,
        # summed over every stored run (also those of earlier invocations)
        "run_time_sum_s": {
            "wall": _f(df["wall_time_s"].sum()) if len(df) else 0.0,
            "cpu": _f(df["cpu_time_s"].sum()) if len(df) else 0.0,
        },
        "points": points,
        "failed_examples": [
            {
                "restitution": float(r.restitution),
                "gyration": float(r.gyration),
                "sample": int(r.sample),
                "error": str(r.error)[-300:],
            }
            for r in failed.head(5).itertuples()
        ],
    }


def format_summary(doc: dict) -> str:
    g = doc["grid"]
    t = doc["tasks"]
    law = ""
    if doc["engine"] in ("reference", "linear"):
        law = f", impact law {impact_law_text(doc['impact_law'], doc['simultaneity_window'])}"
    lines = [
        f"exponent sweep: engine {doc['engine']}{law}",
        f"grid: n = {doc['n']}, {len(g['restitution'])} values of γ × {len(g['gyration'])} of "
        f"ρ, {g['samples']} runs each from random initial states (seed {g['seed']})",
        f"runs: {t['rows']} of {t['total']} stored ({t['stored_before']} before, "
        f"{t['computed']} computed now" + (f", {t['missing']} missing)" if t["missing"] else ")"),
        "runs ending in: " + ", ".join(f"{k} {v}" for k, v in doc["counts"].items() if v),
        f"wall time {doc['wall_time_s']:.1f} s (runs {doc['compute_time_s']:.1f} s, "
        f"figures {doc['figures_time_s']:.1f} s), executor {doc['executor']}, "
        f"load average {doc['load_average_start'][0]:.2f} -> {doc['load_average_end'][0]:.2f}",
        f"runs' own time, summed over all stored runs: {doc['run_time_sum_s']['wall']:.1f} s "
        f"wall, {doc['run_time_sum_s']['cpu'] or 0.0:.1f} s CPU",
        "",
        "mean energy exponent c of E ~ (t_f − t)^c over the runs with a fitted c",
        "(rows ρ, columns γ; '-': no run of that cell has one)",
    ]
    gam, rho = g["restitution"], g["gyration"]
    if len(gam) <= 25:
        by = {(p["restitution"], p["gyration"]): p for p in doc["points"]}
        lines.append("   ρ \\ γ " + "".join(f"{x:6.2f}" for x in gam))
        for r in reversed(rho):
            cells = []
            for x in gam:
                m = by[(x, r)]["mean_c"]
                cells.append(f"{m:6.2f}" if m is not None else "     -")
            lines.append(f"  {r:6.3f} " + "".join(cells))
    lines.append("")
    lines += doc.get("set_aside", [])  # "set aside <kind> part <name>: <why>"
    lines.append(f"parts: {doc['parts']['dir']} ({doc['parts']['count']} files)")
    for name, path in doc["figures"].items():
        lines.append(f"{name}: {path}")
    return "\n".join(wrapped for line in lines for wrapped in _wrap(line))


def _wrap(line: str, width: int = 100) -> list[str]:
    import textwrap

    return textwrap.wrap(line, width, subsequent_indent="  ") if len(line) > width else [line]
