"""Rerun recordings: written from hand-built Trajectories, read back with rerun's reader.

The synthetic trajectories have E = a (t_f − t)^c by construction, so the recorded
values, the time to go and the fitted exponent are checked against known numbers.
"""

from __future__ import annotations

import math
import subprocess
import sys
import time
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest
import rerun as rr

from harness.recording import entity_names, record_trajectories, recording_path
from harness.recording.geometry import contact_points, inclinations, quaternion_xyzw
from harness.recording.loglog import (
    SingularityTime,
    fit_exponent,
    singularity_time,
    time_to_go,
)
from reference import quaternion as qt
from reference.scene import scene_from_dict
from reference.trajectory import ImpactEvent, Status, Trajectory
from tests.oracle.body import BodyModel

RERUN_CLI = Path(sys.executable).parent / "rerun"
T_F = 2.0


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
    n_samples: int = 200,
    dt: float | None = None,
    c: float = 2.0,
    a: float = 3.0,
    n_impacts: int = 7,
    t_singularity: float | None = None,
) -> Trajectory:
    """E = a (t_f − t)^c split 70/30 into kinetic/potential; tilt about a wobbling axis."""
    tau = np.geomspace(1.0, 1e-8, n_samples)  # time to go, exactly representable t_f − tau
    t = T_F - tau
    alpha = 0.2 * np.sqrt(tau)
    phi = 3.0 * t
    axis = np.stack([np.cos(phi), np.sin(phi), np.zeros_like(t)], axis=1)
    quat = np.concatenate([np.cos(alpha / 2)[:, None], np.sin(alpha / 2)[:, None] * axis], axis=1)
    position = np.stack([0.1 * t, -0.05 * t, 0.5 * np.sin(alpha)], axis=1)
    energy = a * tau**c
    impacts = [
        ImpactEvent(
            t=float(ti),
            contact=i % 5,
            impulse=0.1 / (i + 1),
            v_normal_pre=-1.0 / (i + 1),
            v_normal_post=0.5 / (i + 1),
        )
        for i, ti in enumerate(np.linspace(1.1, 1.9, n_impacts))
    ]
    return Trajectory(
        engine=engine,
        scene="synthetic",
        t=t,
        position=position,
        quaternion=quat,
        velocity=np.zeros_like(position),
        angular_velocity=np.zeros_like(position),
        kinetic_energy=0.7 * energy,
        potential_energy=0.3 * energy,
        impacts=impacts,
        status=Status.SINGULARITY if t_singularity is not None else Status.T_END,
        t_final=float(t[-1]),
        t_singularity=t_singularity,
        dt=dt,
    )


def three_simulators() -> list[Trajectory]:
    return [
        synthetic_trajectory("reference", c=2.0, n_impacts=7, t_singularity=T_F),
        synthetic_trajectory("mujoco", dt=1e-4, c=1.5, n_impacts=4),
        synthetic_trajectory("mujoco", dt=1e-3, c=2.5, n_impacts=0),
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
    return (np.concatenate(times) if times else np.zeros(0, dtype=np.int64)), values


def static_value(path: Path, entity: str, component: str):
    store = rr.chunk.RrdReader(path).store()
    for chunk in store.stream().filter(content=entity, is_static=True).to_chunks():
        batch = chunk.to_record_batch()
        if component in batch.schema.names:
            return batch.column(component).to_pylist()[-1]
    raise KeyError(f"{entity} has no static {component}")


# ----------------------------------------------------------------------------- the file


def test_recording_has_an_entity_subtree_per_simulator(recorded):
    path, _ = recorded
    summary = rr.chunk.RrdReader(path).store().summary()
    entities = {line.split()[0] for line in summary.splitlines()}
    for name in NAMES:
        for leaf in (
            "scene/disk",
            "scene/disk/outline",
            "scene/ground",
            "scene/contacts",
            "inclination",
            "energy/kinetic",
            "energy/potential",
            "energy/total",
            "impacts/impulse",
            "impacts/contact",
            "info",
        ):
            assert f"/{name}/{leaf}" in entities, f"/{name}/{leaf} missing"


def test_energies_read_back_equal_the_trajectories(recorded):
    path, trajs = recorded
    for name, traj in zip(NAMES, trajs, strict=True):
        for kind, expected in (
            ("kinetic", traj.kinetic_energy),
            ("potential", traj.potential_energy),
            ("total", traj.kinetic_energy + traj.potential_energy),
        ):
            t_ns, values = temporal_column(path, f"/{name}/energy/{kind}", "Scalars:scalars")
            got = np.array([v[0] for v in values])
            np.testing.assert_array_equal(got, expected)
            np.testing.assert_array_equal(t_ns, np.round(traj.t * 1e9).astype(np.int64))


def test_one_impact_entry_per_impact(recorded):
    path, trajs = recorded
    for name, traj in zip(NAMES, trajs, strict=True):
        _, impulse = temporal_column(path, f"/{name}/impacts/impulse", "Scalars:scalars")
        _, contact = temporal_column(path, f"/{name}/impacts/contact", "Scalars:scalars")
        _, text = temporal_column(path, f"/{name}/impacts/log", "TextLog:text")
        assert len(impulse) == len(contact) == len(text) == len(traj.impacts)
        assert [v[0] for v in impulse] == [e.impulse for e in traj.impacts]
        assert [int(v[0]) for v in contact] == [e.contact for e in traj.impacts]
        for line, e in zip(text, traj.impacts, strict=True):
            assert f"contact {e.contact} " in line[0]


def test_disk_pose_is_logged_with_xyzw_quaternions(recorded):
    path, trajs = recorded
    traj = trajs[0]
    _, quats = temporal_column(path, "/reference/scene/disk", "Transform3D:quaternion")
    got = np.array([q[0] for q in quats])
    w, x, y, z = traj.quaternion.T
    np.testing.assert_allclose(got, np.stack([x, y, z, w], axis=1), atol=1e-7)


def test_log_time_to_go_is_logged_exactly_near_the_singularity(recorded):
    path, trajs = recorded
    tau = np.geomspace(1.0, 1e-8, trajs[0].n_samples)  # by construction t = t_f − tau
    _, values = temporal_column(path, "/reference/singularity/log10_time_to_go", "Scalars:scalars")
    np.testing.assert_allclose([v[0] for v in values], np.log10(tau), rtol=0, atol=1e-7)


def test_fitted_exponents_are_the_constructed_ones(recorded):
    path, _ = recorded
    for name, c in zip(NAMES, (2.0, 1.5, 2.5), strict=True):
        label = static_value(path, f"/compare/loglog/{name}/fit", "LineStrips2D:labels")[0]
        assert label.startswith(f"{name}: c = ")
        assert float(label.split("= ")[1]) == pytest.approx(c, rel=1e-3)


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
    assert ("2D", "/compare/loglog") in {(k, o) for k, o, _ in views}
    display = {d for _, _, d in views}
    assert {"energy (all simulators)", "impacts: impulse", "impact log"} <= display


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
    first_summary = rr.chunk.RrdReader(first).store().summary()
    second_summary = rr.chunk.RrdReader(second).store().summary()
    assert "/reference/energy/total" in first_summary
    assert "/linear/" not in first_summary
    assert "/linear/energy/total" in second_summary
    assert "/reference/" not in second_summary


# ----------------------------------------------------------------------------- names, paths


def test_bare_file_name_goes_under_recordings(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert recording_path("run.rrd") == Path("recordings/run.rrd")
    assert recording_path("./run.rrd") == Path("run.rrd")
    assert recording_path("out/deep/run.rrd") == Path("out/deep/run.rrd")
    assert not (tmp_path / "recordings").exists()  # created only when a recording is written


def test_recording_creates_its_folders_when_written(tmp_path):
    path = record_trajectories(
        [synthetic_trajectory("reference")], tmp_path / "out/deep/run.rrd", make_scene()
    )
    assert path.is_file() and path.parent == tmp_path / "out/deep"
    assert [p.name for p in path.parent.iterdir()] == ["run.rrd"]  # no temporary file left


def test_entity_names_are_unique_per_run():
    trajs = [
        synthetic_trajectory("reference", n_samples=3),
        synthetic_trajectory("mujoco-default", n_samples=3, dt=1e-4),
        synthetic_trajectory("mujoco-default", n_samples=3, dt=1e-3),
        synthetic_trajectory("mujoco-default", n_samples=3, dt=1e-3),
    ]
    assert entity_names(trajs) == [
        "reference",
        "mujoco-default_dt1e-04",
        "mujoco-default_dt1e-03",
        "mujoco-default_dt1e-03_2",
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


def test_inclinations_match_the_quaternion_helper():
    traj = synthetic_trajectory("reference", n_samples=50)
    np.testing.assert_allclose(inclinations(traj.quaternion), traj.inclination, rtol=1e-15)
    # and the constructed tilt: α = 0.2 sqrt(t_f − t)
    np.testing.assert_allclose(
        traj.inclination, 0.2 * np.sqrt(np.geomspace(1.0, 1e-8, 50)), rtol=1e-12
    )


def test_quaternion_xyzw_moves_w_last():
    np.testing.assert_array_equal(quaternion_xyzw(np.array([[1.0, 2, 3, 4]])), [[2.0, 3, 4, 1]])


# ----------------------------------------------------------------------------- log-log


def test_singularity_time_prefers_t_singularity_then_last_impact():
    with_sing = synthetic_trajectory("reference", t_singularity=1.75)
    assert singularity_time(with_sing).hi == 1.75
    no_sing = synthetic_trajectory("reference")
    last = no_sing.impacts[-1]
    no_sing.impacts[-1] = ImpactEvent(last.t, last.contact, last.impulse, -1, 1, t_lo=1e-20)
    tf = singularity_time(no_sing)
    assert (tf.hi, tf.lo) == (last.t, 1e-20)
    none = synthetic_trajectory("reference", n_impacts=0)
    assert singularity_time(none) is None


def test_time_to_go_keeps_the_low_parts():
    # t_f = 1 + 2^-80 (hi 1, lo 2^-80); samples t = 1 - 2^-50 + 2^-90 and 1 - 2^-90
    traj = synthetic_trajectory("reference", n_samples=2)
    traj.t = np.array([1.0 - 2.0**-50, 1.0])
    traj.t_lo = np.array([2.0**-90, -(2.0**-90)])
    tf = SingularityTime(hi=1.0, lo=2.0**-80, source="test")
    two = Fraction(2)
    exact = [two**-50 + two**-80 - two**-90, two**-80 + two**-90]
    got = time_to_go(traj, tf)
    for g, e in zip(got, exact, strict=True):
        assert abs(Fraction(float(g)) - e) <= e * Fraction(2) ** -52


def test_fit_exponent_recovers_a_power_law_and_ignores_unloggable_samples():
    tau = np.concatenate([np.geomspace(1.0, 1e-10, 40), [0.0, -1e-3]])
    energy = 0.25 * np.abs(tau) ** 2.75
    fit = fit_exponent(tau, energy)
    assert fit.c == pytest.approx(2.75, rel=1e-12)
    assert math.exp(fit.log_a) == pytest.approx(0.25, rel=1e-10)
    assert fit.n_samples == 40
    assert fit_exponent(np.array([1.0]), np.array([1.0])) is None


# ----------------------------------------------------------------------------- size, speed


@pytest.mark.slow
def test_write_time_and_size_of_a_long_three_simulator_recording(tmp_path):
    """Measurement, not an assertion on speed: 3 simulators × 100,000 samples."""
    trajs = [
        synthetic_trajectory("reference", n_samples=100_000, n_impacts=2_000, t_singularity=T_F),
        synthetic_trajectory("mujoco", n_samples=100_000, dt=1e-4, n_impacts=2_000),
        synthetic_trajectory("pybullet", n_samples=100_000, dt=1e-4, n_impacts=2_000),
    ]
    start = time.perf_counter()
    path = record_trajectories(trajs, tmp_path / "long.rrd", make_scene())
    seconds = time.perf_counter() - start
    size = path.stat().st_size
    print(f"\n3 x 100000 samples: wrote {size / 1e6:.1f} MB in {seconds:.2f} s")
    t_ns, values = temporal_column(path, "/pybullet_dt1e-04/energy/total", "Scalars:scalars")
    assert len(values) == 100_000
