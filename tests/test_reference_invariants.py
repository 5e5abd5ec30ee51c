"""Invariants of the model through flights, impacts and contact phases."""

from __future__ import annotations

import numpy as np
import pytest

from harness.scenes import resolve_scene
from reference import quaternion as qt
from reference.simulate import simulate
from tests.conftest import angular_momentum, make_scene, states_of


@pytest.mark.parametrize("name", ["pentagon-bounce", "triangle-chatter", "rod", "elastic-hexagon"])
def test_flat_ground_keeps_horizontal_momentum_and_vertical_angular_momentum(name):
    scene = resolve_scene(name)
    traj = simulate(scene)
    assert len(traj.impacts) > 10
    Y = states_of(traj)
    mass, i1 = scene.body.mass, scene.body.inertia_diag[0]
    p = mass * Y[:, 7:9]
    Lz = angular_momentum(scene, Y)[:, 2]
    scale_p = np.max(np.abs(p)) + mass * np.max(np.abs(Y[:, 9]))
    scale_L = np.max(np.abs(Lz)) + i1 * np.max(np.linalg.norm(Y[:, 10:12], axis=1))
    assert np.max(np.abs(p - p[0])) <= 1e-12 * scale_p
    assert np.max(np.abs(Lz - Lz[0])) <= 1e-12 * scale_L


def test_three_point_ground_keeps_spin_about_the_face_normal():
    scene = resolve_scene("three-point-disk")
    traj = simulate(scene)
    assert len(traj.impacts) > 10
    w3 = np.array(
        [w @ qt.body_axis(q) for w, q in zip(traj.angular_velocity, traj.quaternion, strict=True)]
    )
    scale = np.max(np.linalg.norm(traj.angular_velocity, axis=1))
    assert np.max(np.abs(w3 - w3[0])) <= 1e-12 * scale


@pytest.mark.parametrize("name", ["pentagon-bounce", "triangle-chatter", "three-point-disk"])
def test_energy_never_increases(name):
    traj = simulate(resolve_scene(name))
    E = traj.energy
    rise = np.max(np.diff(E))
    assert rise <= 1e-12 * E[0]


def test_elastic_energy_is_kept_through_impacts():
    traj = simulate(resolve_scene("elastic-hexagon"))
    assert len(traj.impacts) > 100
    E = traj.energy
    assert np.max(np.abs(E - E[0])) <= 1e-13 * E[0]


def test_elastic_energy_drift_over_10000_impacts_is_below_1e_12():
    scene = make_scene(
        n=6, gamma=1.0, t_end=1e6, max_impacts=10_000, q=(0.01, -0.004, 0.03), p=(0.03, 0.05, -0.2)
    )
    traj = simulate(scene)
    assert len(traj.impacts) == 10_000
    E = traj.energy
    assert np.max(np.abs(E - E[0])) <= 1e-12 * E[0]


def test_scaled_impact_times_keep_their_digits_deep_into_the_singularity():
    """Scaling invariance (paper §2.6): with q·ε², p·ε the scaled impact times t_k/ε of
    the full model converge to the linear model's as ε → 0, with differences O(ε²)
    (measured: they already agree to roundoff at ε = 1e-3 here).  Lost digits
    (1 − cos α, absolute time resolution) would make them scatter by ~1e-16/ε² instead,
    i.e. 1e-4 at ε = 1e-6, where α ~ 1e-14."""
    times = {}
    for eps in (1e-3, 1e-6):
        scene = make_scene(n=5, gamma=0.5, max_impacts=12, t_end=10.0).scaled(eps)
        traj = simulate(scene)
        assert len(traj.impacts) == 12
        times[eps] = np.array([(e.t + e.t_lo) / eps for e in traj.impacts])
        contacts = [e.contact for e in traj.impacts]
    assert np.max(np.abs(times[1e-3] - times[1e-6])) < 1e-12
    assert len(set(contacts)) > 1
