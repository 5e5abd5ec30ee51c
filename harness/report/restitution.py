"""The report's section for `harness restitution --json`: per engine its γ mapping, its
faithful range per dt, a table of e_eff/γ − 1 by impact speed (with the energy error,
gains, penetration and contact time of each row) and its figure, redrawn from the rows."""

from __future__ import annotations

from typing import Any

from ..restitution.plot import restitution_figure
from ..restitution.study import worst_row
from ..restitution.text import percent, worst_energy_error
from .html import Cell, details, esc, figure, num, paragraph, table


def restitution_section(doc: dict[str, Any]) -> str:
    g = doc["grid"]
    parts = [
        paragraph(
            f"Single impacts, e_eff = −u⁺/u⁻ against the requested γ; faithful where "
            f"|e_eff/γ − 1| ≤ {100 * doc['faithful']:g} %. Grid: γ {_values(g['gamma'])}; "
            f"impact speed {_values(g['speed'])} √(g a); dt {_values(g['dt'])}; onset phase "
            f"{_values(g.get('phase', []))} of a step; geometry "
            f"{', '.join(map(str, g['geometry']))}."
        )
    ]
    for e in doc["engines"]:
        parts.append(_engine(e, g, doc["faithful"]))
    return "\n".join(parts)


def _engine(e: dict[str, Any], grid: dict[str, Any], faithful: float) -> str:
    speeds = grid["speed"]
    rows = []
    for geo in grid["geometry"]:
        for dt in sorted({r["dt"] for r in e["rows"]}, key=lambda d: -(d or float("inf"))):
            for gamma in grid["gamma"]:
                group = [
                    r
                    for r in e["rows"]
                    if r["geometry"] == geo and r["dt"] == dt and r["gamma"] == gamma
                ]
                if group:
                    rows.append(_row(geo, dt, gamma, group, speeds))
    header = ["geometry", "dt", "γ", *[f"u⁻ = {v:g}" for v in speeds]]
    caption = "e_eff/γ − 1 by impact speed [√(g a)], the worst over the onset phases"
    header += ["ΔE/ΔE_exact − 1 (worst faithful)", "energy gained", "penetration / a"]
    header += ["contact time"]
    return (
        f"<h3>{esc(e['engine'])}</h3>"
        + paragraph(f"Mapping: {e['mapping']}")
        + _contract(e)
        + table(header, rows, caption, left=3)
        + figure(
            restitution_figure(e, grid, faithful),
            f"e_eff/gamma - 1 against impact speed, {e['engine']}",
        )
        + details(f"every impact ({len(e['rows'])})", _every_row(e["rows"]))
    )


def _row(geo, dt, gamma, group, speeds) -> list:
    cells: list[Any] = [geo, "exact" if dt is None else num(dt, "g"), num(gamma, "g")]
    cells += [_cell(worst_row([r for r in group if r["speed"] == v])) for v in speeds]
    worst = worst_energy_error(group)
    cells.append(percent(worst) + " %" if worst is not None else "-")
    gains = sum(bool(r["energy_gained"]) for r in group)
    cells.append(Cell(gains or "-", "fail" if gains else ""))
    cells.append(num(max((r["penetration"] or 0.0) for r in group), ".2g"))
    cells.append(num(max((r["contact_time"] or 0.0) for r in group), ".2g"))
    return cells


def _cell(r: dict[str, Any] | None) -> Cell | str:
    if r is None:
        return ""
    if r["outcome"] != "ok" or r["e_error"] is None:
        return Cell(
            r["outcome"][:24], "skip" if not r.get("applicable", True) else "fail", r["outcome"]
        )
    return Cell(percent(r["e_error"]) + " %", "pass" if r["faithful"] else "fail")


def _contract(e: dict[str, Any]) -> str:
    rows = []
    for c in e["contract"]:
        rng = c["range"]
        text = (
            "none"
            if rng is None
            else (f"{rng[0]:g}" if rng[0] == rng[1] else f"{rng[0]:g} … {rng[1]:g}")
        )
        rows.append(
            [
                "exact" if c["dt"] is None else num(c["dt"], "g"),
                c["geometry"],
                Cell(text, "pass" if rng else "fail"),
            ]
        )
    return table(
        ["dt", "geometry", "faithful impact speeds [√(g a)]"], rows, "faithful range", left=2
    )


def _every_row(rows: list[dict[str, Any]]) -> str:
    head = ["geometry", "dt", "phase", "γ", "u⁻", "e_eff", "ΔE", "ΔE exact", "outcome"]
    body = [
        [
            r["geometry"],
            "exact" if r["dt"] is None else num(r["dt"], "g"),
            num(r.get("phase"), "g"),
            num(r["gamma"], "g"),
            num(r["u_pre"], ".4g"),
            num(r["e_eff"], ".6f"),
            num(r["energy_change"], ".4e"),
            num(-r["energy_loss_exact"] if r["energy_loss_exact"] else None, ".4e"),
            r["outcome"],
        ]
        for r in rows
    ]
    return table(head, body, left=3)


def _values(xs) -> str:
    return ", ".join(num(x, "g") for x in xs)
