"""One HTML section per kind of result document.  Every figure is redrawn from the
document's own data (bench rows → work-precision, fidelity rows → α* and matched
fractions, sweep points → exponent map), so a report depends on no file but its inputs."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from ..text import quantile_cells
from .html import Cell, details, esc, figure, num, paragraph, table
from .links import file_href, url_scheme

# ----------------------------------------------------------------------------- provenance


def provenance_section(
    doc: dict[str, Any],
    rebuilt_command: str | None = None,
    shared_versions: dict[str, str] | None = None,
) -> str:
    """The command that made the document, when and where; its versions only where they
    differ from `shared_versions` (the report's one versions table, `versions_table`)."""
    prov = doc.get("provenance")
    if not prov:
        text = "<h3>Provenance</h3>"
        if rebuilt_command:
            return text + (
                "<p>Equivalent command, rebuilt from the sweep's manifest.json (the directory "
                f"records no provenance):</p><pre>{esc(rebuilt_command)}</pre>"
            )
        return text + paragraph(
            "Not recorded: this document was made before results carried a provenance object.",
            "muted",
        )
    own = prov.get("versions", {})
    differ = [[k, v] for k, v in sorted(own.items()) if (shared_versions or {}).get(k) != v]
    if not differ:
        versions = paragraph("Versions: as in the table at the end of the report.", "muted")
    else:
        caption = "versions that differ from the table at the end of the report"
        versions = table(["package", "version"], differ, caption, left=2)
    return (
        "<h3>Provenance</h3>"
        f"<p>Command:</p><pre>{esc(prov.get('command', '-'))}</pre>"
        f"<p>Created {esc(prov.get('created', '-'))} on {esc(prov.get('host', '-'))}.</p>"
        + versions
    )


def shared_versions(docs: list[dict[str, Any]]) -> dict[str, str]:
    """The versions of the first document that records them (the report's table)."""
    for doc in docs:
        versions = (doc.get("provenance") or {}).get("versions")
        if versions:
            return dict(versions)
    return {}


def versions_table(versions: dict[str, str]) -> str:
    """The one versions table of the report (importlib.metadata)."""
    rows = [[k, v] for k, v in sorted(versions.items())]
    return table(["package", "version"], rows, "versions (importlib.metadata)", left=2)


# ----------------------------------------------------------------------------- compare


def compare_section(doc: dict[str, Any], out_dir: Path) -> str:
    ref = doc["reference"]
    exp = ref.get("exponent") or {}
    parts = [
        paragraph(
            f"Scene {doc['scene']} (restitution {doc.get('restitution')}): the reference ended "
            f"{ref['status']} at t = {num(ref['t_final'], '.6g')} after {ref.get('n_impacts')} "
            f"impacts ({num(ref.get('wall_time_s'), '.2g')} s); "
            + (f"c = {exp['c']:.3f}." if exp.get("c") is not None else "no energy exponent c.")
        )
    ]
    rows = []
    for e in doc["engines"]:
        c = (e.get("exponent") or {}).get("c")
        rows.append(
            [
                e["engine"],
                num(e["dt"], "g"),
                e["status"],
                e["impacts_matched"],
                e["reference_impacts"],
                num(e["first_divergence_time"], ".4g"),
                num(e["energy_error_agreeing"], ".2e"),
                num(e["impact_time_error"], ".2e"),
                num(c, ".3f"),
                num(e["wall_time_s"], ".3g"),
                *_horizon_cells(e.get("horizon")),
            ]
        )
    parts.append(
        table(
            [
                "engine",
                "dt",
                "status",
                "matched",
                "of",
                "diverges at [s]",
                "E error",
                "t error [s]",
                "c",
                "wall [s]",
                "grid 10 %",
                "grid 90 %",
                "within",
                "own error",
                "own 10 %",
                "own 90 %",
            ],
            rows,
            "runs against the reference (docs/output.md defines every column)",
        )
    )
    parts.append("<h3>Verdicts</h3>")
    parts += [paragraph(e["verdict"], "verdict") for e in doc["engines"] if e.get("verdict")]
    first = doc.get("first_to_diverge")
    if first:
        parts.append(paragraph(f"First to diverge: {first['why']}"))
    parts.append(_horizon_paragraphs(doc))
    parts += _branch_paragraphs(doc)
    parts.append(recording_link(doc.get("recording"), out_dir))
    return "\n".join(parts)


def _branch_paragraphs(doc: dict[str, Any]) -> list[str]:
    """After the reference's undecidable state: the branch each run follows (the
    engines' `branch.sentence`, docs/output.md); nothing when there is none."""
    sentences = [(e.get("branch") or {}).get("sentence") for e in doc["engines"]]
    sentences = [s for s in sentences if s]
    if not sentences:
        return []
    head = "After the undecidable state: the branch each run follows (harness branches)"
    return [f"<h3>{head}</h3>", *[paragraph(s) for s in sentences]]


def _horizon_cells(h: dict[str, Any] | None) -> list[Any]:
    """The grid model's 10 % and 90 % matched, within (its verdict as the cell's class),
    own error, the perturbed model's 10 % and 90 % matched."""
    if not h:
        return ["-"] * 6
    within: Any = "-"
    if h.get("within") is not None:
        ok = h["within"]
        within = Cell(num(ok), "pass" if ok else "fail", "within" if ok else "below")
    return [*quantile_cells(h.get("matched_quantiles")), within, num(h.get("own_error"), ".2e"),
            *quantile_cells(h.get("own_error_quantiles"))]  # fmt: skip


def _horizon_paragraphs(doc: dict[str, Any]) -> str:
    """The horizon sentences (docs/fidelity.md, "Horizon"), or nothing without them."""
    rows = [e["horizon"] for e in doc["engines"] if e.get("horizon")]
    if not rows:
        return ""
    rate = rows[0].get("lyapunov_per_impact")
    head = paragraph(
        "Horizon: band (a) is the leading impacts the exact model matches with its impacts on "
        "the run's step grid (10–90 % of random grid phases); band (b) the exact model "
        "perturbed at the run's own error; a separation grows by e^λ per impact, λ = "
        + num(rate, ".3g")
    )
    return "\n".join(
        [head, *[paragraph(h["sentence"], "verdict") for h in rows if h.get("sentence")]]
    )


def recording_link(path: str | None, out_dir: Path) -> str:
    """A relative link to the run's .rrd recording (open it with `rerun FILE`); an
    http(s) URL as it is; nothing else (harness.report.links)."""
    if not path:
        return paragraph("No recording was made (compare --record FILE.rrd makes one).", "muted")
    target = Path(path)
    href = file_href(path, out_dir)
    missing = not url_scheme(path) and not target.exists()
    found = " (not found when this report was written)" if missing else ""
    return (
        f'<p>Recording: <a href="{esc(href)}">{esc(target.name)}</a>{esc(found)}; open it with '
        f"<code>rerun {esc(target.name)}</code> (docs/recording.md).</p>"
    )


# ----------------------------------------------------------------------------- bench


def bench_section(doc: dict[str, Any]) -> str:
    from ..bench import work_precision_figure
    from ..bench.table import match_columns

    tr = doc["truth"]
    parts = [
        paragraph(
            f"Scene {doc['scene']}, t = 0 .. {num(doc['t_end'], '.6g')}; truth: reference "
            f"{tr['setting']} ({tr['status']}, {tr['impacts']} impacts); median of "
            f"{doc['repeats']} runs after a warm-up; budget {num(doc['budget_s'], 'g')} s "
            "per setting."
        )
    ]
    rows = [
        [
            r["engine"],
            r["setting"],
            r["status"],
            num(r["wall_time_s"], ".3g"),
            *match_columns(r),
            num(r["impact_time_error"], ".2e"),
            num(r["energy_error"], ".2e"),
            num(r["energy_error_agreeing"], ".2e"),
        ]
        for r in doc["results"]
    ]
    header = [
        "engine",
        "setting",
        "status",
        "median [s]",
        "matched",
        "of",
        "follows",
        "t err [s]",
        "E err",
        "E err<div",
    ]
    caption = "work-precision rows (matched: the first reference impacts the run reproduces, of "
    caption += "the reference's impacts in the common window; follows no: fewer than 9 of its "
    caption += "first 10 impacts matched, left out of the summary)"
    parts.append(table(header, rows, caption, left=2))
    for s in doc.get("skipped", []):
        parts.append(paragraph(f"skipped: {s['engine']} {s['setting']}: {s['reason']}", "muted"))
    derived = doc.get("derived", {}).get("energy_error_agreeing", {})
    if derived:
        drows = [
            [
                eng,
                num(d["error_at_reference_cost"], ".2e"),
                d["error_at_reference_cost_bound"],
                num(d["best_error"], ".2e"),
                num(d["cost_ratio"], ".3g"),
                d["cost_ratio_bound"] or "-",
            ]
            for eng, d in derived.items()
        ]
        parts.append(
            table(
                ["engine", "error at reference cost", "bound", "best error", "cost ratio", "bound"],
                drows,
                "energy error before divergence, runs that follow the reference: at the "
                "reference's cost, and cost at equal accuracy over the reference's",
            )
        )
    parts.append(
        figure(
            work_precision_figure(doc),
            f"work-precision on {doc['scene']}",
            "Work-precision, redrawn from the rows above.",
        )
    )
    return "\n".join(parts)


# ----------------------------------------------------------------------------- fidelity


def fidelity_section(doc: dict[str, Any]) -> str:
    from ..fidelity import alpha_star_figure, matched_figure
    from ..fidelity.text import (
        FIT_HEADER,
        alpha_star_text,
        dt_header,
        dt_label,
        fit_cells,
        header_lines,
        lowest_pass_text,
        matched_cell,
    )

    parts = [paragraph(line) for line in header_lines(doc)]
    dts = sorted(
        {s["dt"] for s in doc["alpha_star"]}, key=lambda d: -(d if d is not None else 1e300)
    )
    fits = {f["engine"]: f for f in doc["fits"]}
    rows = []
    for engine in doc["engines"]:
        by_dt = {s["dt"]: s for s in doc["alpha_star"] if s["engine"] == engine}
        cells = [
            Cell(alpha_star_text(by_dt[d]), _star_class(by_dt[d]), by_dt[d]["bound"])
            if d in by_dt
            else ""
            for d in dts
        ]
        rows.append([engine, *cells, *fit_cells(fits.get(engine))])
    parts.append(
        table(
            ["engine", *[dt_header(d) for d in dts], *FIT_HEADER],
            rows,
            "α* [rad]: the smallest inclination the engine follows ('<=' passes at every scale "
            "run, '>' fails at the largest); k: the exponent of α* ∝ dt^k, its standard error, "
            "the least and largest k the grid's brackets allow, the number of dts fitted",
        )
    )
    low_rows = []
    for engine in doc["engines"]:
        by_dt = {s["dt"]: s for s in doc["alpha_star"] if s["engine"] == engine}
        low = fits[engine]["lowest"] if engine in fits else None
        cells = [lowest_pass_text(by_dt[d]) if d in by_dt else "" for d in dts]
        low_rows.append([engine, *cells, *fit_cells(low)])
    parts.append(
        table(
            ["engine", *[dt_header(d) for d in dts], *FIT_HEADER],
            low_rows,
            "the smallest inclination passed at all: between it and α*, passing depends on "
            "the exact α (the transition band)",
        )
    )
    parts.append(_horizon_star_table(doc, dts))
    parts.append(figure(alpha_star_figure(doc), f"alpha* against dt on {doc['scene']}"))
    parts.append(_ladder_table(doc, matched_cell))
    parts.append(figure(matched_figure(doc), f"leading impacts matched on {doc['scene']}"))
    parts.append(_fidelity_reference_table(doc))
    parts.append(details(f"every run ({len(doc['runs'])})", _fidelity_runs_table(doc)))
    skipped = [r for r in doc["runs"] if r["skipped"]]
    for r in skipped:
        parts.append(
            paragraph(
                f"skipped: {r['engine']} {dt_label(r['dt'])} ε = {r['eps']:.3g}: {r['skipped']}",
                "muted",
            )
        )
    return "\n".join(parts)


def _horizon_star_table(doc: dict[str, Any], dts: list) -> str:
    """α* when a run fails only below the horizon band (fidelity --horizon-runs)."""
    from ..fidelity.text import alpha_star_text, dt_header

    if not any("horizon" in s for s in doc["alpha_star"]):
        return ""
    rows = []
    for engine in doc["engines"]:
        by_dt = {s["dt"]: s for s in doc["alpha_star"] if s["engine"] == engine}
        cells = [
            Cell(alpha_star_text(s["horizon"]), _star_class(s["horizon"]), s["horizon"]["bound"])
            if (s := by_dt.get(d)) and "horizon" in s
            else "-"
            for d in dts
        ]
        rows.append([engine, *cells])
    return table(
        ["engine", *[dt_header(d) for d in dts]],
        rows,
        "α* against the horizon: a run fails only when its leading impacts matched fall below "
        "the 10 % value of the grid model's at that scale and dt",
    )


def _star_class(star: dict[str, Any]) -> str:
    return {"bracket": "pass", "at most": "pass", "above grid": "fail"}.get(star["bound"], "na")


def _ladder_table(doc: dict[str, Any], cell) -> str:
    alphas = {r["eps"]: r["alpha"] for r in doc["reference"]}
    groups: dict[tuple, dict[float, dict]] = {}
    for r in doc["runs"]:
        groups.setdefault((r["engine"], r["dt"]), {})[r["eps"]] = r
    rows = []
    for (engine, dt), by_eps in groups.items():
        cells = []
        for e in doc["eps"]:
            r = by_eps.get(e)
            if r is None:
                cells.append("")
                continue
            cls = "skip" if r["skipped"] else ("na" if r["passes"] is None else "")
            cls = cls or ("pass" if r["passes"] else "fail")
            cells.append(Cell(cell(r), cls, r["skipped"] or r.get("first_mismatch") or ""))
        rows.append([engine, num(dt, ".0e"), *cells])
    header = ["engine", "dt", *[f"α {alphas[e]:.1e}" for e in doc["eps"]]]
    return table(
        header,
        rows,
        f"leading impacts matched (of {doc['criteria']['leading']}) at each α [rad]: green "
        "passes, red fails, grey 'skipped' for the budget",
        left=2,
        vertical_from=2,
    )


def _fidelity_reference_table(doc: dict[str, Any]) -> str:
    rows = [
        [
            num(r["eps"], ".3g"),
            num(r["alpha"], ".3g"),
            r["status"],
            r["impacts"],
            r["leading"],
            num(r["leading_t_last_scaled"], ".4g"),
            num(r["c"], ".3f"),
            num(r["same_contacts_as_first"]),
            num(r["scaled_time_shift"], ".2e"),
        ]
        for r in doc["reference"]
    ]
    header = [
        "ε",
        "α",
        "status",
        "impacts",
        "leading",
        "last leading t/ε",
        "c",
        "same contacts",
        "t/ε shift",
    ]
    return table(
        header,
        rows,
        "the reference at each scale (same contacts and t/ε shift: against the largest scale)",
        left=0,
    )


def _run_verdict(r: dict[str, Any]) -> Cell:
    """'pass' / 'fail' / 'skipped' / '-' (not assessed), coloured, the reason as tooltip."""
    if r["skipped"]:
        return Cell("skipped", "skip", r["skipped"])
    if r["passes"] is None:
        return Cell("-", "na", r.get("note") or "")
    return Cell("pass" if r["passes"] else "fail", "pass" if r["passes"] else "fail", r["c_check"])


def _fidelity_runs_table(doc: dict[str, Any]) -> str:
    rows = [
        [
            r["engine"],
            num(r["dt"], "g"),
            num(r["eps"], ".3g"),
            num(r["alpha"], ".3g"),
            r.get("status") or "-",
            "-" if r["passes"] is None else r["leading_matched"],
            r["leading"],
            num(r.get("impact_time_error_scaled"), ".2e"),
            num(r.get("energy_error"), ".2e"),
            num(r.get("c"), ".3f"),
            _run_verdict(r),
            num(r.get("wall_time_s"), ".3g"),
        ]
        for r in doc["runs"]
    ]
    header = ["engine", "dt [s]", "ε", "α [rad]", "status", "matched", "of", "t error/ε [s]",
              "E error", "c", "verdict"]  # fmt: skip
    return table([*header, "wall [s]"], rows, left=1)


# ----------------------------------------------------------------------------- sweep


def sweep_section(doc: dict[str, Any]) -> str:
    from ..sweep.grid import SweepConfig
    from ..sweep.plots import Boundaries, exponent_map_figure, sweep_label

    config = SweepConfig.from_dict(doc["manifest"])
    stats = points_frame(doc["points"], config)
    g, t = doc["grid"], doc["tasks"]
    counts = ", ".join(f"{k} {v}" for k, v in doc.get("counts", {}).items() if v)
    parts = [
        paragraph(
            f"Exponent sweep: engine {doc['engine']}, n = {doc['n']}, "
            f"{len(g['restitution'])} γ × {len(g['gyration'])} ρ × {g['samples']} runs, seed "
            f"{g['seed']}; {t['rows']} of {t['total']} runs stored; status: {counts or '-'}; "
            f"mean c over all runs {num(doc.get('mean_c'), '.3f')}."
        ),
        figure(
            exponent_map_figure(stats, config, Boundaries(config), sweep_label(config)),
            f"exponent map of the {doc['engine']} sweep",
            "Mean energy exponent c per grid point, redrawn from the per-point means.",
        ),
    ]
    rows = [
        [
            num(p["restitution"], ".3g"),
            num(p["gyration"], ".3g"),
            p["runs"],
            p["n_c"],
            num(p["mean_c"], ".3f"),
            num(p["std_c"], ".3f"),
            num(p["frac_simultaneous"], ".2f"),
        ]
        for p in doc["points"]
    ]
    header = ["γ", "ρ", "runs", "with c", "mean c", "std c", "simultaneous"]
    parts.append(details(f"every grid point ({len(rows)})", table(header, rows, left=0)))
    return "\n".join(parts)


def points_frame(points: list[dict[str, Any]], config):
    """The sweep summary's per-point rows as the statistics frame the map is drawn from
    (grid indices recovered as the nearest grid value)."""
    import numpy as np
    import pandas as pd

    gam, rho = config.gamma_values, config.rho_values
    return pd.DataFrame(
        {
            "i_restitution": [int(np.argmin(np.abs(gam - p["restitution"]))) for p in points],
            "i_gyration": [int(np.argmin(np.abs(rho - p["gyration"]))) for p in points],
            "mean_c": [np.nan if p["mean_c"] is None else p["mean_c"] for p in points],
        }
    )


def sweep_command(config) -> str:
    """The `harness sweep exponent` command that makes (or resumes) this sweep."""
    import shlex

    def g(t) -> str:
        return f"{t[0]:g}:{t[1]:g}:{t[2]}"

    args = [
        "harness", "sweep", "exponent", "--n", str(config.n), "--gyration", g(config.gyration),
        "--restitution", g(config.restitution), "--samples", str(config.samples),
        "--seed", str(config.seed), "--engine", config.engine,
    ]  # fmt: skip
    if config.dt is not None:
        args += ["--dt", f"{config.dt:g}"]
    if config.engine != "linear":
        args += ["--t-end", f"{config.t_end:g}"]
    return shlex.join([*args, "--out", "ROOT"])


# ----------------------------------------------------------------------------- stress


def stress_section(doc: dict[str, Any]) -> str:
    rows = []
    for r in doc["cases"]:
        v = r["verdict"]
        cls = {"ok": "pass", "failed": "fail"}.get(v, "skip" if v.startswith("skipped") else "")
        rows.append(
            [
                r["case"],
                r["engine"],
                Cell(v, cls, r.get("reason") or ""),
                r["status"] or "-",
                num(r["energy_gain"], ".2e"),
                num(r.get("penetration_relative"), ".2e"),
                num(r["missed_impacts"]),
                num(r["spurious_impacts"]),
                num(r.get("wall_time_s"), ".2f"),
            ]
        )
    header = [
        "case",
        "engine",
        "verdict",
        "status",
        "E gain",
        "pen/L",
        "missed",
        "spurious",
        "wall [s]",
    ]
    parts = [
        paragraph(
            f"Fixed-step engines at dt = {doc['dt']:g}, budget {doc['budget_s']:g} s per run."
        ),
        table(header, rows, "verdict per case and simulator", left=2),
    ]
    reasons = [
        f"{r['case']} / {r['engine']}: {r['verdict']}: {r['reason']}"
        for r in doc["cases"]
        if r["verdict"] != "ok" and r.get("reason")
    ]
    if reasons:
        parts.append(details(f"reasons ({len(reasons)})", "".join(paragraph(x) for x in reasons)))
    return "\n".join(parts)
