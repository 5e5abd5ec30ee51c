"""Rerun recordings: written from hand-built Trajectories, read back with rerun's reader.

The synthetic runs are built so that every recorded number is known independently:
the inclination α = 0.2 √(t_f − t) about an axis turning at 3 rad/s (heading ψ known),
and a vertical velocity whose kinetic energy, the only energy above rest, is
a (t_f − t)^c held constant between impacts at t_f − 2^−i (a staircase whose
pre-impact corners are an exact power law, so the exponent is c).
"""

from __future__ import annotations

import math
import re
import subprocess
import sys
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest
import rerun as rr

from harness.cli import main
from harness.recording import entity_names, record_trajectories
from harness.recording.geometry import (
    contact_points,
    exaggerated_pose,
    exaggeration_schedule,
    factor_at,
    headings,
    inclinations,
    quaternion_xyzw,
    tilt_exaggeration,
)
from harness.recording.layout import focus_range
from harness.recording.raster import SIZE_MAX, SIZE_MIN, marker_sizes
from harness.recording.runs import TIME_MARGIN
from harness.recording.singularity import EndTime, _ttg, staircase
from reference import quaternion as qt
from reference.scene import scene_from_dict
from reference.trajectory import ImpactEvent, Status, Trajectory
from tests.oracle.body import BodyModel

RERUN_CLI = Path(sys.executable).parent / "rerun"
T_F = 2.0
N_IMPACTS = 35  # 2^-34 s before t_f: still resolved against t_singularity


def make_scene(kind: str = "flat", n: int = 5):
    return scene_from_dict(
        {
            "name": "synthetic",
            "body": {"n": n},
            "ground": {"kind": kind},
            "initial": {"q": [0.01, 0.0, 0.02], "p": [0.0, 0.0, 0.0]},
        }
    )


def synthetic_trajectory(
    engine: str,
    dt: float | None = None,
    c: float = 2.0,
    a: float = 3.0,
    singular: bool = False,
    contacts: list[int] | None = None,
    t_end: float = T_F,
) -> Trajectory:
    """Impacts at t_f − 2^−i; one sample at t = 0, one between each impact and the one
    before (at t_f − 1.5·2^−i) and samples after t_f up to t_end; between impacts the
    energy above rest is a (2^−i)^c (kinetic, vertical), after t_f zero."""
    tau_i = 0.5 ** np.arange(N_IMPACTS)
    t_pre = T_F - 1.5 * tau_i
    e_pre = a * tau_i**c
    after = np.linspace(T_F, t_end, 5)[1:] if t_end > T_F else np.zeros(0)
    t = np.concatenate([[0.0], t_pre, after])
    energy = np.concatenate([[e_pre[0]], e_pre, np.zeros(len(after))])
    t_pre[0] = 0.5 * (T_F - 1.0)  # between t = 0 and the first impact
    tau = np.maximum(T_F - t, 0.0)
    alpha = 0.2 * np.sqrt(tau)
    phi = 3.0 * t
    axis = np.stack([np.cos(phi), np.sin(phi), np.zeros_like(t)], axis=1)
    quat = qt.from_rotation_vector(alpha[:, None] * axis)
    velocity = np.zeros((len(t), 3))
    velocity[:, 2] = -np.sqrt(2.0 * energy)  # m = 1
    position = np.zeros((len(t), 3))
    contacts = contacts or [i % 5 for i in range(N_IMPACTS)]
    impacts = [
        ImpactEvent(float(T_F - x), contacts[i], 0.1 * 0.5**i, -1.0, 0.5)  # no chatter tails
        for i, x in enumerate(tau_i)
    ]
    return Trajectory(
        engine=engine,
        scene="synthetic",
        t=t,
        position=position,
        quaternion=quat,
        velocity=velocity,
        angular_velocity=np.zeros((len(t), 3)),
        kinetic_energy=energy,
        potential_energy=np.zeros(len(t)),
        impacts=impacts,
        status=Status.SINGULARITY if singular else Status.T_END,
        t_final=float(t[-1]),
        t_singularity=T_F if singular else None,
        dt=dt,
    )


WRONG_CONTACT_AT = 20  # the second engine hits another vertex at its impact 20


def three_simulators() -> list[Trajectory]:
    wrong = [i % 5 for i in range(N_IMPACTS)]
    wrong[WRONG_CONTACT_AT] = (wrong[WRONG_CONTACT_AT] + 1) % 5
    return [
        synthetic_trajectory("reference", singular=True),
        synthetic_trajectory("mujoco", dt=1e-4, t_end=3.0),
        synthetic_trajectory("mujoco", dt=1e-3, contacts=wrong, t_end=3.0),
    ]


NAMES = ["reference", "mujoco_dt1e-04", "mujoco_dt1e-03"]


@pytest.fixture(scope="module")
def recorded(tmp_path_factory):
    trajs = three_simulators()
    path = record_trajectories(trajs, tmp_path_factory.mktemp("rec") / "three.rrd", make_scene())
    return path, trajs


def temporal_column(path: Path, entity: str, component: str) -> tuple[np.ndarray, list]:
    """(sim_time in ns, values) of one component of one entity, temporal rows only."""
    store = rr.chunk.RrdReader(path).store()
    chunks = store.stream().filter(content=entity, is_static=False).to_chunks()
    times, values = [], []
    for chunk in chunks:
        batch = chunk.to_record_batch()
        if component not in batch.schema.names:
            continue
        times.append(batch.column("sim_time").cast("int64").to_numpy())
        values.extend(batch.column(component).to_pylist())
    t = np.concatenate(times) if times else np.zeros(0, dtype=np.int64)
    order = np.argsort(t, kind="stable")
    return t[order], [values[i] for i in order]


def scalars(path: Path, entity: str) -> tuple[np.ndarray, np.ndarray]:
    t, values = temporal_column(path, entity, "Scalars:scalars")
    return t, np.array([v[0] for v in values], dtype=float)


def static_value(path: Path, entity: str, component: str):
    store = rr.chunk.RrdReader(path).store()
    for chunk in store.stream().filter(content=entity, is_static=True).to_chunks():
        batch = chunk.to_record_batch()
        if component in batch.schema.names:
            return batch.column(component).to_pylist()[-1]
    raise KeyError(f"{entity} has no static {component}")


def entities(path: Path) -> set[str]:
    return {line.split()[0] for line in rr.chunk.RrdReader(path).store().summary().splitlines()}


# ----------------------------------------------------------------------------- the file


def test_recording_has_the_rows_of_every_simulator(recorded):
    path, _ = recorded
    found = entities(path)
    for name in NAMES:
        for leaf in (
            "scene/disk",
            "scene/disk/outline",
            "scene/ground",
            "scene/contacts",
            "scene/exaggeration",
            "attitude/log10_alpha",
            "attitude/heading",
            "energy/log10_excess",
        ):
            assert f"/{name}/{leaf}" in found, f"/{name}/{leaf} missing"
        assert f"/impacts/{name}" in found
    assert {"/summary", "/singularity/energy/reference/fit"} <= found


def test_rows_read_back_as_the_constructed_attitude_and_energy(recorded):
    path, trajs = recorded
    ref = trajs[0]
    t_ns, log_alpha = scalars(path, "/reference/attitude/log10_alpha")
    np.testing.assert_array_equal(t_ns, np.round(ref.t * 1e9).astype(np.int64))
    tau = T_F - ref.t
    np.testing.assert_allclose(log_alpha, np.log10(0.2 * np.sqrt(tau)), atol=1e-9)
    # the tilt axis turns at 3 rad/s, so the lowest point's heading does too (turns)
    _, psi = scalars(path, "/reference/attitude/heading")
    np.testing.assert_allclose(np.diff(psi), 3.0 * np.diff(ref.t) / (2 * math.pi), atol=1e-9)
    _, log_e = scalars(path, "/reference/energy/log10_excess")
    np.testing.assert_allclose(log_e, np.log10(ref.kinetic_energy), rtol=0, atol=1e-9)


def test_data_end_at_the_reference_end_plus_the_margin(recorded):
    path, trajs = recorded
    t_ns, _ = scalars(path, "/mujoco_dt1e-04/energy/log10_excess")
    assert t_ns.max() <= T_F * (1 + TIME_MARGIN) * 1e9
    kept = trajs[1].t[trajs[1].t <= T_F * (1 + TIME_MARGIN)]
    assert len(t_ns) == len(kept) < trajs[1].n_samples


def test_raster_has_one_marker_per_impact_at_its_contact(recorded):
    path, trajs = recorded
    largest = max(e.impulse for traj in trajs for e in traj.impacts)
    for name, traj in zip(NAMES, trajs, strict=True):
        t_ns, y = scalars(path, f"/impacts/{name}")
        _, sizes = temporal_column(path, f"/impacts/{name}", "SeriesPoints:marker_sizes")
        contacts = np.array([e.contact for e in traj.impacts])
        impulse = np.array([e.impulse for e in traj.impacts])
        np.testing.assert_array_equal(y, contacts)  # the y axis reads as contact names
        np.testing.assert_array_equal(t_ns, np.round(traj.impact_times() * 1e9).astype(np.int64))
        np.testing.assert_allclose([s[0] for s in sizes], marker_sizes(impulse, largest), rtol=1e-6)


def test_reference_impacts_are_drawn_faintly_behind_the_engines(recorded):
    path, trajs = recorded
    t_ns, y = scalars(path, "/impacts/behind/reference")
    np.testing.assert_array_equal(y, [e.contact for e in trajs[0].impacts])
    np.testing.assert_array_equal(t_ns, np.round(trajs[0].impact_times() * 1e9).astype(np.int64))


def test_rows_open_just_before_the_first_impact():
    assert focus_range(np.array([0.3, 0.4, 0.5]), 0.5) == pytest.approx((0.29, 0.5))
    assert focus_range(np.array([]), 0.5) == (0.0, 0.5)  # no impact: the whole run
    assert focus_range(np.array([0.0, 0.2]), 1.0) == (0.0, 1.0)


def test_marker_size_grows_with_log_impulse_over_four_decades():
    sizes = marker_sizes(np.array([1.0, 0.1, 1e-4, 1e-6]), 1.0)
    assert sizes[0] == SIZE_MAX and sizes[2] == sizes[3] == SIZE_MIN
    assert sizes[1] == pytest.approx(SIZE_MIN + 0.75 * (SIZE_MAX - SIZE_MIN))


def test_first_mismatch_is_marked_where_the_contact_differs(recorded):
    path, trajs = recorded
    t_ns, y = scalars(path, "/impacts/mujoco_dt1e-03/first_mismatch")
    wrong = trajs[2].impacts[WRONG_CONTACT_AT]
    assert t_ns.tolist() == [round(wrong.t * 1e9)]
    assert y.tolist() == [wrong.contact]
    assert "/impacts/mujoco_dt1e-04/first_mismatch" not in entities(path)
    # and on every row of that simulator, at the same time
    t_row, _ = scalars(path, "/mujoco_dt1e-03/divergence/log10_alpha")
    assert t_row.tolist() == [round(wrong.t * 1e9)]


def test_exponents_only_for_runs_that_reach_the_singularity(recorded):
    """The reference reaches it; the first engine follows it impact for impact to t_f (and
    so has the reference's t_f); the second leaves it at impact 20 and has no c."""
    path, _ = recorded
    lines = [
        static_value(path, f"/singularity/energy/legend/{k}", "Points2D:labels")[0]
        for k in range(1 + len(NAMES))  # what t_f is, then one line per run
    ]
    for name in ("reference", "mujoco 1e-04"):
        line = next(x for x in lines if x.startswith(f"{name}: "))
        c, se = map(float, re.search(r"c = ([\d.]+) ± ([\d.e-]+)", line).groups())
        assert c == pytest.approx(2.0, abs=1e-3) and se < 1e-3
    assert "mujoco 1e-03: no c (t_end)" in lines
    summary = static_value(path, "/summary", "TextDocument:text")[0]
    assert "First to diverge: mujoco 1e-03" in summary
    assert "impact 20" in summary


def test_disk_pose_is_logged_with_xyzw_quaternions_and_the_exaggeration(recorded):
    path, trajs = recorded
    traj = trajs[0]
    _, quats = temporal_column(path, "/reference/scene/disk", "Transform3D:quaternion")
    got = np.array([q[0] for q in quats])
    t_ns, labels = temporal_column(path, "/reference/scene/exaggeration", "Points3D:labels")
    schedule = exaggeration_schedule(traj.t, inclinations(traj.quaternion))
    k = factor_at(schedule, traj.t)
    _, q2 = exaggerated_pose(make_scene(), traj.position, traj.quaternion, k)
    np.testing.assert_allclose(got, quaternion_xyzw(q2), atol=1e-7)
    assert labels[0][0] == f"tilt and heights ×{schedule[1][0]:g}"
    assert len(labels) == len(schedule[1]) > 1


def test_blueprint_is_embedded_with_the_views(recorded):
    path, _ = recorded
    reader = rr.chunk.RrdReader(path)
    blueprints = reader.blueprints()
    assert len(blueprints) == 1
    views = []
    for chunk in reader.stream(store=blueprints[0]).to_chunks():
        batch = chunk.to_record_batch()
        if "ViewBlueprint:class_identifier" in batch.schema.names:
            views.append(
                (
                    batch.column("ViewBlueprint:class_identifier").to_pylist()[-1][0],
                    batch.column("ViewBlueprint:space_origin").to_pylist()[-1][0],
                    batch.column("ViewBlueprint:display_name").to_pylist()[-1][0],
                )
            )
    spaces3d = {origin for kind, origin, _ in views if kind == "3D"}
    assert spaces3d == {f"/{n}/scene" for n in NAMES}
    assert {("2D", "/singularity/energy"), ("2D", "/singularity/alpha")} <= {
        (k, o) for k, o, _ in views
    }
    series = [d for k, _, d in views if k == "TimeSeries"]
    for row in ("log10 α [rad]", "heading ψ [turns]", "log10(E − E_rest) [J]"):
        assert sum(d.startswith(row) for d in series) == len(NAMES), row
    assert sum(d.startswith("impacts · ") for d in series) == len(NAMES)


def test_rerun_rrd_verify_accepts_the_file(recorded):
    path, _ = recorded
    result = subprocess.run(
        [str(RERUN_CLI), "rrd", "verify", str(path)], capture_output=True, text=True, timeout=120
    )
    assert result.returncode == 0, result.stderr


def test_second_recording_in_the_same_process_leaves_no_global_stream(tmp_path):
    scene = make_scene("three_point")
    first = record_trajectories([synthetic_trajectory("reference")], tmp_path / "a.rrd", scene)
    second = record_trajectories([synthetic_trajectory("linear")], tmp_path / "b.rrd", scene)
    assert rr.get_global_data_recording() is None
    assert rr.get_thread_local_data_recording() is None
    assert "/reference/energy/log10_excess" in entities(first)
    assert not any(e.startswith("/linear/") for e in entities(first))
    assert "/linear/energy/log10_excess" in entities(second)
    assert not any(e.startswith("/reference/") for e in entities(second))


def test_compare_records_its_runs_with_their_verdicts(tmp_path, capsys):
    out = tmp_path / "cmp.rrd"
    argv = ["compare", "near-simultaneous", "--engine", "linear", "--t-end", "0.05"]
    assert main([*argv, "--record", str(out), "--json"]) == 0
    capsys.readouterr()
    found = entities(out)
    assert {"/reference/attitude/log10_alpha", "/linear/attitude/log10_alpha"} <= found
    assert "linear" in static_value(out, "/summary", "TextDocument:text")[0]


# ----------------------------------------------------------------------------- names, paths


def test_recording_creates_its_folders_when_written(tmp_path):
    path = record_trajectories(
        [synthetic_trajectory("reference")], tmp_path / "out/deep/run.rrd", make_scene()
    )
    assert path.is_file() and path.parent == tmp_path / "out/deep"
    assert [p.name for p in path.parent.iterdir()] == ["run.rrd"]  # no temporary file left


def test_entity_names_are_unique_per_run():
    trajs = [
        synthetic_trajectory("reference"),
        synthetic_trajectory("mujoco-default", dt=1e-4),
        synthetic_trajectory("mujoco-default", dt=1e-3),
        synthetic_trajectory("mujoco-default", dt=1e-3),
        synthetic_trajectory("impacts"),
    ]
    assert entity_names(trajs) == [
        "reference",
        "mujoco-default_dt1e-04",
        "mujoco-default_dt1e-03",
        "mujoco-default_dt1e-03_2",
        "impacts_2",
    ]


# ----------------------------------------------------------------------------- geometry


@pytest.mark.parametrize("kind", ["flat", "three_point"])
def test_contact_points_match_the_body_model(kind):
    scene = make_scene(kind, n=7)
    model = BodyModel.from_scene(scene)
    rng = np.random.default_rng(1)
    quats = np.array([qt.from_rotation_vector(v) for v in 0.3 * rng.standard_normal((20, 3))])
    positions = rng.standard_normal((20, 3))
    pts, gaps = contact_points(scene, positions, quats)
    for i in range(20):
        y = np.concatenate([positions[i], quats[i], np.zeros(6)])
        gap, _, lever, _, _ = model.contacts(y)
        np.testing.assert_allclose(gaps[i], gap, atol=1e-14)
        np.testing.assert_allclose(pts[i], positions[i] + lever, atol=1e-14)


@pytest.mark.parametrize("kind", ["flat", "three_point"])
def test_exaggeration_multiplies_tilt_and_lowest_gap_and_keeps_heading(kind):
    scene = make_scene(kind, n=6)
    rng = np.random.default_rng(3)
    alpha = 10 ** rng.uniform(-6, -2, 30)
    psi = rng.uniform(-math.pi, math.pi, 30)
    spin = rng.uniform(-math.pi, math.pi, 30)
    axis = np.stack([-np.sin(psi), np.cos(psi), np.zeros(30)], axis=1)  # tilts e3 towards ψ
    q = qt.multiply(
        qt.from_rotation_vector(alpha[:, None] * axis),
        qt.from_rotation_vector(np.stack([np.zeros(30), np.zeros(30), spin], axis=1)),
    )
    x = np.concatenate([rng.normal(0, 0.1, (30, 2)), rng.uniform(0, 0.05, (30, 1))], axis=1)
    k = 10.0
    x2, q2 = exaggerated_pose(scene, x, q, k)
    np.testing.assert_allclose(inclinations(q2), k * alpha, rtol=1e-9)
    np.testing.assert_allclose(np.cos(2 * math.pi * headings(q2)), np.cos(psi), atol=1e-9)
    np.testing.assert_allclose(np.sin(2 * math.pi * headings(q2)), np.sin(psi), atol=1e-9)
    _, gap = contact_points(scene, x, q)
    _, gap2 = contact_points(scene, x2, q2)
    np.testing.assert_allclose(gap2.min(axis=1), k * gap.min(axis=1), rtol=1e-9, atol=1e-15)
    np.testing.assert_array_equal(x2[:, :2], x[:, :2])


def test_exaggeration_is_round_and_grows_as_the_motion_dies_down():
    assert tilt_exaggeration(0.02) == 10.0  # 0.35 / 0.02 = 17.5 → 10
    assert tilt_exaggeration(0.0003) == 1000.0  # 1167 → 1000
    assert tilt_exaggeration(0.0001) == 2000.0  # 3500 → 2000
    assert tilt_exaggeration(1.0) == 1.0
    t = np.linspace(0, 1, 50)
    times, factors = exaggeration_schedule(t, 0.02 * np.exp(-8 * t) * (1.5 + np.sin(40 * t)))
    assert np.all(np.diff(factors) > 0) and times[0] == 0.0
    np.testing.assert_array_equal(factor_at((times, factors), times), factors)


def test_inclinations_and_headings_match_the_quaternion_helpers():
    traj = synthetic_trajectory("reference")
    np.testing.assert_allclose(inclinations(traj.quaternion), traj.inclination, rtol=1e-15)
    e3 = qt.body_axis(traj.quaternion)
    psi = 2 * math.pi * headings(traj.quaternion)
    np.testing.assert_allclose(np.cos(psi), e3[:, 0] / np.hypot(e3[:, 0], e3[:, 1]), atol=1e-9)


def test_quaternion_xyzw_moves_w_last():
    np.testing.assert_array_equal(quaternion_xyzw(np.array([[1.0, 2, 3, 4]])), [[2.0, 3, 4, 1]])


# ----------------------------------------------------------------------------- log-log


def test_time_to_go_keeps_the_low_parts():
    # t_f = 1 + 2^-80 (hi 1, lo 2^-80); samples t = 1 - 2^-50 + 2^-90 and 1 - 2^-90
    t = np.array([1.0 - 2.0**-50, 1.0])
    t_lo = np.array([2.0**-90, -(2.0**-90)])
    got = _ttg(t, t_lo, EndTime(hi=1.0, lo=2.0**-80, what="test"))
    two = Fraction(2)
    exact = [two**-50 + two**-80 - two**-90, two**-80 + two**-90]
    for g, e in zip(got, exact, strict=True):
        assert abs(Fraction(float(g)) - e) <= e * Fraction(2) ** -52


def test_staircase_holds_each_pre_impact_energy_until_its_impact():
    xs, ys = staircase(np.array([0.0, -1.0, -2.0]), np.array([5.0, 3.0, 1.0]))
    assert xs.tolist() == [0.0, -1.0, -1.0, -2.0, -2.0]
    assert ys.tolist() == [5.0, 5.0, 3.0, 3.0, 1.0]


# ----------------------------------------------------------------------------- size


@pytest.mark.slow
def test_write_time_and_size_of_a_long_three_simulator_recording(tmp_path):
    """Measurement, not an assertion on speed: 3 simulators × 100,000 samples."""
    import time

    scene = make_scene()
    base = synthetic_trajectory("reference", singular=True)
    t = np.linspace(0.0, T_F, 100_000)
    trajs = []
    for engine, dt in (("reference", None), ("mujoco", 1e-4), ("pybullet", 1e-4)):
        idx = np.minimum(np.searchsorted(base.t, t), base.n_samples - 1)
        trajs.append(
            Trajectory.from_states(
                engine, "synthetic", t,
                np.concatenate([base.position[idx], base.quaternion[idx], base.velocity[idx],
                                base.angular_velocity[idx]], axis=1),
                base.kinetic_energy[idx], base.potential_energy[idx], base.impacts,
                base.status if dt is None else Status.T_END, dt=dt,
                t_singularity=T_F if dt is None else None,
            )
        )  # fmt: skip
    start = time.perf_counter()
    path = record_trajectories(trajs, tmp_path / "long.rrd", scene)
    seconds = time.perf_counter() - start
    print(f"\n3 x 100000 samples: wrote {path.stat().st_size / 1e6:.1f} MB in {seconds:.2f} s")
    _, values = scalars(path, "/pybullet_dt1e-04/energy/log10_excess")
    assert len(values) == 100_000


def test_bumpy_recording_draws_the_bumps_and_sets_bump_impacts_apart(tmp_path, capsys):
    """compare on bumpy-rolling with MuJoCo: the bumps are drawn, and each raster's bump
    impacts (contacts n … of the 20-gon) are diamonds in their own series, apart from
    the rim's."""
    out = tmp_path / "bumpy.rrd"
    argv = ["compare", "bumpy-rolling", "--engine", "mujoco", "--dt", "1e-4"]
    assert main([*argv, "--record", str(out), "--json"]) == 0
    capsys.readouterr()
    found = entities(out)
    assert {"/reference/scene/ground/bumps", "/impacts/reference/bump"} <= found
    diamond = rr.components.MarkerShape.Diamond.value
    assert static_value(out, "/impacts/reference/bump", "SeriesPoints:markers") == [diamond]
    _, rim = scalars(out, "/impacts/reference")
    _, bump = scalars(out, "/impacts/reference/bump")
    assert len(bump) >= 1 and np.all(bump >= 20) and np.all(rim < 20)
