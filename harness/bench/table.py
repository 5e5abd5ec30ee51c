"""The terminal text of `harness bench`: the table, its legend, skipped settings, the
summary (derived numbers of the runs that follow the reference), the load.  The default
fits 100 columns; `wide=True` adds the min time, the attitude errors and the divergence
time, and prints the summary's sentences whole."""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

from ..metrics.follows import LEADING_IMPACTS, MATCH_FRACTION
from ..text import WIDTH, table

# Status names shortened in the default table (the JSON and --wide keep them whole).
SHORT_STATUS = {"simultaneous_impact": "simultaneous"}


def _fmt(x: float | None, spec: str = ".2e") -> str:
    return "-" if x is None or not math.isfinite(x) else format(x, spec)


def _short(x: float | None) -> str:
    """1e-06 -> 1e-6 (a setting in the narrow table)."""
    if x is None:
        return "-"
    mantissa, _, exp = f"{x:.0e}".partition("e")
    return f"{mantissa}e{int(exp)}"


def setting_columns(row: dict[str, Any], wide: bool) -> list[str]:
    """dt [s] and the reference's contact_rtol ('-' where the setting has none); --wide:
    the setting's own label (with chatter_tol)."""
    if wide:
        return [row["setting"]]
    return [_short(row["dt"]), _short(row["contact_rtol"])]


def match_columns(row: dict[str, Any]) -> list[str]:
    """matched, of, follows ('yes' / 'no')."""
    follows = "yes" if row.get("follows_reference", True) else "no"
    return [str(row["impacts_matched"]), str(row["reference_impacts"]), follows]


def results_table(doc: dict[str, Any], wide: bool) -> str:
    header = ["engine"] + (["setting"] if wide else ["dt [s]", "rtol"])
    header += ["status", "time [s]"]
    header += ["min [s]"] if wide else []
    header += ["matched", "of", "follows", "t_err [s]"]
    header += (
        ["E error window", "E error following", "attitude following [rad]", "diverges at [s]"]
        if wide
        else ["E error"]
    )
    rows = []
    for r in doc["results"]:
        status = r["status"] if wide else SHORT_STATUS.get(r["status"], r["status"])
        row = [r["engine"], *setting_columns(r, wide), status, _fmt(r["wall_time_s"], ".3g")]
        row += [_fmt(r["wall_time_min_s"], ".3g")] if wide else []
        row += [*match_columns(r), _fmt(r["impact_time_error"])]
        row += [_fmt(r["energy_error"])] if wide else []
        row += [_fmt(r["energy_error_agreeing"])]
        if wide:
            row += [
                _fmt(r.get("attitude_error_agreeing")),
                _fmt(r.get("first_divergence_time"), ".4g"),
            ]
        rows.append(row)
    left = 2 if wide else 3
    return table(rows, header, align="l" * left + "l" + "r" * (len(header) - left - 1))


LEGEND = "\n".join(
    [
        "dt         fixed timestep [s]; rtol: the reference's contact_rtol (--wide: with its",
        "           chatter_tol)",
        "matched    the first k of the reference's impacts the run reproduces in order (same",
        "           contact, time within the window), of the reference's impacts up to the",
        "           earlier end of the two runs (a run that fails or stops early has a small `of`)",
        f"follows    yes: at least {MATCH_FRACTION:.0%} of the first {LEADING_IMPACTS} impacts "
        "matched; the runs that",
        "           do not follow the reference are left out of the summary below",
        "t_err      max |t - t_ref| over the matched impacts [s]",
        "E error    max |E - E_ref| / E_ref(0) up to the divergence (--wide: E error following,",
        "           and E error window: over the common window)",
        "time       median wall time of one run [s] (--wide: and the fastest)",
        "(docs/output.md defines every column; --wide: every column, --json: every number)",
    ]
)


# the summary's metrics in words (the JSON keeps the keys)
METRIC_NAMES = {
    "energy_error_agreeing": "energy error while the run follows the reference (E error)",
    "energy_error": "energy error over the common window (E error window)",
    "impact_time_error": "impact time error [s] (t_err)",
}


def summary_lines(doc: dict[str, Any], wide: bool) -> list[str]:
    """Per metric, each simulator's best error among the runs that follow the
    reference, its cost, and the cost ratio to the reference at that accuracy."""
    derived = doc.get("derived", {})
    engines = [e for e in dict.fromkeys(r["engine"] for r in doc["results"]) if e != "reference"]
    lines = [
        "summary (runs that follow the reference only): best error, its cost, and that cost "
        "over the",
        "reference's cost at the same accuracy (≥: a lower bound, ≤: an upper bound)",
    ]
    for metric, per in derived.items():
        rows = []
        for engine in engines:
            d = per.get(engine)
            if d is None:
                rows.append([engine, "-", "-", "no run follows the reference"])
                continue
            bound = {"lower": "≥ ", "upper": "≤ "}.get(d["cost_ratio_bound"], "")
            ratio = _fmt(d["cost_ratio"], ".3g")
            rows.append(
                [engine, _fmt(d["best_error"]), f"{d['best_error_cost_s']:.3g}", f"{bound}{ratio}"]
            )
        header = ["simulator", "best error", "its cost [s]", "cost / reference's"]
        lines += ["", f"{METRIC_NAMES.get(metric, metric)}:", table(rows, header, align="lrrl")]
    return lines


def format_bench(doc: dict[str, Any], wide: bool = False) -> str:
    """The work-precision table with its legend, skipped settings, the summary and the
    load (module docstring)."""
    tr = doc["truth"]
    lines = [
        f"scene {doc['scene']}: t = 0 .. {doc['t_end']:.6g}; truth: the reference at "
        f"{tr['setting']}",
        f"({tr['status']}, {tr['impacts']} impacts)",
        "",
        results_table(doc, wide),
        "",
        LEGEND,
    ]
    skipped = doc.get("skipped", [])
    if skipped:
        lines.append("")
    for s in skipped:
        lines.append(_clip(f"skipped: {s['engine']} {s['setting']}: {s['reason']}", wide))
    lines += ["", *summary_lines(doc, wide), ""]
    load = doc["load"]
    lines.append(
        f"load average (1, 5, 15 min) before {_triple(load['before'])}, after "
        f"{_triple(load['after'])}; {doc['cpu_count']} cpus"
    )
    lines.append(f"times: median of {doc['repeats']} runs after a warm-up")
    return "\n".join(lines)


def _clip(line: str, wide: bool) -> str:
    return line if wide or len(line) <= WIDTH else line[: WIDTH - 3] + "..."


def _triple(x: Sequence[float]) -> str:
    return " ".join(f"{v:.2f}" for v in x)
