"""Rerun recordings (`--record FILE.rrd`): simulators side by side, written offline.

One `.rrd` file, one entity subtree per simulator (`/reference`, `/mujoco_dt1e-04`, ...):

    /<sim>/scene                    3D space (z up): ground, posed disk, contact points
    /<sim>/scene/ground             plane (flat) or plane + three bumps (three_point), static
    /<sim>/scene/disk               Transform3D per sample (translation, quaternion x,y,z,w)
    /<sim>/scene/disk/{outline,face,axis,vertices}   the body in its own frame, static
    /<sim>/scene/contacts           contact points whose gap is ≤ `contact_tolerance`
    /<sim>/scene/impact             the contact point of the latest impact
    /<sim>/inclination              α (rad)
    /<sim>/energy/{kinetic,potential,total}
    /<sim>/impacts/{impulse,contact}   one marker per impact; /<sim>/impacts/log: TextLog
    /<sim>/singularity/{log10_time_to_go,log10_energy}   values, exact near t_f
    /<sim>/info                     run summary (markdown)
    /compare/loglog/...             the paper's log-log plot (2D, y = −log10 E), fits
    /compare/summary                table of runs and fitted exponents

Everything temporal is on the duration timeline `sim_time` and sent with
`send_columns` (one call per entity).  The blueprint is embedded with
`RecordingStream.save(path, default_blueprint=...)`.  No global recording is created.
"""

from __future__ import annotations

import math
import os
import re
import uuid
from pathlib import Path

import numpy as np
import rerun as rr
import rerun.blueprint as rrb

from reference.scene import Scene
from reference.trajectory import Trajectory

from ..outputs import atomic_write
from .geometry import (
    bump_positions,
    contact_points,
    ground_square,
    inclinations,
    polygon_fan,
    polygon_outline,
    quaternion_xyzw,
)
from .loglog import (
    ExponentFit,
    SingularityTime,
    fit_exponent,
    loglog_mask,
    singularity_time,
    time_to_go,
)

APPLICATION_ID = "euler_disk_harness"
SIM_TIME = "sim_time"
DEFAULT_FOLDER = Path("recordings")
LOGLOG = "/compare/loglog"
SUMMARY = "/compare/summary"

# first colour (light grey) is the reference's; then the tab10 palette
PALETTE = [
    (230, 230, 230),
    (31, 119, 180),
    (255, 127, 14),
    (44, 160, 44),
    (214, 39, 40),
    (148, 103, 189),
    (140, 86, 75),
    (227, 119, 194),
    (188, 189, 34),
    (23, 190, 207),
]


# ----------------------------------------------------------------------------- names


def recording_path(path: str | Path) -> Path:
    """Where to write: a bare file name (no folder, not even ./) goes under recordings/.
    Folders are created when the recording is written (harness.outputs.atomic_write)."""
    p = Path(path)
    if "/" not in str(path) and os.sep not in str(path):
        p = DEFAULT_FOLDER / p
    return p


def entity_names(trajs: list[Trajectory]) -> list[str]:
    """One unique entity-path part per trajectory: engine name, `_dt<dt>` for fixed-step
    runs, `_2`, `_3`, ... when still repeated; characters outside [A-Za-z0-9_-] become `_`."""
    names: list[str] = []
    for traj in trajs:
        base = re.sub(r"[^A-Za-z0-9_\-]", "_", traj.engine) or "simulator"
        if traj.dt is not None:
            base += f"_dt{traj.dt:.0e}"
        name, k = base, 2
        while name in names or name == "compare":
            name, k = f"{base}_{k}", k + 1
        names.append(name)
    return names


def _shade(color: tuple[int, int, int], f: float) -> tuple[int, int, int]:
    """Blend towards white (f > 0) or black (f < 0)."""
    target = 255 if f > 0 else 0
    f = abs(f)
    return tuple(int(round((1 - f) * c + f * target)) for c in color)


def _time_column(t: np.ndarray) -> rr.TimeColumn:
    ns = np.round(np.asarray(t, dtype=float) * 1e9).astype(np.int64)
    return rr.TimeColumn(SIM_TIME, duration=ns.astype("timedelta64[ns]"))


def _fmt(x: float | None) -> str:
    return "–" if x is None else f"{x:.10g}"


# ----------------------------------------------------------------------------- entry point


def record_trajectories(
    trajs: list[Trajectory],
    path: str | Path,
    scene: Scene,
    contact_tolerance: float | None = None,
    force: bool = False,
) -> Path:
    """Write one `.rrd` with the trajectories side by side; the first is the reference
    (its t_singularity, else its last impact, is t_f of the log-log plot).

    `contact_tolerance`: gap below which a contact point is drawn as touching
    (default 1e-6 × body radius).  Returns the path written."""
    if not trajs:
        raise ValueError("record_trajectories needs at least one trajectory")
    out = recording_path(path)
    names = entity_names(trajs)
    colors = {name: PALETTE[i % len(PALETTE)] for i, name in enumerate(names)}
    tol = 1e-6 * scene.body.radius if contact_tolerance is None else contact_tolerance

    t_f = singularity_time(trajs[0])
    loglog = {name: _loglog_data(traj, t_f) for name, traj in zip(names, trajs, strict=True)}
    bounds = _loglog_bounds(loglog)
    blueprint = build_blueprint(names, bounds, radius=scene.body.radius)

    rec = rr.RecordingStream(APPLICATION_ID, recording_id=uuid.uuid4())
    if not rr.is_enabled(rec):
        raise RuntimeError("rerun logging is disabled (RERUN=off?): no recording written")
    with atomic_write(out, force) as tmp:
        rec.save(tmp, default_blueprint=blueprint)
        try:
            rec.send_recording_name(f"{scene.name}: {', '.join(names)}")
            for name, traj in zip(names, trajs, strict=True):
                _log_simulator(rec, name, traj, scene, colors[name], tol)
                _log_singularity_values(rec, name, loglog[name], colors[name])
                _log_info(rec, name, traj, loglog[name], t_f)
            _log_loglog_plot(rec, names, loglog, colors, bounds)
            _log_summary(rec, scene, names, trajs, loglog, t_f)
        finally:
            rec.flush()
            rec.disconnect()  # closes the file sink: footer and manifest are written
    return out


# ----------------------------------------------------------------------------- per simulator


def _log_simulator(
    rec: rr.RecordingStream,
    name: str,
    traj: Trajectory,
    scene: Scene,
    color: tuple[int, int, int],
    tol: float,
) -> None:
    root = f"/{name}"
    _log_static_scene(rec, root, scene, color)
    if traj.n_samples == 0:
        return
    times = [_time_column(traj.t)]

    rec.send_columns(
        f"{root}/scene/disk",
        indexes=times,
        columns=rr.Transform3D.columns(
            translation=np.asarray(traj.position, dtype=float),
            quaternion=quaternion_xyzw(traj.quaternion),
        ),
    )

    pts, gaps = contact_points(scene, traj.position, traj.quaternion)
    touching = gaps <= tol
    rec.log(
        f"{root}/scene/contacts",
        rr.Points3D.from_fields(radii=[0.03 * scene.body.radius], colors=[(255, 60, 60)]),
        static=True,
    )
    rec.send_columns(
        f"{root}/scene/contacts",
        indexes=times,
        columns=rr.Points3D.columns(positions=pts[touching].reshape(-1, 3)).partition(
            touching.sum(axis=1)
        ),
    )

    rec.log(
        f"{root}/inclination",
        rr.SeriesLines(colors=[color], names=[f"{name} α"]),
        static=True,
    )
    rec.send_columns(
        f"{root}/inclination",
        indexes=times,
        columns=rr.Scalars.columns(scalars=inclinations(traj.quaternion)),
    )

    energies = {
        "kinetic": (traj.kinetic_energy, _shade(color, -0.45)),
        "potential": (traj.potential_energy, _shade(color, 0.45)),
        "total": (traj.energy, color),
    }
    for kind, (values, c) in energies.items():
        rec.log(
            f"{root}/energy/{kind}",
            rr.SeriesLines(colors=[c], names=[f"{name} {kind}"]),
            static=True,
        )
        rec.send_columns(
            f"{root}/energy/{kind}",
            indexes=times,
            columns=rr.Scalars.columns(scalars=np.asarray(values, dtype=float)),
        )

    _log_impacts(rec, name, traj, pts, color, scene)


def _log_static_scene(
    rec: rr.RecordingStream, root: str, scene: Scene, color: tuple[int, int, int]
) -> None:
    a = scene.body.radius
    rec.log(f"{root}/scene", rr.ViewCoordinates.RIGHT_HAND_Z_UP, static=True)
    verts, tris = ground_square(1.6 * a)
    rec.log(
        f"{root}/scene/ground",
        rr.Mesh3D(vertex_positions=verts, triangle_indices=tris, albedo_factor=(90, 90, 90)),
        static=True,
    )
    if scene.ground.kind == "three_point":
        r = 0.04 * a
        bumps = bump_positions(scene) - np.array([0.0, 0.0, r])  # tips at z = 0
        rec.log(
            f"{root}/scene/ground/bumps",
            rr.Points3D(
                bumps,
                radii=[r],
                colors=[(200, 170, 60)],
                labels=[f"bump {k}" for k in range(3)],
            ),
            static=True,
        )
    n = scene.body.n
    rec.log(
        f"{root}/scene/disk/outline",
        rr.LineStrips3D([polygon_outline(n, a)], colors=[color], radii=[0.01 * a]),
        static=True,
    )
    fan_v, fan_t = polygon_fan(n, a)
    rec.log(
        f"{root}/scene/disk/face",
        rr.Mesh3D(
            vertex_positions=fan_v,
            triangle_indices=fan_t,
            albedo_factor=(*_shade(color, -0.6), 160),
        ),
        static=True,
    )
    rec.log(
        f"{root}/scene/disk/axis",
        rr.Arrows3D(vectors=[[0.0, 0.0, 0.6 * a]], colors=[color], labels=["e3"]),
        static=True,
    )
    labels = [str(k) for k in range(n)] if scene.ground.kind == "flat" else None
    rec.log(
        f"{root}/scene/disk/vertices",
        rr.Points3D(polygon_outline(n, a)[:-1], radii=[0.015 * a], colors=[color], labels=labels),
        static=True,
    )


def _log_impacts(
    rec: rr.RecordingStream,
    name: str,
    traj: Trajectory,
    contact_pts: np.ndarray,
    color: tuple[int, int, int],
    scene: Scene,
) -> None:
    """Markers (impulse, contact index) and one TextLog line per impact, at the impact
    time; in 3D, the impacted contact point at the sample nearest the impact."""
    root = f"/{name}/impacts"
    rec.log(
        f"{root}/impulse",
        rr.SeriesPoints(colors=[color], names=[f"{name} impulse"], markers=["circle"]),
        static=True,
    )
    rec.log(
        f"{root}/contact",
        rr.SeriesPoints(colors=[color], names=[f"{name} contact"], markers=["diamond"]),
        static=True,
    )
    if not traj.impacts:
        return
    t = np.array([e.t for e in traj.impacts])
    contact = np.array([e.contact for e in traj.impacts], dtype=int)
    impulse = np.array([e.impulse for e in traj.impacts])
    times = [_time_column(t)]
    rec.send_columns(f"{root}/impulse", times, rr.Scalars.columns(scalars=impulse))
    rec.send_columns(f"{root}/contact", times, rr.Scalars.columns(scalars=contact.astype(float)))
    lines = [
        f"impact {i}: contact {e.contact} at t = {float(e.t)!r}"
        + (f" (lo {float(e.t_lo):+.3g})" if e.t_lo else "")
        + f", impulse {e.impulse:.6g}, v_n {e.v_normal_pre:.6g} → {e.v_normal_post:.6g}"
        for i, e in enumerate(traj.impacts)
    ]
    rec.send_columns(
        f"{root}/log",
        times,
        rr.TextLog.columns(text=lines, level=["INFO"] * len(lines)),
    )

    sample = np.clip(np.searchsorted(traj.t, t), 0, traj.n_samples - 1)
    where = contact_pts[sample, np.clip(contact, 0, contact_pts.shape[1] - 1)]
    rec.log(
        f"/{name}/scene/impact",
        rr.Points3D.from_fields(radii=[0.05 * scene.body.radius], colors=[(255, 220, 0)]),
        static=True,
    )
    rec.send_columns(
        f"/{name}/scene/impact",
        times,
        rr.Points3D.columns(positions=where, labels=[f"impact {i}" for i in range(len(t))]),
    )


def _log_info(
    rec: rr.RecordingStream,
    name: str,
    traj: Trajectory,
    data: dict,
    t_f: SingularityTime | None,
) -> None:
    fit: ExponentFit | None = data["fit"]
    e0 = float(traj.energy[0]) if traj.n_samples else None
    e1 = float(traj.energy[-1]) if traj.n_samples else None
    text = "\n".join(
        [
            f"## {name}",
            "",
            f"- engine: `{traj.engine}`, dt: {_fmt(traj.dt)}",
            f"- status: **{traj.status.value}** {traj.message}",
            f"- t_final: {_fmt(traj.t_final)}, t_singularity: {_fmt(traj.t_singularity)}",
            f"- samples: {traj.n_samples}, impacts: {len(traj.impacts)}",
            f"- energy: initial {_fmt(e0)}, final {_fmt(e1)}",
            f"- energy exponent c: {_fmt(fit.c if fit else None)}"
            + (f" ({fit.n_samples} samples, t_f = {t_f.source})" if fit and t_f else ""),
        ]
    )
    rec.log(f"/{name}/info", rr.TextDocument(text, media_type="text/markdown"), static=True)


# ----------------------------------------------------------------------------- log-log


def _loglog_data(traj: Trajectory, t_f: SingularityTime | None) -> dict:
    """log10(t_f − t) and log10 E on the loggable samples, and the fitted exponent."""
    empty = np.zeros(0)
    if t_f is None or traj.n_samples == 0:
        return {"t": empty, "x": empty, "y": empty, "fit": None}
    tau = time_to_go(traj, t_f)
    energy = traj.energy
    mask = loglog_mask(tau, energy)
    return {
        "t": np.asarray(traj.t, dtype=float)[mask],
        "x": np.log10(tau[mask]),
        "y": np.log10(energy[mask]),
        "fit": fit_exponent(tau, energy),
    }


def _loglog_bounds(loglog: dict[str, dict]) -> tuple[int, int, int, int] | None:
    """Whole decades (x0, x1, y0, y1) covering every simulator's log10(t_f − t), log10 E."""
    xs = np.concatenate([d["x"] for d in loglog.values()])
    ys = np.concatenate([d["y"] for d in loglog.values()])
    if len(xs) == 0:
        return None
    x0, x1 = math.floor(xs.min()), math.ceil(xs.max())
    y0, y1 = math.floor(ys.min()), math.ceil(ys.max())
    return x0, max(x1, x0 + 1), y0, max(y1, y0 + 1)


def _log_singularity_values(rec: rr.RecordingStream, name: str, data: dict, color) -> None:
    """log10(t_f − t) and log10 E as values over sim_time: the duration timeline has only
    nanosecond resolution, these keep every digit of the time to go."""
    if len(data["t"]) == 0:
        return
    times = [_time_column(data["t"])]
    for kind, values in (("log10_time_to_go", data["x"]), ("log10_energy", data["y"])):
        path = f"/{name}/singularity/{kind}"
        rec.log(path, rr.SeriesLines(colors=[color], names=[f"{name} {kind}"]), static=True)
        rec.send_columns(path, times, rr.Scalars.columns(scalars=values))


def _decade_step(span: int) -> int:
    """Tick spacing in decades so that a span has at most ~12 ticks."""
    for step in (1, 2, 5, 10, 20, 50, 100):
        if span / step <= 12:
            return step
    return 200


def _log_loglog_plot(
    rec: rr.RecordingStream,
    names: list[str],
    loglog: dict[str, dict],
    colors: dict,
    bounds: tuple[int, int, int, int] | None,
) -> None:
    """The paper's plot in a 2D view: x = log10(t_f − t), y = −log10 E (2D views point
    y down, so energy grows upwards), decade grid and tick labels, one curve and one
    fitted line (legend: exponent c) per simulator, and a marker that follows sim_time."""
    if bounds is None:
        rec.log(
            f"{LOGLOG}/note",
            rr.TextDocument(
                "No singularity time: the reference has neither t_singularity nor impacts."
            ),
            static=True,
        )
        return
    x0, x1, y0, y1 = bounds
    sx, sy = _decade_step(x1 - x0), _decade_step(y1 - y0)
    xt = np.arange(sx * math.ceil(x0 / sx), x1 + 1, sx)
    yt = np.arange(sy * math.ceil(y0 / sy), y1 + 1, sy)
    grid = [np.array([[x, -y0], [x, -y1]], dtype=float) for x in xt]
    grid += [np.array([[x0, -y], [x1, -y]], dtype=float) for y in yt]
    rec.log(
        f"{LOGLOG}/grid",
        rr.LineStrips2D(grid, colors=[(80, 80, 80)], radii=rr.Radius.ui_points(0.5), draw_order=0),
        static=True,
    )
    pad = 0.04 * max(x1 - x0, y1 - y0)
    tick_pos = [[x, -y0 + pad] for x in xt] + [[x0 - pad, -y] for y in yt]
    tick_lab = [f"1e{int(x)}" for x in xt] + [f"1e{int(y)}" for y in yt]
    tick_pos += [[0.5 * (x0 + x1), -y0 + 3 * pad], [x0 - 3 * pad, -0.5 * (y0 + y1)]]
    tick_lab += ["t_f − t", "E"]
    rec.log(
        f"{LOGLOG}/ticks",
        rr.Points2D(
            tick_pos, labels=tick_lab, radii=rr.Radius.ui_points(0.1), colors=[(160, 160, 160)]
        ),
        static=True,
    )
    for name in names:
        d = loglog[name]
        if len(d["x"]) == 0:
            continue
        color = colors[name]
        rec.log(
            f"{LOGLOG}/{name}/curve",
            rr.LineStrips2D(
                [np.stack([d["x"], -d["y"]], axis=1)],
                colors=[color],
                radii=rr.Radius.ui_points(1.0),
                labels=[name],
                draw_order=1,
            ),
            static=True,
        )
        fit: ExponentFit | None = d["fit"]
        if fit is not None:
            xs = np.array([d["x"].min(), d["x"].max()])
            ys = fit.c * xs + fit.log_a / math.log(10.0)
            rec.log(
                f"{LOGLOG}/{name}/fit",
                rr.LineStrips2D(
                    [np.stack([xs, -ys], axis=1)],
                    colors=[_shade(color, 0.5)],
                    radii=rr.Radius.ui_points(0.75),
                    labels=[f"{name}: c = {fit.c:.4g}"],
                    draw_order=2,
                ),
                static=True,
            )
        rec.log(
            f"{LOGLOG}/{name}/now",
            rr.Points2D.from_fields(radii=rr.Radius.ui_points(4.0), colors=[color]),
            static=True,
        )
        # the marker follows the samples that have a logarithm
        rec.send_columns(
            f"{LOGLOG}/{name}/now",
            [_time_column(d["t"])],
            rr.Points2D.columns(positions=np.stack([d["x"], -d["y"]], axis=1)),
        )


def _log_summary(
    rec: rr.RecordingStream,
    scene: Scene,
    names: list[str],
    trajs: list[Trajectory],
    loglog: dict[str, dict],
    t_f: SingularityTime | None,
) -> None:
    rows = [
        f"# {scene.name}",
        "",
        f"t_f = {_fmt(t_f.hi) if t_f else '–'} ({t_f.source if t_f else 'no singularity time'});"
        " E ≈ a (t_f − t)^c fitted by least squares of log E on log(t_f − t).",
        "",
        "| simulator | status | impacts | E final | c | fit samples |",
        "|---|---|---|---|---|---|",
    ]
    method = None
    for name, traj in zip(names, trajs, strict=True):
        fit = loglog[name]["fit"]
        method = method or (fit.method if fit else None)
        e1 = float(traj.energy[-1]) if traj.n_samples else None
        rows.append(
            f"| {name} | {traj.status.value} | {len(traj.impacts)} | {_fmt(e1)} | "
            f"{_fmt(fit.c if fit else None)} | {fit.n_samples if fit else 0} |"
        )
    if method:
        rows += ["", f"fit: {method}"]
    rec.log(SUMMARY, rr.TextDocument("\n".join(rows), media_type="text/markdown"), static=True)


# ----------------------------------------------------------------------------- blueprint


def build_blueprint(
    names: list[str], bounds: tuple[int, int, int, int] | None = None, radius: float = 1.0
) -> rrb.Blueprint:
    """3D views side by side on top; below: energy overlay (and per-simulator energies,
    inclination), impact views, and the log-log plot with the fitted exponents."""
    eye = rrb.EyeControls3D(
        position=[2.2 * radius, -2.6 * radius, 1.6 * radius],
        look_target=[0.0, 0.0, 0.0],
        eye_up=[0.0, 0.0, 1.0],
    )
    scenes = [
        rrb.Spatial3DView(origin=f"/{n}/scene", name=f"{n}: disk", eye_controls=eye) for n in names
    ]
    energy = rrb.Tabs(
        rrb.TimeSeriesView(
            name="energy (all simulators)",
            origin="/",
            contents=[f"/{n}/energy/total" for n in names],
        ),
        rrb.TimeSeriesView(
            name="inclination α",
            origin="/",
            contents=[f"/{n}/inclination" for n in names],
        ),
        *[rrb.TimeSeriesView(name=f"{n}: energy", origin=f"/{n}/energy") for n in names],
        name="energy",
    )
    impacts = rrb.Tabs(
        rrb.TimeSeriesView(
            name="impacts: impulse",
            origin="/",
            contents=[f"/{n}/impacts/impulse" for n in names],
        ),
        rrb.TimeSeriesView(
            name="impacts: contact",
            origin="/",
            contents=[f"/{n}/impacts/contact" for n in names],
        ),
        rrb.TextLogView(
            name="impact log", origin="/", contents=[f"/{n}/impacts/log" for n in names]
        ),
        name="impacts",
    )
    visual = None
    if bounds is not None:
        x0, x1, y0, y1 = bounds
        pad = 0.1 * max(x1 - x0, y1 - y0)
        visual = rrb.VisualBounds2D(
            x_range=[x0 - 3 * pad, x1 + pad], y_range=[-y1 - pad, -y0 + 3 * pad]
        )
    loglog = rrb.Tabs(
        rrb.Spatial2DView(name="log E vs log (t_f − t)", origin=LOGLOG, visual_bounds=visual),
        rrb.TimeSeriesView(
            name="log10 (t_f − t)",
            origin="/",
            contents=[f"/{n}/singularity/log10_time_to_go" for n in names],
        ),
        rrb.TextDocumentView(name="summary", origin=SUMMARY),
        name="singularity",
    )
    return rrb.Blueprint(
        rrb.Vertical(
            rrb.Horizontal(*scenes, name="disks"),
            rrb.Horizontal(energy, impacts, loglog, name="plots"),
            row_shares=[1.0, 1.0],
        ),
        rrb.TimePanel(timeline=SIM_TIME),
    )
