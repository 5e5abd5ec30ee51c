"""The terminal text of `harness bench`: the table, its legend, skipped settings,
derived numbers, the load."""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

from ..text import table


def _fmt(x: float | None, spec: str = ".2e") -> str:
    return "-" if x is None or not math.isfinite(x) else format(x, spec)


def format_bench(doc: dict[str, Any]) -> str:
    """The work-precision table, skipped settings, derived numbers and the load."""
    tr = doc["truth"]
    lines = [
        f"scene {doc['scene']}: t = 0 .. {doc['t_end']:.6g} (truth: reference "
        f"{tr['setting']}, {tr['status']}, {tr['impacts']} impacts)",
        "",
    ]
    header = [
        "engine",
        "setting",
        "status",
        "median[s]",
        "min[s]",
        "matched",
        "t_err[s]",
        "E_err",
        "E_err<div",
    ]
    rows = [
        [
            r["engine"],
            r["setting"],
            r["status"],
            _fmt(r["wall_time_s"], ".3g"),
            _fmt(r["wall_time_min_s"], ".3g"),
            f"{r['impacts_matched']}/{r['reference_impacts']}",
            _fmt(r["impact_time_error"]),
            _fmt(r["energy_error"]),
            _fmt(r["energy_error_agreeing"]),
        ]
        for r in doc["results"]
    ]
    lines.append(table(rows, header))
    for s in doc.get("skipped", []):
        lines.append(f"skipped: {s['engine']} {s['setting']}: {s['reason']}")
    lines.append("")
    for metric, per in doc.get("derived", {}).items():
        lines.append(f"at the reference's cost, and cost ratio at equal accuracy ({metric}):")
        for engine, d in per.items():
            err = _fmt(d["error_at_reference_cost"])
            lines.append(
                f"  {engine:17s} error at {d['reference_cost_s']:.3g} s: {err} "
                f"({d['error_at_reference_cost_bound']}); best {_fmt(d['best_error'])} at "
                f"{d['best_error_cost_s']:.3g} s costs {_fmt(d['cost_ratio'], '.3g')}x the "
                f"reference ({d['cost_ratio_bound']} bound)"
                if d["cost_ratio_bound"] != "exact"
                else f"  {engine:17s} error at {d['reference_cost_s']:.3g} s: {err} "
                f"({d['error_at_reference_cost_bound']}); best {_fmt(d['best_error'])} at "
                f"{d['best_error_cost_s']:.3g} s costs {_fmt(d['cost_ratio'], '.3g')}x the "
                "reference"
            )
    load = doc["load"]
    lines.append(
        f"load average (1, 5, 15 min) before {_triple(load['before'])}, after "
        f"{_triple(load['after'])}; {doc['cpu_count']} cpus; median of {doc['repeats']} "
        "repeats after a warm-up"
    )
    return "\n".join(lines)


def _triple(x: Sequence[float]) -> str:
    return " ".join(f"{v:.2f}" for v in x)
