"""The fidelity study for the terminal: α* per engine and dt with the fitted k, then
the leading impacts matched at every scale."""

from __future__ import annotations

import math
import textwrap
from typing import Any

from ..text import WIDTH, column_tables, num, run_label, table


def alpha_star_text(star: dict[str, Any]) -> str:
    """'2.8e-04'; '<= 2.8e-10' (passes at every α run); '> 2.8e-02' (fails at the
    largest); '-' (not measured)."""
    bound = star["bound"]
    if bound == "bracket":
        return f"{star['alpha_star']:.2g}"
    if bound == "at most":
        return f"<= {star['alpha_star']:.2g}"
    if bound == "above grid":
        return f"> {star['alpha_first_fail']:.2g}"
    return "-"


FIT_HEADER = ["k", "k stderr", "k min", "k max", "dts"]


def fit_cells(fit: dict[str, Any] | None) -> list[str]:
    """k, its standard error, the least and largest k the grid's brackets allow and the
    number of dts fitted, one cell each ('-' where there is none)."""
    if fit is None or fit["k"] is None:
        return ["-"] * len(FIT_HEADER)
    grid = fit.get("k_grid") or [None, None]
    return [num(fit["k"], ".2f"), num(fit["k_stderr"], ".2f"), num(grid[0], ".2f"),
            num(grid[1], ".2f"), str(fit["n_points"])]  # fmt: skip


def dt_label(dt: float | None) -> str:
    return "event-driven" if dt is None else f"dt={dt:g}"


def dt_header(dt: float | None) -> str:
    """A table's column for one dt: 'event-driven', 'dt = 0.001 s'."""
    return "event-driven" if dt is None else f"dt = {dt:g} s"


def format_fidelity(doc: dict[str, Any]) -> str:
    """Header (scaling, criteria, the reference's exponent), the α* table with k, the
    matched-impacts ladder and the skipped runs."""
    lines = [textwrap.fill(x, WIDTH, subsequent_indent="  ") for x in header_lines(doc)]
    lines += ["", _alpha_star_table(doc), "", _ladder(doc)]
    skipped = [r for r in doc["runs"] if r["skipped"]]
    for r in skipped:
        lines.append(
            f"skipped: {r['engine']} {dt_label(r['dt'])} eps={r['eps']:.3g}: {r['skipped']}"
        )
    load = doc["load"]
    lines.append(
        f"total {doc['wall_time_s']:.1f} s; load average before {load['before'][0]:.2f}, after "
        f"{load['after'][0]:.2f}; {doc['cpu_count']} cpus; budget {doc['budget_s']:g} s per run"
    )
    return "\n".join(lines)


def header_lines(doc: dict[str, Any]) -> list[str]:
    """What was scaled and run, the criteria, and whether the exponent took part."""
    refs = doc["reference"]
    window = (
        "engines run just past the leading impacts"
        if doc["window"] == "leading"
        else "engines run to the reference's end (the whole motion)"
    )
    return [
        f"fidelity on {doc['scene']}: {_symbols(doc['scaling'])}; {len(refs)} scales, α "
        f"{refs[0]['alpha']:.3g} .. {refs[-1]['alpha']:.3g}; {window}",
        f"criteria: {doc['criteria']['rule']}",
        exponent_line(doc),
    ]


def exponent_line(doc: dict[str, Any]) -> str:
    """Where the reference has a c, and whether any run was judged on it."""
    refs = doc["reference"]
    with_c = [r["c"] for r in refs if r["c"] is not None]
    judged = sum(1 for r in doc["runs"] if r.get("criterion") == "impacts and c")
    if not with_c:
        ends = sorted({r["status"] for r in refs})
        return (
            f"the reference has no energy exponent c at any scale (it ends {', '.join(ends)}): "
            "α* rests on the impact criterion alone"
        )
    text = (
        f"reference c = {min(with_c):.3f} .. {max(with_c):.3f} at {len(with_c)} of "
        f"{len(refs)} scales; "
    )
    if judged:
        return text + f"{judged} engine runs had a c and were judged on it too"
    why = (
        "engines stop after the leading impacts; --window whole runs them to the end"
        if doc["window"] == "leading"
        else "no engine run followed the reference to its singularity"
    )
    return text + f"no engine run has a c ({why}): α* rests on the impact criterion alone"


def lowest_pass_text(star: dict[str, Any]) -> str:
    """The smallest α passed: '1.5e-04'; '<= 2.8e-10' at the grid's bottom; '-' none."""
    if star["alpha_lowest_pass"] is None:
        return "-"
    text = f"{star['alpha_lowest_pass']:.2g}"
    return text if star["alpha_below_lowest_pass"] is not None else "<= " + text


def per_dt_rows(doc: dict[str, Any], cell, fit) -> tuple[list[float | None], list[list[str]]]:
    """(dts, rows): per engine, `cell(star)` at each dt and the cells `fit(engine's fit)`
    (the fit None when the engine has none)."""
    dts = sorted({s["dt"] for s in doc["alpha_star"]}, key=lambda d: -(d or math.inf))
    fits = {f["engine"]: f for f in doc["fits"]}
    rows = []
    for engine in doc["engines"]:
        by_dt = {s["dt"]: s for s in doc["alpha_star"] if s["engine"] == engine}
        cells = [cell(by_dt[d]) if d in by_dt else "" for d in dts]
        rows.append([engine, *cells, *fit(fits.get(engine))])
    return dts, rows


def _alpha_star_table(doc: dict[str, Any]) -> str:
    dts, rows = per_dt_rows(doc, alpha_star_text, fit_cells)
    header = ["engine", *[dt_header(d) for d in dts], *FIT_HEADER]
    _, low = per_dt_rows(doc, lowest_pass_text, lambda f: fit_cells(f and f["lowest"]))
    align = "l" + "r" * (len(header) - 1)
    return (
        "α* [rad] at each dt: the smallest inclination passed with every larger one passed "
        "('<=': it\npasses at every scale run, '>': it fails at the largest); k: the exponent "
        "of α* ~ dt^k fitted\nover dts (their number), its standard error (3 dts or more) and "
        "the least and largest k the\ngrid's brackets allow\n"
        + table(rows, header, align)
        + "\n\nthe smallest inclination [rad] passed at all (between it and α*, passing depends "
        "on the exact α)\n" + table(low, header, align) + _horizon_table(doc, dts)
    )


def _horizon_table(doc: dict[str, Any], dts: list[float | None]) -> str:
    """α* when a run fails only below the horizon band of its scale and dt."""
    if not any("horizon" in s for s in doc["alpha_star"]):
        return ""
    _, rows = per_dt_rows(
        doc, lambda s: alpha_star_text(s["horizon"]) if "horizon" in s else "-", lambda f: []
    )
    header = ["engine", *[dt_header(d) for d in dts]]
    return (
        "\n\nα* [rad] against the horizon (a run fails only when its leading impacts matched "
        "fall below\nthe 10 % value of the grid model's at that scale and dt; "
        f"{doc.get('horizon_runs')} grid phases)\n"
        + table(rows, header, "l" + "r" * (len(header) - 1))
    )


def matched_cell(row: dict[str, Any] | None) -> str:
    """The per-scale table's cell: the leading impacts the run matched, 'skipped' (over
    the time budget), '-' (not assessed, or not run)."""
    if row is None or row["passes"] is None and not row["skipped"]:
        return "-"
    return "skipped" if row["skipped"] else str(row["leading_matched"])


def _ladder(doc: dict[str, Any]) -> str:
    """One row per scale (largest α first): α, ε, the reference's leading impacts and
    each run's leading impacts matched; the runs in as many tables as WIDTH needs, then
    a sentence per run whose verdict the count does not show (c, the horizon band)."""
    groups: dict[tuple[str, Any], dict[float, dict]] = {}
    for r in doc["runs"]:
        groups.setdefault((r["engine"], r["dt"]), {})[r["eps"]] = r
    refs = {r["eps"]: r for r in doc["reference"]}
    fixed = [[f"{refs[e]['alpha']:.2g}", f"{e:.3g}", str(refs[e]["leading"])] for e in doc["eps"]]
    head = ["α [rad]", "ε", "of"]
    columns = [
        (run_label(*key), [matched_cell(by_eps.get(e)) for e in doc["eps"]])
        for key, by_eps in groups.items()
    ]
    fraction = doc["criteria"].get("match_fraction", 0.9)
    lines = [
        "each scale, largest α first: the leading impacts each run matches, of the reference's "
        f"`of`\n(a run passes with at least {fraction:.0%} of them); skipped: predicted over "
        "the time budget; -: not assessed",
        *column_tables(head, fixed, columns, "rrr"),
    ]
    lines += _verdict_notes(groups)
    return "\n".join(lines)


def _verdict_notes(groups) -> list[str]:
    """Runs whose verdict the matched count does not show: enough impacts but c off the
    reference's; fails but within the horizon band."""
    c_fails, within = [], []
    for (engine, dt), by_eps in groups.items():
        for r in by_eps.values():
            alpha = f"α = {r['alpha']:.2g}"
            if r.get("impacts_pass") and r["passes"] is False:
                c_fails.append(f"{run_label(engine, dt)} at {alpha} ({r.get('c_check')})")
            elif r["passes"] is False and r.get("within_horizon"):
                within.append(f"{run_label(engine, dt)} at {alpha}")
    notes = []
    if c_fails:
        notes.append("fails on c alone (enough impacts matched): " + "; ".join(c_fails))
    if within:
        notes.append(
            "fails but within the horizon band (matches at least the grid model's 10 % "
            "value at that scale and dt: as good as its dt allows): " + ", ".join(within)
        )
    return [textwrap.fill(n, WIDTH, subsequent_indent="  ") for n in notes]


def _symbols(text: str) -> str:
    """'q -> eps^2 q' as 'q → ε² q' (the JSON keeps the ASCII spelling)."""
    return text.replace("->", "→").replace("eps^2", "ε²").replace("eps", "ε")
