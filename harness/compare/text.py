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
from ..text import WIDTH, column_tables, fit_table, impact_law_text, num, quantile_cells, table
from .branch_text import branch_lines, branch_sentence

if TYPE_CHECKING:
    from . import CompareResult, EngineRun


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


def _count_range(q: list[float]) -> str:
    """'15–22' from [10 %, 50 %, 90 %] quantiles of matched counts ('15' when equal):
    the sentences' range (the tables give the 10 % and 90 % values in two columns)."""
    lo, hi = f"{q[0]:.0f}", f"{q[2]:.0f}"
    return lo if lo == hi else f"{lo}–{hi}"


def _horizon_wide(run: EngineRun) -> list[str]:
    """The wide table's horizon cells: the grid model's 10 % and 90 % matched, within,
    the run's own error, the perturbed model's 10 % and 90 % matched."""
    h = run.horizon
    if h is None:
        return ["-"] * 6
    return [*quantile_cells(h.matched_quantiles), num(h.within), _num(h.own_error),
            *quantile_cells(h.own_error_quantiles)]  # fmt: skip


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
    it leaves them, its energy error while it follows, its energy exponent and its
    standard error, and its wall time.  Columns that are empty on every row (no chatter
    tail skipped, no exponent) are left out; when every run is measured against the same
    number of reference impacts, the sentence above the table gives it and the `of`
    column is left out too."""
    rows = []
    for run in result.runs:
        m, fit = run.metrics, run.exponent
        t_div = m.first_divergence_time
        has_c = fit is not None and fit.c is not None
        rows.append(
            [
                run.label,
                str(m.impacts_matched),
                str(m.skipped_reference),
                str(m.reference_impacts),
                "-" if t_div is None else f"{t_div:.5g}",
                divergence_short(run, result.scene),
                _num(m.energy_error_agreeing),
                f"{fit.c:.2f}" if has_c else "-",
                _num(fit.c_stderr, ".1g") if has_c else "-",
                f"{run.wall_time_s:.2g}",
            ]
        )
    header = ["simulator", "matched", "skipped", "of", "diverges at [s]",
              "first disagreement", "E error", "c", "c stderr", "wall [s]"]  # fmt: skip
    align = "lrrrrlrrrr"
    drop = {2} if all(r[2] == "0" for r in rows) else set()
    drop |= {7, 8} if all(r[7] == "-" for r in rows) else set()
    drop |= {3} if len(_reference_counts(result)) == 1 else set()
    # wider than WIDTH with the simulators' names broken over lines (fit_table): the wall
    # time left out, then the exponent, each with a note (--wide has every column)
    attempts = (
        (set(), ""),
        ({9}, "\n(wall time left out to stay within 100 columns: --wide has it)"),
        ({9, 7, 8}, "\n(wall time and c left out to stay within 100 columns: --wide has them)"),
    )
    for extra, note in attempts:
        keep = [i for i in range(len(header)) if i not in drop | extra]
        text = fit_table(
            [[r[i] for i in keep] for r in rows],
            [header[i] for i in keep],
            "".join(align[i] for i in keep),
            WIDTH,
        )
        if max(len(line) for line in text.splitlines()) <= WIDTH:
            return text + note
    return text + note


def _table_intro(result: CompareResult) -> str:
    counts = _reference_counts(result)
    of = f"the reference's {counts[0]} impacts" if len(counts) == 1 else "the reference's impacts"
    return f"Each run against {of} in the time both cover:"


def _horizon_table(result: CompareResult) -> list[str]:
    """The horizon of each run as numbers: the impacts the exact model matches (the 10 %
    and 90 % quantiles of its runs) with its impacts on the run's step grid, whether the
    run's count reaches that 10 % value, the run's own state error and what the exact
    model perturbed at that error matches."""
    rows, runs = [], 0
    for run in result.runs:
        h = run.horizon
        if h is None:
            continue
        runs = max(runs, h.runs)
        rows.append([run.label, str(h.matched), *_horizon_wide(run)])
    if not rows:
        return []
    header = ["simulator", "matched", "grid 10 %", "grid 90 %", "within", "own error",
              "own 10 %", "own 90 %"]  # fmt: skip
    keep = [i for i in range(len(header)) if i < 2 or any(r[i] != "-" for r in rows)]
    intro = (
        f"Impacts the exact model itself matches over {runs} runs (10 % and 90 % quantiles), "
        "with its impacts on the run's step grid (grid) and perturbed by the run's own "
        "state error after its first matched impact (own); within: the run matches at "
        "least grid 10 %:"
    )
    rows = [[r[i] for i in keep] for r in rows]
    header = [header[i] for i in keep]
    text = table(rows, header, align="".join("lrrrlrrr"[i] for i in keep))
    if max(len(line) for line in text.splitlines()) > WIDTH:  # long engine names
        columns = [(h, [r[j] for r in rows]) for j, h in enumerate(header[2:], 2)]
        text = "\n".join(column_tables(header[:2], [r[:2] for r in rows], columns, "lr"))
    return [*textwrap.wrap(intro, WIDTH), text]


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
        parts.append(
            "c: energy exponent, c stderr: its standard error (runs that reach the singularity)."
        )
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


WIDE_HEADER = ["engine", "dt [s]", "status", "wall [s]", "impacts", "matched", "of",
               "ref skipped", "run skipped", "t error [s]", "E error window",
               "E error following", "attitude window [rad]", "attitude following [rad]",
               "diverges at [s]", "why", "e_eff", "e_eff impacts", "c", "c stderr", "t_f from",
               "grid 10 %", "grid 90 %", "within", "own error", "own 10 %", "own 90 %"]  # fmt: skip
WIDE_ALIGN = "lrlrrrrrrrrrrrrlrrrrlrrlrrr"
WIDE_NOTES = (
    "matched: leading impacts with the reference's contact and time, |dt| <= "
    f"{STEPS_TIME_TOLERANCE:g} steps (1e-9 s event-driven) + {RELATIVE_TIME_TOLERANCE:g}*t, "
    "capped at half the gap to the next same-contact reference impact; of: the reference "
    "impacts in the common window.",
    "ref skipped, run skipped: chatter-tail impacts of the reference and of the run passed "
    "over (approach slower than max(10 g dt, 1% of the fastest), at a contact already in "
    "the chatter episode).",
    "E error: max |E - E_ref|/E_ref(0) away from impacts; attitude: the largest angle "
    "between the attitudes; window: over the common window; following: before the first "
    "divergence (the default table's E error).",
    "diverges at: the first impact mismatch or attitude error > 0.1 x max reference tilt. "
    "e_eff: median -v_post/v_pre of the e_eff impacts, the run's impacts approaching "
    "faster than max(10 g dt, 1% of the fastest).",
    "c: energy exponent of E ~ a (t_f - t)^c and its standard error (reference.exponent), "
    "only for runs that reach the singularity; t_f from: where t_f came from.",
    "grid 10 %, 90 %: quantiles of the impacts matched by the exact model with its impacts "
    "on the run's step grid; within: matched >= grid 10 %; own error: the run's state error "
    "after its first matched impact; own 10 %, 90 %: matched by the exact model perturbed "
    "at that error.",
)


def _wide_row(run: EngineRun, scene: Scene) -> list[str]:
    m, r, fit = run.metrics, run.metrics.restitution, run.exponent
    has_c = fit is not None and fit.c is not None
    return [
        run.engine,
        "-" if run.dt is None else f"{run.dt:g}",
        run.trajectory.status.value,
        f"{run.wall_time_s:.2f}",
        str(m.impacts),
        str(m.impacts_matched),
        str(m.reference_impacts),
        str(m.skipped_reference),
        str(m.skipped_run),
        _num(m.impact_time_error, ".2e"),
        _num(m.energy_error, ".2e"),
        _num(m.energy_error_agreeing, ".2e"),
        _num(m.attitude_error, ".2e"),
        _num(m.attitude_error_agreeing, ".2e"),
        _num(m.first_divergence_time, ".6g"),
        divergence_short(run, scene),
        "-" if r.median is None else f"{r.median:.4f}",
        str(r.n),
        f"{fit.c:.3f}" if has_c else "-",
        _num(fit.c_stderr, ".1g") if has_c else "-",
        (fit.t_f_source if fit is not None else None) or "-",
        *_horizon_wide(run),
    ]


def format_compare_wide(result: CompareResult) -> str:
    """Every column of every run, and every rule behind them."""
    rows = [_wide_row(run, result.scene) for run in result.runs]
    lines = [*_header(result), "", table(rows, WIDE_HEADER, align=WIDE_ALIGN), ""]
    for note in WIDE_NOTES:
        lines += textwrap.wrap(note, WIDTH, subsequent_indent="  ")
    for run in result.runs:
        m = run.metrics
        if m.first_divergence_time is not None:
            text = f"{run.label}: {divergence_sentence(run, result.scene)}"
            lines += textwrap.wrap(text, WIDTH, initial_indent="  ", subsequent_indent="    ")
        if run.exponent.c is None and run.exponent.reason:
            lines.append(f"  {run.label}: no c: {run.exponent.reason}")
        if run.branch is not None:
            text = f"after t_u: {branch_sentence(run)}"
            lines += textwrap.wrap(text, WIDTH, initial_indent="  ", subsequent_indent="    ")
    lines += _failures(result)
    return "\n".join(lines)
