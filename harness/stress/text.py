"""The stress verdict table for the terminal."""

from __future__ import annotations

from typing import Any

from ..text import num as cell_text
from ..text import table


def num(x: Any, spec: str = ".2e") -> str:
    """A cell's text (harness.text.num), floats in scientific notation by default."""
    return cell_text(x, spec)


def format_stress(doc: dict[str, Any]) -> str:
    """Verdict table, then the reason of every verdict that is not ok."""
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
    lines = [
        f"stress: fixed-step engines at dt={doc['dt']:g}, budget {doc['budget_s']:g} s per run",
        table(rows, header),
        "",
    ]
    for r in doc["cases"]:
        if r["verdict"] != "ok" and r.get("reason"):
            lines.append(f"{r['case']} / {r['engine']}: {r['verdict']}: {r['reason']}")
    load = doc["load"]
    lines.append(
        f"total {doc['wall_time_s']:.1f} s; load average before "
        f"{' '.join(f'{v:.2f}' for v in load['before'])}, after "
        f"{' '.join(f'{v:.2f}' for v in load['after'])}; {doc['cpu_count']} cpus"
    )
    return "\n".join(lines)
