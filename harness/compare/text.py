"""`harness compare` for the terminal: a report that fits 100 columns (one verdict line per
run and one sentence on who diverges first, when and why), or every column (`--wide`).
docs/output.md defines each column."""

from __future__ import annotations

import math
import textwrap
from typing import TYPE_CHECKING

from reference.scene import Scene
from reference.trajectory import Status

from ..metrics import RELATIVE_TIME_TOLERANCE, STEPS_TIME_TOLERANCE
from ..text import impact_law_text, table
from .branch_text import branch_lines, branch_sentence

if TYPE_CHECKING:
    from . import CompareResult, EngineRun

WIDTH = 100


# ----------------------------------------------------------------------------- numbers


def duration(x: float) -> str:
    """A time interval with a unit a person reads at once: 1.2 s, 0.73 ms, 12 µs, 3.1 ns
    (two significant digits, the unit in which the number is at least 0.1)."""
    a = abs(x)
    for scale, unit in ((1.0, "s"), (1e-3, "ms"), (1e-6, "µs"), (1e-9, "ns")):
        if a >= 0.0995 * scale:  # 0.1 s less an ulp is still 0.1 s
            return f"{x / scale:.2g} {unit}"
    return f"{x:.2g} s"


def seconds(x: float) -> str:
    """A wall time: 0.4 ms, 0.041 s, 6.5 s, 13 s, 750 s."""
    if x < 1e-3:
        return f"{x * 1e3:.2g} ms"
    return f"{x:.2g} s" if x < 10 else f"{x:.0f} s"


def _num(x: float | None, fmt: str = ".1e") -> str:
    return "-" if x is None or not math.isfinite(x) else format(x, fmt)


def contact_name(scene: Scene, k: int | None) -> str:
    """'v2' (rim vertex 2) or 'b2' (floor point 2): `GroundContacts.label`."""
    if k is None:
        return "?"
    return scene.contacts.label(int(k))


def impacts_cell(m) -> str:
    """'22/59' (matched of the reference's), '35+86/302' when 86 chatter-tail bounces of
    the reference were skipped on the way (not compared one by one)."""
    skipped = f"+{m.skipped_reference}" if m.skipped_reference else ""
    return f"{m.impacts_matched}{skipped}/{m.reference_impacts}"


def _exponent_cell(fit) -> str:
    if fit is None or fit.c is None:
        return "-"
    return f"{fit.c:.2f}±{fit.c_stderr:.1g}"


def _count_range(q: list[float]) -> str:
    """'15–22' from [10 %, 50 %, 90 %] quantiles of matched counts ('15' when equal)."""
    lo, hi = f"{q[0]:.0f}", f"{q[2]:.0f}"
    return lo if lo == hi else f"{lo}–{hi}"


def horizon_cell(run: EngineRun) -> str:
    """The table's `band`: level (a)'s 10–90 % range and whether the run's count is
    within it ('15–22 in', '15–22 low'); event-driven runs: level (b)'s range after 'b '."""
    h = run.horizon
    if h is None:
        return "-"
    if h.matched_quantiles is not None:
        return f"{_count_range(h.matched_quantiles)} {'in' if h.within else 'low'}"
    if h.own_error_quantiles is not None:
        return f"b {_count_range(h.own_error_quantiles)}"
    return "-"


def _horizon_wide(run: EngineRun) -> list[str]:
    """band(a) with the verdict, own error, band(b): the wide table's horizon cells."""
    h = run.horizon
    if h is None:
        return ["-", "-", "-"]
    a = "-" if h.matched_quantiles is None else horizon_cell(run)
    b = "-" if h.own_error_quantiles is None else _count_range(h.own_error_quantiles)
    return [a, _num(h.own_error), b]


def horizon_sentence(run: EngineRun) -> str | None:
    """The run's horizon verdict as a sentence with the numbers (None without one)."""
    h = run.horizon
    if h is None:
        return None
    m = run.metrics
    parts = [f"{run.label} matches {m.impacts_matched}"]
    if h.matched_quantiles is not None:
        verdict = (
            "within it: the divergence is the scene's chaos at this timestep"
            if h.within
            else "below it: look at the contact model"
        )
        parts.append(
            f"the exact model with its impacts on a {run.dt:g} s step grid matches "
            f"{_count_range(h.matched_quantiles)} (10–90 %, {h.runs} grid phases), {verdict}"
        )
    if h.own_error_quantiles is not None:
        parts.append(
            f"its own error after impact {h.own_error_impact} ({h.own_error:.1e}) lets the "
            f"perturbed exact model match {_count_range(h.own_error_quantiles)}"
        )
    elif h.own_error is None:
        parts.append("its own error could not be measured (no matched impact with a flight after)")
    return "; ".join(parts) + "."


# ----------------------------------------------------------------------------- why


def divergence_short(run: EngineRun, scene: Scene) -> str:
    """Why a run left the reference, in at most ~30 characters."""
    m = run.metrics
    if run.trajectory.status in (Status.FAILED, Status.STALLED):
        return f"{run.trajectory.status.value} (message below)"
    if m.first_divergence_time is None:
        return "no common time window" if m.common_window is None else "none"
    if m.divergence_kind == "attitude":
        return f"attitude off > {m.attitude_threshold:.1g} rad"
    x = m.first_mismatch
    c_ref, c_run = contact_name(scene, x.contact_ref), contact_name(scene, x.contact_run)
    if x.kind == "time":
        late = "late" if x.time_offset > 0 else "early"
        return f"impact {x.ref_index} ({c_ref}) {duration(abs(x.time_offset))} {late}"
    if x.kind == "contact":
        return f"impact {x.ref_index}: {c_run} hit, not {c_ref}"
    if x.kind == "missed":
        return f"impact {x.ref_index} ({c_ref}) missed"
    return f"extra impact at {c_run}"


def divergence_sentence(run: EngineRun, scene: Scene) -> str:
    """Why a run left the reference, as a sentence with the numbers."""
    m = run.metrics
    if m.first_divergence_time is None:
        return "it does not diverge"
    if m.divergence_kind == "attitude":
        return (
            f"its attitude is more than {m.attitude_threshold:.2g} rad (a tenth of the "
            "reference's largest tilt) away from the reference's"
        )
    x = m.first_mismatch
    c_ref, c_run = contact_name(scene, x.contact_ref), contact_name(scene, x.contact_run)
    if x.kind == "time":
        late = "after" if x.time_offset > 0 else "before"
        return (
            f"its impact at {c_ref} came {duration(abs(x.time_offset))} {late} the "
            f"reference's impact {x.ref_index} (t = {x.t_ref:.7g} s), outside the "
            f"±{duration(x.window)} window"
        )
    if x.kind == "contact":
        return (
            f"at the reference's impact {x.ref_index} (t = {x.t_ref:.7g} s, {c_ref}) it hit "
            f"{c_run} instead (t = {x.t_run:.7g} s)"
        )
    if x.kind == "missed":
        return (
            f"it has no impact where the reference's impact {x.ref_index} hits {c_ref} "
            f"(t = {x.t_ref:.7g} s)"
        )
    return f"it hits {c_run} at t = {x.t_run:.7g} s, where the reference has no impact"


def verdict_line(run: EngineRun, scene: Scene) -> str:
    """One line per run for JSON readers: matched k/N, divergence, energy error, cost."""
    m = run.metrics
    when = (
        "follows the reference throughout"
        if m.first_divergence_time is None
        else f"diverges at t = {m.first_divergence_time:.6g} s: {divergence_sentence(run, scene)}"
    )
    e = m.energy_error_agreeing
    return (
        f"{run.label}: {m.impacts_matched}/{m.reference_impacts} impacts matched; {when}; "
        f"energy error {_num(e, '.2e')} while following; {seconds(run.wall_time_s)}"
    )


# ----------------------------------------------------------------------------- report


def _header(result: CompareResult) -> list[str]:
    scene, ref = result.scene, result.reference
    body = scene.body
    shape = "rod" if body.n == 2 else f"{body.n}-gon"
    head = (
        f"{scene.name}: {shape} on {scene.ground.name} ground, "
        f"ρ = {body.gyration:g}, γ = {scene.restitution:g}, g = {scene.gravity:g}"
    )
    law = f"impact law: {impact_law_text(ref.impact_law or 'paper', ref.simultaneity_window)}"
    text = (
        f"reference: {ref.status.value} at t = {ref.t_final:.7g} s after {len(ref.impacts)} "
        f"impacts (wall time {seconds(result.reference_wall_time_s)})"
    )
    if ref.message and ref.status is not Status.T_END:
        text += f": {ref.message}"
    fit = result.reference_exponent
    if fit is not None and fit.c is not None:
        text += f"; energy exponent {fit.describe()}"
    return [head, law, *textwrap.wrap(text, WIDTH, subsequent_indent="  ")]


def _reference_counts(result: CompareResult) -> list[int]:
    return sorted({run.metrics.reference_impacts for run in result.runs})


def _verdict_table(result: CompareResult) -> str:
    """One row per run: how many of the reference's impacts it reproduces, when and why
    it leaves them, its energy error while it follows and its wall time.  Columns that
    are empty on every row (no chatter tail skipped, no exponent) are left out; when
    every run is measured against the same number of reference impacts, the sentence
    above the table gives it and the `of` column is left out too."""
    rows = []
    for run in result.runs:
        m = run.metrics
        t_div = m.first_divergence_time
        rows.append(
            [
                run.label,
                str(m.impacts_matched),
                str(m.skipped_reference),
                str(m.reference_impacts),
                "-" if t_div is None else f"{t_div:.5g}",
                divergence_short(run, result.scene),
                _num(m.energy_error_agreeing),
                _exponent_cell(run.exponent),
                f"{run.wall_time_s:.2g}",
            ]
        )
    header = ["simulator", "matched", "skipped", "of", "diverges at [s]",
              "first disagreement", "E error", "c", "wall [s]"]  # fmt: skip
    align = "lrrrrlrrr"
    drop = {2} if all(r[2] == "0" for r in rows) else set()
    drop |= {7} if all(r[7] == "-" for r in rows) else set()
    drop |= {3} if len(_reference_counts(result)) == 1 else set()
    # when the table is wider than WIDTH (long engine names beside an exponent): the wall
    # time left out, then the exponent, each with a note (--wide has every column)
    attempts = (
        (set(), ""),
        ({8}, "\n(wall time left out to stay within 100 columns: --wide has it)"),
        ({8, 7}, "\n(wall time and c left out to stay within 100 columns: --wide has them)"),
    )
    for extra, note in attempts:
        keep = [i for i in range(len(header)) if i not in drop | extra]
        text = table(
            [[r[i] for i in keep] for r in rows],
            [header[i] for i in keep],
            align="".join(align[i] for i in keep),
        )
        if max(len(line) for line in text.splitlines()) <= WIDTH:
            return text + note
    return text + note


def _table_intro(result: CompareResult) -> str:
    counts = _reference_counts(result)
    of = f"the reference's {counts[0]} impacts" if len(counts) == 1 else "the reference's impacts"
    return f"Each run against {of} in the time both cover:"


def _horizon_table(result: CompareResult) -> list[str]:
    """The horizon of each run as numbers: impacts the exact model matches (10–90 % of
    its runs) with its impacts on the run's step grid, whether the run's count reaches
    that band's 10 % value, the run's own state error and what the exact model
    perturbed at that error matches."""
    rows, runs = [], 0
    for run in result.runs:
        h = run.horizon
        if h is None:
            continue
        runs = max(runs, h.runs)
        grid = h.matched_quantiles
        own = h.own_error_quantiles
        rows.append(
            [
                run.label,
                str(h.matched),
                "-" if grid is None else _count_range(grid),
                "-" if h.within is None else ("yes" if h.within else "no"),
                _num(h.own_error),
                "-" if own is None else _count_range(own),
            ]
        )
    if not rows:
        return []
    header = ["simulator", "matched", "on step grid", "within", "own error", "at own error"]
    keep = [i for i in range(len(header)) if i < 2 or any(r[i] != "-" for r in rows)]
    intro = (
        "Impacts the exact model itself matches (10–90 % of "
        f"{runs} runs), with its impacts on the run's step grid and perturbed by the run's "
        "own state error after its first matched impact:"
    )
    return [
        *textwrap.wrap(intro, WIDTH),
        table(
            [[r[i] for i in keep] for r in rows],
            [header[i] for i in keep],
            align="".join("lrrlrr"[i] for i in keep),
        ),
    ]


def _first_to_diverge(result: CompareResult) -> list[str]:
    first = result.first_to_diverge()
    if first is None:
        return ["No simulator diverges from the reference inside its time window."]
    t = first.metrics.first_divergence_time
    text = (
        f"First to diverge: {first.label} at t = {t:.6g} s: "
        f"{divergence_sentence(first, result.scene)}."
    )
    return textwrap.wrap(text, WIDTH, subsequent_indent="  ") + _horizon_lines(result)


def _horizon_lines(result: CompareResult) -> list[str]:
    """One sentence per run with a horizon, and the scene's growth per impact."""
    sentences = [s for s in (horizon_sentence(r) for r in result.runs) if s]
    if not sentences:
        return []
    rate = next(r.horizon.lyapunov_per_impact for r in result.runs if r.horizon is not None)
    head = "Horizon: a separation grows by e^λ per impact, λ = " + (
        "-" if rate is None else f"{rate:.3g}"
    )
    lines = textwrap.wrap(head + " (perturbed exact model, docs/fidelity.md).", WIDTH)
    lines += _horizon_table(result)
    for run in result.runs:
        text = horizon_verdict(run)
        if text:
            lines += textwrap.wrap(text, WIDTH, initial_indent="  ", subsequent_indent="    ")
    return lines


def horizon_verdict(run: EngineRun) -> str | None:
    """'mujoco 1e-04 matches 22 impacts, at least the 10 (10 %) the exact model matches
    on its step grid: ...' (None without the step-grid band)."""
    h = run.horizon
    if h is None or h.matched_quantiles is None:
        return None
    low = f"{h.matched_quantiles[0]:.0f}"
    if h.within:
        return (
            f"{run.label} matches {h.matched} impacts, at least the {low} that 90 % of the "
            "exact model's runs on its step grid match: its divergence is the scene's chaos "
            "at this timestep."
        )
    return (
        f"{run.label} matches {h.matched} impacts, fewer than the {low} that 90 % of the "
        "exact model's runs on its step grid match: its contact model loses impacts the "
        "timestep alone would keep."
    )


def legend(result: CompareResult) -> str:
    """What the verdict table's columns mean, for the columns it shows."""
    parts = [
        "simulator: the engine and its timestep dt in s. matched: leading reference impacts "
        "the run reproduces (same contact, time within "
        f"{STEPS_TIME_TOLERANCE:g}·dt + {RELATIVE_TIME_TOLERANCE:g}·t)."
    ]
    if any(run.metrics.skipped_reference for run in result.runs):
        parts.append("skipped: slow chatter-tail bounces of the reference passed over on the way.")
    parts.append("E error: max|E − E_ref|/E_ref(0) while the run follows the reference.")
    if any(run.exponent is not None and run.exponent.c is not None for run in result.runs):
        parts.append("c: energy exponent ± its standard error (runs that reach the singularity).")
    parts.append(
        "v2 = rim vertex 2, b2 = bump 2. Every column: --wide; definitions: docs/output.md."
    )
    return " ".join(parts)


def _failures(result: CompareResult) -> list[str]:
    lines = []
    for run in result.runs:
        status = run.trajectory.status
        if status in (Status.FAILED, Status.STALLED) and run.trajectory.message:
            lines += textwrap.wrap(
                f"{run.label} {status.value}: {run.trajectory.message}",
                WIDTH,
                subsequent_indent="  ",
            )
    return lines


def format_compare(result: CompareResult, wide: bool = False) -> str:
    """The report: scene and reference, one verdict row per run, who diverges first and
    why, a short legend.  `wide`: every column instead (wider than 100 characters)."""
    if wide:
        return format_compare_wide(result)
    lines = [*_header(result), "", _table_intro(result), _verdict_table(result), ""]
    lines += _first_to_diverge(result)
    lines += _failures(result)
    branches = branch_lines(result)
    if branches:
        lines += ["", *branches]
    lines += ["", *textwrap.wrap(legend(result), WIDTH)]
    return "\n".join(lines)


def format_compare_wide(result: CompareResult) -> str:
    """Every column of every run, and every rule behind them."""
    header = [
        "engine",
        "dt",
        "status",
        "wall[s]",
        "impacts",
        "matched",
        "tails",
        "t_err[s]",
        "E_err",
        "E_err<div",
        "att_err[rad]",
        "att<div",
        "diverge[s]",
        "why",
        "e_eff",
        "c",
        "t_f from",
        "band(a)",
        "own_err",
        "band(b)",
    ]
    rows = []
    for run in result.runs:
        m = run.metrics
        r = m.restitution
        fit = run.exponent
        rows.append(
            [
                run.engine,
                "-" if run.dt is None else f"{run.dt:g}",
                run.trajectory.status.value,
                f"{run.wall_time_s:.2f}",
                str(m.impacts),
                f"{m.impacts_matched}/{m.reference_impacts}",
                f"{m.skipped_reference}/{m.skipped_run}",
                _num(m.impact_time_error, ".2e"),
                _num(m.energy_error, ".2e"),
                _num(m.energy_error_agreeing, ".2e"),
                _num(m.attitude_error, ".2e"),
                _num(m.attitude_error_agreeing, ".2e"),
                _num(m.first_divergence_time, ".6g"),
                divergence_short(run, result.scene),
                "-" if r.median is None else f"{r.median:.4f} (n={r.n})",
                _exponent_cell(fit),
                fit.t_f_source or "-",
                *_horizon_wide(run),
            ]
        )
    lines = [*_header(result), "", table(rows, header, align="lrlrrrrrrrrrrlrrllrl"), ""]
    lines += [
        "matched: leading impacts with the reference's contact and time, |dt| <= "
        f"{STEPS_TIME_TOLERANCE:g} steps (1e-9 s event-driven) + {RELATIVE_TIME_TOLERANCE:g}*t, "
        "capped at half the gap to the next same-contact reference impact; of the reference "
        "impacts in the common window",
        "tails: chatter-tail impacts skipped (reference/run): approach slower than "
        "max(10 g dt, 1% of the fastest), at a contact already in the chatter episode",
        "E_err: max |E - E_ref|/E_ref(0) away from impacts; att_err: max attitude angle; "
        "<div: the same before the first divergence",
        "diverge: first impact mismatch or attitude error > 0.1 x max reference tilt; "
        "e_eff: median -v_post/v_pre of the run's impacts approaching faster than "
        "max(10 g dt, 1% of the fastest)",
        "c: energy exponent of E ~ a (t_f - t)^c ± standard error (reference.exponent), only "
        "for runs that reach the singularity; t_f from: where t_f came from",
        "band(a): 10-90 % of the impacts matched by the exact model with impacts on the run's "
        "step grid (in: count >= 10 %); own_err: the run's state error after its first matched "
        "impact; band(b): 10-90 % matched by the exact model perturbed at that error",
    ]
    for run in result.runs:
        m = run.metrics
        if m.divergence_reason:
            lines.append(f"  {run.label}: {m.divergence_reason}")
        if run.exponent.c is None and run.exponent.reason:
            lines.append(f"  {run.label}: no c: {run.exponent.reason}")
        if run.branch is not None:
            lines.append(f"  after t_u: {branch_sentence(run)}")
    lines += _failures(result)
    return "\n".join(lines)
