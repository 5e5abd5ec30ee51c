"""Drake adapter: state conventions against Drake's own kinematics, exact point-contact
geometry, the two restitution maps (Hunt & Crossley, SAP's step map) against Drake, first
impacts, static loads on three bumps, and both profiles through the registry."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tests.conftest import require_extra

require_extra("pydrake", "drake")

from engines import drake as dk  # noqa: E402
from engines.base import contact_kinematics, effective_contact_mass  # noqa: E402
from harness.restitution.drops import drop_scene, watched_point  # noqa: E402
from harness.restitution.impact import read_impact  # noqa: E402
from reference import quaternion as qt  # noqa: E402
from reference.geometry import initial_state  # noqa: E402
from tests.conftest import make_scene  # noqa: E402

SPINNING = np.concatenate(
    [[0.1, -0.2, 0.9], qt.from_rotation_vector([0.3, -0.5, 1.1]), [0.2, 0.1, -0.3]]
    + [[0.7, -0.4, 1.3]]
)


def _in_drake(scene, y):
    settings = dk.contact_settings(scene, 1e-4, "sap")
    model = dk.build_model(scene, settings)
    context = model.diagram.CreateDefaultContext()
    pc = model.plant.GetMyMutableContextFromRoot(context)
    model.plant.SetPositionsAndVelocities(pc, dk.to_drake_state(y))
    return model, pc


def _states(traj):
    return np.column_stack([traj.position, traj.quaternion, traj.velocity, traj.angular_velocity])


# ------------------------------------------------------------------ state conventions
def test_state_set_in_drake_reads_back_from_drakes_world_frame_kinematics():
    scene = make_scene(state=SPINNING)
    model, pc = _in_drake(scene, SPINNING)
    np.testing.assert_allclose(dk.state_from_kinematics(model, pc), SPINNING, atol=1e-12)
    x = model.plant.GetPositionsAndVelocities(pc)
    np.testing.assert_allclose(dk.from_drake_state(x), SPINNING, rtol=0, atol=0)


def test_drake_stores_angular_velocity_in_the_world_frame_quaternion_first():
    scene = make_scene(state=SPINNING)
    model, pc = _in_drake(scene, SPINNING)
    x = model.plant.GetPositionsAndVelocities(pc)
    np.testing.assert_array_equal(x[0:4], SPINNING[3:7])  # (qw, qx, qy, qz) first
    np.testing.assert_array_equal(x[7:10], SPINNING[10:13])  # ω in W, not R^T ω
    assert not np.allclose(x[7:10], qt.rotate(qt.conjugate(SPINNING[3:7]), SPINNING[10:13]))


def test_free_flight_in_drake_keeps_the_spin_and_falls_under_gravity():
    """No contact for 0.2 s: the centre falls as a parabola and |L| is constant."""
    y0 = SPINNING.copy()
    y0[2] = 5.0
    scene = make_scene(state=y0, t_end=0.2)
    traj = dk.simulate_drake(scene, 1e-3, profile="continuous")
    y = _states(traj)[-1]
    t = traj.t[-1]
    np.testing.assert_allclose(y[0:3], y0[0:3] + t * y0[7:10] - [0, 0, 0.5 * t * t], atol=1e-6)
    assert not traj.impacts


# ------------------------------------------------------------------ geometry
@pytest.mark.parametrize("kind", ["flat", "three_point"])
def test_drake_signed_distances_are_the_reference_gaps(kind):
    """Tilted body slightly into the ground: Drake's point pairs have depth = −gap."""
    y = np.zeros(13)
    y[3:7] = qt.from_rotation_vector([0.02, -0.01, 0.0])
    scene = make_scene(state=y, ground=kind)
    gaps = contact_kinematics(scene, y[None])[0][0]
    y[2] -= gaps.min() + 1e-4  # the lowest point 1e-4 deep
    gaps = contact_kinematics(scene, y[None])[0][0]
    model, pc = _in_drake(scene, y)
    query = model.plant.get_geometry_query_input_port().Eval(pc)
    depth = {}
    for pair in query.ComputePointPairPenetration():
        k = model.contact_of.get(pair.id_A, model.contact_of.get(pair.id_B))
        depth[k] = pair.depth
    assert depth, "no contact reported"
    for k, d in depth.items():
        assert abs(d + gaps[k]) < 1e-12


# ------------------------------------------------------------------ restitution maps
@pytest.mark.parametrize("gamma", [0.3, 0.8])
def test_hunt_crossley_bounce_at_the_typical_speed_is_gamma(gamma):
    """Continuous profile, free vertex impact at the speed d was chosen for: e = γ within
    the gravity impulse of one contact (T = 1e-3) against that speed (0.5 %)."""
    u = dk.hc_speed_factor(gamma)
    assert abs(dk.hc_restitution(u) - gamma) < 1e-12
    v = 1.0
    scene = drop_scene("vertex", gamma, v, 0.002 / v, 0.02)
    settings = dk.contact_settings(scene, 1e-4, "continuous")
    import dataclasses

    settings = dataclasses.replace(settings, hc_dissipation=u / v, accuracy=1e-7)
    e = _bounce(scene, dk.run_with_settings(scene, settings))
    assert abs(e - gamma) < 5e-3 * max(1.0, gamma / 0.3)


def _bounce(scene, traj) -> float:
    """e_eff of the drop's vertex 0 (the restitution study's reading)."""
    reading = read_impact(scene, traj, *watched_point("vertex"))
    assert reading.outcome == "ok"
    return reading.e_eff


def test_hunt_crossley_small_dissipation_gives_the_linear_limit():
    """e ≈ 1 − 2u/3 for small u (the series of u(1 + e) = ln(1 + u) − ln(1 − e u))."""
    for u in (1e-3, 1e-2):
        assert abs(dk.hc_restitution(u) - (1 - 2 * u / 3)) < u * u


@pytest.mark.parametrize("gamma", [0.5, 0.8])
def test_sap_single_vertex_bounce_is_gamma_within_three_percent(gamma):
    """The step map hits γ at the middle onset phase; other phases spread e by ±1.3 % at
    γ = 0.5 (N = 28 steps) and the gravity impulse over the contact, g N h, is 1 % of
    the approach speed 0.3."""
    scene = drop_scene("vertex", gamma, 0.3, 0.002 / 0.3, 0.05)
    e = _bounce(scene, dk.simulate_drake(scene, 1e-4, profile="sap"))
    assert abs(e - gamma) < 0.03 * gamma


def test_sap_step_map_without_damping_loses_the_implicit_steps_energy():
    """τ = 0: e_max(N) ≈ exp(−π²/(2N)) (implicit Euler's damping of the contact
    oscillator), and the bisection hits γ at the middle phase."""
    for n in (20, 80):
        assert abs(dk.sap_bounce(n, 0.0) - math.exp(-(math.pi**2) / (2 * n))) < 0.02
    tau = dk.sap_relaxation_time(0.8, 88.0)
    assert abs(dk.sap_bounce(88.0, tau) - 0.8) < 1e-9


def test_sap_stiffness_resolves_the_contact_in_its_step_count():
    scene = make_scene(gamma=0.8)
    s = dk.contact_settings(scene, 1e-4, "sap")
    period = math.pi * math.sqrt(effective_contact_mass(scene) / s.stiffness)
    assert abs(period / 1e-4 - s.contact_steps) < 1e-9


# ------------------------------------------------------------------ runs
@pytest.mark.parametrize("profile", dk.PROFILES)
def test_first_sample_is_the_initial_state_and_first_impact_the_lowest_vertex(profile):
    scene = make_scene(gamma=0.5, t_end=0.4)
    traj = dk.simulate_drake(scene, 1e-4, profile=profile)
    np.testing.assert_allclose(_states(traj)[0], initial_state(scene.initial), atol=1e-12)
    from reference.simulate import simulate

    ref = simulate(scene, t_end=0.4)
    assert traj.impacts[0].contact == ref.impacts[0].contact
    assert abs(traj.impacts[0].t - ref.impacts[0].t) < 5e-4


@pytest.mark.parametrize("profile", dk.PROFILES)
def test_disk_resting_on_three_bumps_carries_a_third_of_its_weight_on_each(profile):
    y = np.zeros(13)
    y[3] = 1.0
    scene = make_scene(state=y, ground="three_point", gamma=0.0, t_end=0.3)
    traj = dk.simulate_drake(scene, 1e-4, profile=profile)
    assert traj.status.value == "t_end", traj.message
    model, pc = _in_drake(scene, _states(traj)[-1])
    # the model's loads at the final state: stiffness × depth
    loads = np.array(
        [-g * traj.stats["stiffness"] for g in contact_kinematics(scene, _states(traj)[-1:])[0][0]]
    )
    np.testing.assert_allclose(loads, scene.body.mass * scene.gravity / 3, rtol=0.02)


def test_max_impacts_stops_the_run_with_its_status():
    scene = make_scene(gamma=0.5, t_end=1.0, max_impacts=2)
    traj = dk.simulate_drake(scene, 1e-3, profile="sap")
    assert traj.status.value == "max_impacts" and len(traj.impacts) == 2
    assert traj.t_final < 1.0


def test_both_profiles_run_through_the_registry():
    from harness.simulators import is_fixed_step, run_simulator

    scene = make_scene(t_end=0.3)
    for name in ("drake", "drake-continuous"):
        assert is_fixed_step(name)
        traj = run_simulator(name, scene, dt=1e-3)
        assert traj.engine == name and traj.dt == 1e-3 and traj.impacts


# ------------------------------------------------------------------ quaternion norm
def test_discrete_drake_quaternion_drift_is_drakes_and_the_run_reads_its_rotation():
    """Drake's discrete update q + h N(q) v does not keep |q| = 1: each step multiplies
    |q| by sqrt(1 + (h|ω|/2)²) exactly (N(q)v = ½ ω⊗q is orthogonal to q).  The adapter
    reads the rotation Drake uses (q/|q|): the run is not cut by the guard, and the drift
    is recorded."""
    from harness.simulators import run_simulator
    from harness.stress.cases import fast_spin_scene

    h, steps = 1e-4, 50
    scene = fast_spin_scene().with_run(t_end=steps * h)  # ω = 100 rad/s, no contact yet
    traj = run_simulator("drake", scene, dt=h)
    assert traj.status.value == "t_end", traj.message
    norms = np.linalg.norm(traj.quaternion, axis=1)
    np.testing.assert_allclose(norms, 1.0, rtol=0, atol=1e-15)
    omega = np.linalg.norm(traj.angular_velocity[0])
    expected = (1 + (h * omega / 2) ** 2) ** (steps / 2) - 1
    assert traj.stats["quaternion_norm_drift"] == pytest.approx(expected, rel=1e-3)
