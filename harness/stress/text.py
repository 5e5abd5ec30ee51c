"""The stress report for the terminal.

Default (at most 100 columns): a matrix of verdicts, one row per case and one column per
simulator, its legend, then why each run failed or was skipped, one line per case and
reason (simulators with the same reason share the line; long reasons are cut), and how
many runs are degraded.
`wide=True`: one row per run with every measurement, and every reason in full."""

from __future__ import annotations

import textwrap
from typing import Any

from ..text import WIDTH, table
from ..text import num as cell_text
from .budget import HARD_CAP_FACTOR
from .judge import FAILED_ENERGY_GAIN, FAILED_PENETRATION

SHORT_VERDICT = {
    "ok": "ok",
    "degraded": "degraded",
    "failed": "FAILED",
    "skipped (budget)": "skipped",
    "skipped (not runnable)": "n/a",
}
LEGEND = (
    "ok: as the reference within the simulator's tolerances; degraded: energy gain or\n"
    "penetration above its tolerance, or a missed or spurious impact; FAILED: NaN, not\n"
    f"finished, energy gain > {FAILED_ENERGY_GAIN:.0%}, penetration > {FAILED_PENETRATION:g} L "
    "(L: the case's length scale), or none of the\n"
    "reference's impacts matched; skipped: predicted over the budget; n/a: cannot run at\n"
    "this dt.  --wide: every measurement and every reason; --json: every number"
)
# Verdicts whose reasons the default report lists (degraded ones: --wide).
LISTED = ("failed", "skipped (budget)", "skipped (not runnable)")


def num(x: Any, spec: str = ".2e") -> str:
    """A cell's text (harness.text.num), floats in scientific notation by default."""
    return cell_text(x, spec)


def format_stress(doc: dict[str, Any], wide: bool = False) -> str:
    """The report (module docstring)."""
    budget = doc["budget_s"]
    lines = textwrap.wrap(
        f"stress: fixed-step engines at dt = {doc['dt']:g} s; a run predicted over {budget:g} s "
        f"is skipped, stopped at {HARD_CAP_FACTOR * budget:g} s",
        WIDTH,
    )
    if wide:
        lines += [wide_table(doc), "", *reason_lines(doc, wide=True)]
    else:
        lines += [verdict_matrix(doc), "", LEGEND, "", *reason_lines(doc, wide=False)]
    load = doc["load"]
    lines.append(
        f"total {doc['wall_time_s']:.1f} s; load average before "
        f"{' '.join(f'{v:.2f}' for v in load['before'])}, after "
        f"{' '.join(f'{v:.2f}' for v in load['after'])}; {doc['cpu_count']} cpus"
    )
    return "\n".join(lines)


def verdict_matrix(doc: dict[str, Any]) -> str:
    """Cases down, simulators across; a simulator's name is split at its first '-' over
    two header lines (pybullet / -default) to keep the columns narrow."""
    rows = doc["cases"]
    cases = list(dict.fromkeys(r["case"] for r in rows))
    engines = list(dict.fromkeys(r["engine"] for r in rows))
    verdict = {
        (r["case"], r["engine"]): SHORT_VERDICT.get(r["verdict"], r["verdict"]) for r in rows
    }
    heads = [_split(e) for e in engines]
    widths = [max(4, len(a), len(b)) for a, b in heads]
    case_w = max(len("case"), *(len(c) for c in cases))

    def line(first: str, cells: list[str]) -> str:
        return "  ".join(
            [first.ljust(case_w), *(c.ljust(w) for c, w in zip(cells, widths, strict=True))]
        ).rstrip()

    out = [line("", [a for a, _ in heads]), line("case", [b for _, b in heads])]
    out.append(line("-" * case_w, ["-" * w for w in widths]))
    for case in cases:
        out.append(line(case, [verdict.get((case, e), "") for e in engines]))
    return "\n".join(out)


def _split(engine: str) -> tuple[str, str]:
    head, sep, tail = engine.partition("-")
    return (head, sep + tail) if sep else (engine, "")


def reason_lines(doc: dict[str, Any], wide: bool) -> list[str]:
    """Why the verdicts were given: per case, engines with the same verdict and reason
    on one line.  Default: failed and skipped runs, cut to WIDTH, and a count of the
    degraded ones; `wide`: every verdict that is not ok, in full."""
    groups: dict[tuple[str, str, str], list[str]] = {}
    degraded = 0
    for r in doc["cases"]:
        if r["verdict"] == "ok" or not r.get("reason"):
            continue
        if not wide and r["verdict"] not in LISTED:
            degraded += 1
            continue
        reason = r["reason"] if wide else _short_reason(r["reason"])
        groups.setdefault((r["case"], r["verdict"], reason), []).append(r["engine"])
    out = ["why:"] if groups else []
    for (case, verdict, reason), engines in groups.items():
        text = f"{case} / {', '.join(engines)}: {verdict}: {reason}"
        out.append(text if wide or len(text) <= WIDTH else text[: WIDTH - 3] + "...")
    if degraded:
        out.append(
            f"({degraded} degraded runs: missed or spurious impacts, energy or penetration; --wide)"
        )
    return out


def _short_reason(reason: str) -> str:
    """The reason without its '(first mismatch: ...)' details (in --wide and --json)."""
    return "; ".join(part.split(" (first mismatch:")[0] for part in reason.split("; "))


def wide_table(doc: dict[str, Any]) -> str:
    header = [
        "case",
        "engine",
        "verdict",
        "status",
        "finished",
        "nan",
        "E_gain",
        "pen[m]",
        "pen/L",
        "missed",
        "spurious",
        "wall[s]",
    ]
    rows = [
        [
            r["case"],
            r["engine"],
            r["verdict"],
            r["status"] or "-",
            num(r["finished"]),
            num(r["nan"]),
            num(r["energy_gain"]),
            num(r["max_penetration"]),
            num(r.get("penetration_relative")),
            num(r["missed_impacts"]),
            num(r["spurious_impacts"]),
            num(r.get("wall_time_s"), ".2f"),
        ]
        for r in doc["cases"]
    ]
    return table(rows, header)
