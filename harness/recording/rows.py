"""Per simulator: the 3D scene (tilt exaggerated) and the time series of the rows
(log10 α, heading ψ of the lowest point, log10 of the energy above rest), all on the
`sim_time` timeline and sent with `send_columns`.

Entities (/<sim> = one simulator):

    /<sim>/scene                    3D space (z up), heights and tilt × the exaggeration k(t)
    /<sim>/scene/ground             plane (flat) or plane + three bumps (three_point)
    /<sim>/scene/disk               Transform3D per sample (exaggerated pose)
    /<sim>/scene/disk/{outline,face,axis,vertices}   the body in its own frame, static
    /<sim>/scene/contacts           contact points whose real gap is ≤ the tolerance
    /<sim>/scene/impact             the contact point of the latest impact
    /<sim>/scene/exaggeration       label: the current tilt and height factor
    /<sim>/attitude/log10_alpha     log10 α (α in rad)
    /<sim>/attitude/heading         ψ in turns, unwrapped
    /<sim>/energy/log10_excess      log10 (E − E_rest) (E in J)
    /<sim>/energy/{kinetic,potential}  the two parts of E (J), not in the default views
    /<sim>/divergence/{log10_alpha,heading,log10_excess}   a red × on each row's curve at
                                    the run's first divergence from the reference

rerun 0.41 has no logarithmic plot axis (github.com/rerun-io/rerun/issues/6773), so the
logarithmic rows carry log10 of the value and say so in their names.
"""

from __future__ import annotations

import numpy as np
import rerun as rr

from reference.scene import Scene

from .geometry import (
    bump_positions,
    contact_points,
    exaggerated_pose,
    factor_at,
    ground_square,
    polygon_fan,
    polygon_outline,
    quaternion_xyzw,
)
from .runs import RunView, mismatch_marker

SIM_TIME = "sim_time"


def time_column(t: np.ndarray) -> rr.TimeColumn:
    """Seconds as the `sim_time` duration timeline (nanoseconds)."""
    ns = np.round(np.asarray(t, dtype=float) * 1e9).astype(np.int64)
    return rr.TimeColumn(SIM_TIME, duration=ns.astype("timedelta64[ns]"))


def shade(color: tuple[int, int, int], f: float) -> tuple[int, int, int]:
    """Blend towards white (f > 0) or black (f < 0)."""
    target = 255 if f > 0 else 0
    f = abs(f)
    return tuple(int(round((1 - f) * c + f * target)) for c in color)


def log10_positive(x: np.ndarray) -> np.ndarray:
    """log10 x where x > 0 and finite, NaN elsewhere (rerun draws a gap)."""
    x = np.asarray(x, dtype=float)
    ok = np.isfinite(x) & (x > 0)
    out = np.full(len(x), np.nan)
    out[ok] = np.log10(x[ok])
    return out


def series(
    rec: rr.RecordingStream, path: str, t: np.ndarray, values: np.ndarray, color, name: str, width
) -> None:
    """One line series: its style (static) and its values (one send_columns call)."""
    rec.log(path, rr.SeriesLines(colors=[color], names=[name], widths=[width]), static=True)
    if len(t):
        rec.send_columns(path, [time_column(t)], rr.Scalars.columns(scalars=values))


ROWS = {  # leaf → (entity under /<sim>, legend name)
    "log10_alpha": ("attitude/log10_alpha", "log10 α"),
    "heading": ("attitude/heading", "ψ (turns)"),
    "log10_excess": ("energy/log10_excess", "log10 (E − E_rest)"),
}


def row_values(run: RunView) -> dict[str, np.ndarray]:
    """The values of the rows per sample (ROWS)."""
    return {
        "log10_alpha": log10_positive(run.alpha),
        "heading": run.psi,
        "log10_excess": log10_positive(run.excess),
    }


def log_rows(rec: rr.RecordingStream, run: RunView) -> None:
    """The time series of one simulator (module docstring).  The reference's lines are
    thinner: it is drawn behind every engine as context."""
    traj = run.trajectory
    width = 1.0 if run.is_reference else 1.5
    root = f"/{run.name}"
    values = row_values(run)
    for key, (leaf, name) in ROWS.items():
        series(rec, f"{root}/{leaf}", traj.t, values[key], run.color, f"{run.label}: {name}", width)
    t_div = None if run.metrics is None else run.metrics.first_divergence_time
    if t_div is not None and traj.n_samples:
        for key, v in values.items():
            ok = np.isfinite(v)
            if not ok.any():
                continue
            path = f"{root}/divergence/{key}"
            rec.log(
                path,
                mismatch_marker(f"{run.label}: first divergence, t = {t_div:.6g} s", 6.0),
                static=True,
            )
            y = float(np.interp(t_div, traj.t[ok], v[ok]))
            rec.send_columns(path, [time_column([t_div])], rr.Scalars.columns(scalars=[y]))
    for kind, values in (("kinetic", traj.kinetic_energy), ("potential", traj.potential_energy)):
        series(
            rec, f"{root}/energy/{kind}", traj.t, np.asarray(values, float), run.color,
            f"{run.label}: {kind} energy", width,
        )  # fmt: skip


# ----------------------------------------------------------------------------- 3D


def log_scene(
    rec: rr.RecordingStream,
    run: RunView,
    scene: Scene,
    schedule: tuple[np.ndarray, np.ndarray],
    tol: float,
) -> None:
    """The 3D view of one simulator: static ground and body, then per sample the pose
    exaggerated by the schedule's factor (`exaggerated_pose`, `exaggeration_schedule`),
    the factor as a label on the ground, the touching contacts and the latest impact."""
    root = f"/{run.name}/scene"
    _log_static_scene(rec, root, scene, run.color)
    _log_factor_label(rec, root, scene, schedule)
    traj = run.trajectory
    if traj.n_samples == 0:
        return
    times = [time_column(traj.t)]
    x, q = exaggerated_pose(scene, traj.position, traj.quaternion, factor_at(schedule, traj.t))
    rec.send_columns(
        f"{root}/disk",
        indexes=times,
        columns=rr.Transform3D.columns(translation=x, quaternion=quaternion_xyzw(q)),
    )
    _, real_gaps = contact_points(scene, traj.position, traj.quaternion)
    drawn, _ = contact_points(scene, x, q)
    touching = real_gaps <= tol
    a = scene.body.radius
    rec.log(
        f"{root}/contacts",
        rr.Points3D.from_fields(radii=[0.035 * a], colors=[(255, 60, 60)]),
        static=True,
    )
    rec.send_columns(
        f"{root}/contacts",
        indexes=times,
        columns=rr.Points3D.columns(positions=drawn[touching].reshape(-1, 3)).partition(
            touching.sum(axis=1)
        ),
    )
    _log_impact_marker(rec, root, run, drawn, a)


def _log_factor_label(
    rec: rr.RecordingStream, root: str, scene: Scene, schedule: tuple[np.ndarray, np.ndarray]
) -> None:
    """'tilt, heights ×k' at the front edge of the ground, changing with the schedule."""
    a = scene.body.radius
    times, factors = schedule
    path = f"{root}/exaggeration"
    rec.log(
        path,
        rr.Points3D.from_fields(radii=[0.0], colors=[(220, 220, 220)], show_labels=True),
        static=True,
    )
    rec.send_columns(
        path,
        [time_column(times)],
        rr.Points3D.columns(
            positions=np.tile([[0.0, -1.2 * a, 0.0]], (len(times), 1)),
            labels=[f"tilt and heights ×{k:g}" for k in factors],
        ),
    )


def _log_impact_marker(
    rec: rr.RecordingStream, root: str, run: RunView, drawn: np.ndarray, a: float
) -> None:
    """A yellow ring where the latest impact was (no label: the raster numbers them)."""
    traj = run.trajectory
    rec.log(
        f"{root}/impact",
        rr.Points3D.from_fields(radii=[0.06 * a], colors=[(255, 220, 0, 200)]),
        static=True,
    )
    if not traj.impacts:
        return
    t, contact = traj.impact_times(), traj.impact_contacts()
    sample = np.clip(np.searchsorted(traj.t, t), 0, traj.n_samples - 1)
    where = drawn[sample, np.clip(contact, 0, drawn.shape[1] - 1)]
    rec.send_columns(f"{root}/impact", [time_column(t)], rr.Points3D.columns(positions=where))


def _log_static_scene(
    rec: rr.RecordingStream, root: str, scene: Scene, color: tuple[int, int, int]
) -> None:
    a = scene.body.radius
    rec.log(root, rr.ViewCoordinates.RIGHT_HAND_Z_UP, static=True)
    verts, tris = ground_square(1.25 * a)
    rec.log(
        f"{root}/ground",
        rr.Mesh3D(vertex_positions=verts, triangle_indices=tris, albedo_factor=(70, 70, 70)),
        static=True,
    )
    if len(scene.contacts.floor_points):
        r = 0.04 * a
        bumps = bump_positions(scene) - np.array([0.0, 0.0, r])  # tips at the floor points
        rec.log(
            f"{root}/ground/bumps",
            rr.Points3D(bumps, radii=[r], colors=[(200, 170, 60)]),
            static=True,
        )
    n = scene.body.n
    rec.log(
        f"{root}/disk/outline",
        rr.LineStrips3D([polygon_outline(n, a)], colors=[color], radii=[0.012 * a]),
        static=True,
    )
    fan_v, fan_t = polygon_fan(n, a)
    rec.log(
        f"{root}/disk/face",
        rr.Mesh3D(
            vertex_positions=fan_v,
            triangle_indices=fan_t,
            albedo_factor=(*shade(color, -0.35), 210),
        ),
        static=True,
    )
    rec.log(
        f"{root}/disk/axis",
        rr.Arrows3D(vectors=[[0.0, 0.0, 0.5 * a]], colors=[color], radii=[0.008 * a]),
        static=True,
    )
    labels = [str(k) for k in range(n)] if scene.contacts.has_plane and n <= 12 else None
    rec.log(
        f"{root}/disk/vertices",
        rr.Points3D(
            polygon_outline(n, a)[:-1],
            radii=[0.02 * a],
            colors=[shade(color, 0.3)],
            labels=labels,
            show_labels=labels is not None,
        ),
        static=True,
    )
