"""The recording's summary (markdown, `/summary`): the scene, how the reference ended, who
diverges first and why, one line per simulator, and how to read the views.  Short
paragraphs and bullets, so that the text view wraps them instead of cutting them off.
The sentences are `harness compare`'s (harness.compare.text)."""

from __future__ import annotations

from reference.scene import Scene

from ..compare.text import divergence_sentence, divergence_short
from .runs import RunView


def _scene_line(scene: Scene, t_max: float, t_ref: float) -> str:
    b = scene.body
    shape = "rod" if b.n == 2 else f"{b.n}-gon"
    why = " (the reference's end + 10 %)" if t_max > t_ref else ""
    return (
        f"{shape} on {scene.ground.name} ground, ρ = {b.gyration:g}, "
        f"γ = {scene.restitution:g}, g = {scene.gravity:g}; recorded to t = {t_max:.4g} s"
        f"{why}."
    )


def _reference_line(ref: RunView) -> str:
    traj = ref.trajectory
    text = (
        f"**Reference**: {traj.status.value} at t = {traj.t_final:.7g} s after "
        f"{len(traj.impacts)} impacts"
    )
    if traj.message:
        text += f": {traj.message}"
    return text + f". Energy exponent: {ref.fit.describe()}."


def _first_line(runs: list[RunView], scene: Scene) -> str:
    diverged = [r for r in runs[1:] if r.metrics and r.metrics.first_divergence_time is not None]
    if not diverged:
        if len(runs) == 1:
            return ""
        return "**No simulator diverges** from the reference in its time window."
    first = min(diverged, key=lambda r: r.metrics.first_divergence_time)
    t = first.metrics.first_divergence_time
    return (
        f"**First to diverge: {first.label}** at t = {t:.6g} s: "
        f"{divergence_sentence(first, scene)}."
    )


def _run_line(run: RunView, scene: Scene) -> str:
    m = run.metrics
    parts = [f"- **{run.label}**: {run.trajectory.status.value}"]
    if m is not None:
        parts.append(f"{m.impacts_matched}/{m.reference_impacts} impacts matched")
        when = "-" if m.first_divergence_time is None else f"t = {m.first_divergence_time:.5g} s"
        parts.append(f"diverges {when}: {divergence_short(run, scene)}")
        if m.energy_error_agreeing is not None:
            parts.append(f"energy error {m.energy_error_agreeing:.1e} while following")
    parts.append(run.fit.describe())
    return "; ".join(parts)


def summary_markdown(
    runs: list[RunView], scene: Scene, t_max: float, notes: list[str] | None = None
) -> str:
    """The summary tab; `notes`: paragraphs after the runs' lines (compare: the branch
    each run follows after the reference's undecidable state)."""
    lines = [
        f"# {scene.name}",
        "",
        _scene_line(scene, t_max, float(runs[0].trajectory.t_final)),
        "",
        _reference_line(runs[0]),
        "",
        _first_line(runs, scene),
        "",
        *[_run_line(run, scene) for run in runs],
    ]
    for note in notes or []:
        lines += ["", note]
    return "\n".join(lines)


def reading_markdown() -> str:
    """How to read the views (its own tab beside the summary, so that neither is cut)."""
    return (
        "**Reading the views.** Columns: one simulator each, the reference first; engines "
        "show the reference in grey behind them. Rows share the time axis: the body "
        "(tilt and heights exaggerated by the factor written on the ground, which grows as "
        "the motion dies down; red dots: touching contacts, yellow: the latest impact), "
        "log10 α, the heading ψ of the lowest point (turns), log10 of the energy "
        "above rest, the impacts (y = contact index, marker size growing with log impulse, the "
        "reference's faint behind an engine's, red × at the first mismatch). Right: "
        "E − E_rest and α against t_f − t on log scales; c only for runs that reach the "
        "singularity (fit window: the two light lines). v2 = vertex 2, b2 = bump 2. The "
        "rows open on the time from just before the first impact: scroll or drag to zoom, "
        "double-click to return to it."
    )
