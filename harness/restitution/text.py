"""The restitution study as text: per engine, its γ mapping, a table of e_eff/γ − 1 by
impact speed (rows: geometry, dt, γ; each cell the worst over the onset phases) with the
worst energy error, energy gains, penetration and contact time of each row, and its
faithful range.  Lines stay within
WIDTH columns: with many speeds the speed columns are split into several tables."""

from __future__ import annotations

import math
import textwrap

from ..text import WIDTH
from .study import worst_row

KEY = "{:<6} {:>6} {:>5}"  # geometry, dt, gamma
CELL = 7
EXTRAS_HEAD = f" {'dE/dEx-1':>9} {'gain':>4} {'pen/a':>7} {'t_c':>7}"
OUTCOME_CODES = {"ok": None, "no contact": "none", "no separation": "stuck"}


def format_restitution(doc: dict) -> str:
    g = doc["grid"]
    head = (
        f"single impacts, e_eff = −u⁺/u⁻ against γ; faithful: "
        f"|e_eff/γ − 1| ≤ {100 * doc['faithful']:g} %"
    )
    grid = (
        f"grid: γ {_values(g['gamma'])}; impact speed {_values(g['speed'])} √(g a); "
        f"dt {_values(g['dt'])}; onset phase {_values(g.get('phase', []))} of a step; "
        f"geometry {', '.join(g['geometry'])}"
    )
    lines = [*textwrap.wrap(head, WIDTH), *textwrap.wrap(grid, WIDTH, subsequent_indent="  ")]
    for e in doc["engines"]:
        lines += ["", *engine_text(e, g)]
    lines += ["", *legend()]
    return "\n".join(lines)


def engine_text(e: dict, grid: dict) -> list[str]:
    wrap = textwrap.wrap(f"mapping: {e['mapping']}", WIDTH, subsequent_indent="  ")
    lines = [f"{e['engine']}  ({len(e['rows'])} impacts, {e['wall_time_s']:.1f} s)", *wrap]
    speeds = grid["speed"]
    per_table = max(1, (WIDTH - len(KEY.format("", "", "")) - len(EXTRAS_HEAD)) // CELL)
    chunks = [speeds[i : i + per_table] for i in range(0, len(speeds), per_table)]
    for i, chunk in enumerate(chunks):
        lines += _table(e, grid, chunk, extras=i == len(chunks) - 1)
    lines += contract_lines(e)
    return lines


def _table(e: dict, grid: dict, speeds: list[float], extras: bool) -> list[str]:
    head = KEY.format("geom", "dt [s]", "γ") + "".join(f"{_speed(v):>{CELL}}" for v in speeds)
    over = " " * (len(KEY.format("", "", "")) + 1) + "e_eff/γ − 1 [%] at impact speed u⁻ [√(g a)]:"
    lines = [over, head + (EXTRAS_HEAD if extras else "")]
    for key, rows in _groups(e["rows"], grid):
        cells = "".join(
            f"{_cell(worst_row([r for r in rows if r['speed'] == v])):>{CELL}}" for v in speeds
        )
        lines.append(KEY.format(*key) + cells + (_extras(rows) if extras else ""))
    return lines


def _groups(rows: list[dict], grid: dict):
    dts = sorted({r["dt"] for r in rows}, key=lambda d: -(d if d is not None else math.inf))
    for geo in grid["geometry"]:
        for dt in dts:
            for gamma in grid["gamma"]:
                group = [
                    r
                    for r in rows
                    if r["geometry"] == geo and r["dt"] == dt and r["gamma"] == gamma
                ]
                if group:
                    yield (geo, "-" if dt is None else f"{dt:.0e}", f"{gamma:g}"), group


def _cell(r: dict | None) -> str:
    if r is None:
        return ""
    if r["outcome"].startswith("run failed"):
        return "fail"
    if r["outcome"] != "ok" or r["e_error"] is None:
        return OUTCOME_CODES.get(r["outcome"]) or "n/a"
    return percent(r["e_error"])


def percent(x: float) -> str:
    """x as a signed percentage in at most 6 characters."""
    p = 100.0 * x
    if abs(p) < 9.995:
        return f"{p:+.2f}"
    if abs(p) < 999.5:
        return f"{p:+.0f}"
    return ">+999" if p > 0 else "<-999"


def worst_energy_error(rows: list[dict]) -> float | None:
    """The largest |ΔE/ΔE_exact − 1| among the faithful impacts (None: none faithful):
    whether the energy is right where the bounce is."""
    ok = [
        r["energy_loss_error"] for r in rows if r["faithful"] and r["energy_loss_error"] is not None
    ]
    return max(ok, key=abs, default=None)


def _extras(rows: list[dict]) -> str:
    worst = worst_energy_error(rows)
    energy = percent(worst) + "%" if worst is not None else "-"
    gains = sum(bool(r["energy_gained"]) for r in rows)
    pen = max((r["penetration"] for r in rows if r["penetration"] is not None), default=None)
    t_c = max((r["contact_time"] for r in rows if r["contact_time"] is not None), default=None)
    return f" {energy:>9} {gains or '-':>4} {_sci(pen):>7} {_sci(t_c):>7}"


def contract_lines(e: dict) -> list[str]:
    """The faithful range of each dt: for all geometries, and per geometry."""
    out = []
    for c in e["contract"]:
        if c["geometry"] != "all":
            continue
        dt = "event-driven" if c["dt"] is None else f"dt {c['dt']:g}"
        per_geo = [
            f"{x['geometry']} {_range(x['range'])}"
            for x in e["contract"]
            if x["dt"] == c["dt"] and x["geometry"] != "all"
        ]
        text = f"faithful at {dt}: {_range(c['range'])} ({'; '.join(per_geo)})"
        out += textwrap.wrap(text, WIDTH, subsequent_indent="  ")
    return out


def _range(r: list[float] | None) -> str:
    if r is None:
        return "none"
    return f"u- = {_speed(r[0])}" if r[0] == r[1] else f"u- = {_speed(r[0])}..{_speed(r[1])}"


def legend() -> list[str]:
    return textwrap.wrap(
        "Columns: e_eff/gamma - 1 [%] at each impact speed u- [sqrt(g a)], the worst over "
        "the onset phases (stuck: did not "
        "leave the ground; none: never touched; fail: the run failed; n/a: the model stops "
        "there, e.g. the reference at a simultaneous impact); dE/dEx-1: the "
        "worst energy change against the exact loss (1 - gamma^2) u-^2/(2w) among the "
        "faithful impacts; gain: impacts that gained energy (any); pen/a: deepest "
        "penetration; t_c: longest contact [sqrt(a/g)].",
        WIDTH,
    )


def _speed(v: float) -> str:
    return f"{v:g}"


def _sci(x: float | None) -> str:
    return "-" if x is None else f"{x:.1e}"


def _values(xs: list) -> str:
    return ", ".join(f"{x:g}" for x in xs)
