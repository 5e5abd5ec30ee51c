"""The fidelity study for the terminal: α* per engine and dt with the fitted k, then
the leading impacts matched at every scale."""

from __future__ import annotations

import math
import textwrap
from typing import Any

from ..text import table

WIDTH = 100
LADDER_SPACED = 30  # up to this many scales the ladder's characters are spaced


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


def fit_text(fit: dict[str, Any]) -> str:
    """'2.00 ± 0.05, grid 1.75..2.25 (3 dts)'; without a standard error with 2 dts; '-'
    with fewer."""
    if fit["k"] is None:
        return "-"
    text = f"{fit['k']:.2f}"
    if fit["k_stderr"] is not None:
        text += f" ± {fit['k_stderr']:.2f}"
    if fit.get("k_grid"):
        lo, hi = fit["k_grid"]
        text += f", grid {lo:.2f}..{hi:.2f}"
    return text + f" ({fit['n_points']} dts)"


def dt_label(dt: float | None) -> str:
    return "event-driven" if dt is None else f"dt={dt:g}"


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
    """(dts, rows): per engine, `cell(star)` at each dt and `fit(engine's fit)`."""
    dts = sorted({s["dt"] for s in doc["alpha_star"]}, key=lambda d: -(d or math.inf))
    fits = {f["engine"]: f for f in doc["fits"]}
    rows = []
    for engine in doc["engines"]:
        by_dt = {s["dt"]: s for s in doc["alpha_star"] if s["engine"] == engine}
        cells = [cell(by_dt[d]) if d in by_dt else "" for d in dts]
        rows.append([engine, *cells, fit(fits[engine]) if engine in fits else "-"])
    return dts, rows


def _alpha_star_table(doc: dict[str, Any]) -> str:
    dts, rows = per_dt_rows(doc, alpha_star_text, fit_text)
    header = ["engine", *[dt_label(d) for d in dts], "k of α* ~ dt^k"]
    _, low = per_dt_rows(doc, lowest_pass_text, lambda f: fit_text(f["lowest"]))
    low_header = ["engine", *[dt_label(d) for d in dts], "k"]
    align = "l" + "r" * (len(header) - 1)
    return (
        "α* (smallest inclination passed with every larger one passed; '<=': passes at "
        "every scale run,\n'>': fails at the largest); k ± its standard error, and the range "
        "the grid's brackets allow for k\n"
        + table(rows, header, align)
        + "\n\nsmallest inclination passed at all (between it and α*, passing depends on "
        "the exact alpha)\n" + table(low, low_header, align) + _horizon_table(doc, dts, align)
    )


def _horizon_table(doc: dict[str, Any], dts: list[float | None], align: str) -> str:
    """α* when a run fails only below the horizon band of its scale and dt."""
    if not any("horizon" in s for s in doc["alpha_star"]):
        return ""
    _, rows = per_dt_rows(
        doc, lambda s: alpha_star_text(s["horizon"]) if "horizon" in s else "-", lambda f: ""
    )
    header = ["engine", *[dt_label(d) for d in dts], ""]
    return (
        "\n\nα* against the horizon (a run fails only when its leading impacts matched "
        "fall below\nthe 10 % value of the grid model's at that scale and dt; "
        f"{doc.get('horizon_runs')} grid phases)\n" + table(rows, header, align)
    )


def ladder_cell(row: dict[str, Any]) -> str:
    """Leading impacts matched, 'x' when the run fails, 's' skipped, '-' not assessed."""
    if row["skipped"]:
        return "s"
    if row["passes"] is None:
        return "-"
    return f"{row['leading_matched']}{'' if row['passes'] else 'x'}"


def ladder_char(row: dict[str, Any] | None) -> str:
    """One character per scale: '+' passes, '0'..'9' fails (tenths of the leading
    impacts matched), 's' skipped for the budget, '.' not assessed, ' ' not run."""
    if row is None:
        return " "
    if row["skipped"]:
        return "s"
    if row["passes"] is None:
        return "."
    if row["passes"]:
        return "+"
    if row.get("within_horizon"):
        return "h"
    return str(min(9, int(10 * (row.get("match_fraction") or 0.0))))


def _ladder(doc: dict[str, Any]) -> str:
    refs = doc["reference"]
    groups: dict[tuple[str, Any], dict[float, dict]] = {}
    for r in doc["runs"]:
        groups.setdefault((r["engine"], r["dt"]), {})[r["eps"]] = r
    sep = " " if len(doc["eps"]) <= LADDER_SPACED else ""  # one character per scale
    rows = [
        [
            engine,
            "-" if dt is None else f"{dt:.0e}",
            sep.join(ladder_char(by_eps.get(e)) for e in doc["eps"]),
        ]
        for (engine, dt), by_eps in groups.items()
    ]
    header = ["engine", "dt", f"α {refs[0]['alpha']:.1e} -> {refs[-1]['alpha']:.1e}"]
    return (
        "each scale, largest α first: + passes, 0-9 fails (tenths of the leading impacts\n"
        "matched), h fails but within the horizon band (as good as its dt allows), s skipped\n"
        "(budget), . not assessed\n" + table(rows, header, "lll")
    )


def _symbols(text: str) -> str:
    """'q -> eps^2 q' as 'q → ε² q' (the JSON keeps the ASCII spelling)."""
    return text.replace("->", "→").replace("eps^2", "ε²").replace("eps", "ε")
