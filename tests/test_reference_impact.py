"""Single-point Newtonian impacts (reference.core.impact): the law, the momenta and the
energy, checked on states with one contact at the ground."""

from __future__ import annotations

import numpy as np
import pytest

from reference import quaternion as qt
from reference.core.impact import impact
from reference.geometry import energies, scene_contact_kinematics
from tests.conftest import core_model, make_scene, tilted_spinning_state


def _state_on_contact(scene, k):
    y = tilted_spinning_state()
    gap = scene_contact_kinematics(scene, y)[0][0]
    y[2] -= gap[k]
    return y


def _impact(scene, k):
    model, pts = core_model(scene)
    y = _state_on_contact(scene, k)
    y_post = y.copy()
    return y, y_post, impact(y_post, model, pts, k)


def _energy(scene, y):
    ke, pe = energies(scene, y)
    return float(ke[0] + pe[0])


def _momentum(scene, y):
    """Linear momentum and angular momentum about the centre of mass (world frame)."""
    i1, _, i3 = scene.body.inertia_diag
    e3 = qt.body_axis(y[3:7])
    w = y[10:13]
    return scene.body.mass * y[7:10], i1 * w + (i3 - i1) * (w @ e3) * e3


@pytest.mark.parametrize("gamma", [0.0, 0.3, 0.5, 1.0])
@pytest.mark.parametrize("ground", ["flat", "three_point"])
def test_post_impact_normal_velocity_is_minus_gamma_times_pre(gamma, ground):
    scene = make_scene(n=6, gamma=gamma, ground=ground)
    _, y_post, res = _impact(scene, 1)
    assert res.u_pre < 0
    assert abs(res.u_post + gamma * res.u_pre) < 4e-16 * abs(res.u_pre)
    # independently: the post-impact normal velocity of the new state
    vn = scene_contact_kinematics(scene, y_post)[1][0, 1]
    assert abs(vn + gamma * res.u_pre) < 4e-16 * abs(res.u_pre)


@pytest.mark.parametrize("gamma", [0.0, 0.5, 1.0])
def test_impact_keeps_horizontal_momentum_and_vertical_angular_momentum(gamma):
    scene = make_scene(n=5, gamma=gamma)
    y, y_post, _ = _impact(scene, 2)
    p0, L0 = _momentum(scene, y)
    p1, L1 = _momentum(scene, y_post)
    assert np.max(np.abs(p1[:2] - p0[:2])) <= 1e-15 * np.linalg.norm(p0)
    assert abs(L1[2] - L0[2]) <= 1e-14 * abs(L0[2])


def test_impact_on_three_point_keeps_spin_about_the_face_normal():
    scene = make_scene(ground="three_point", gamma=0.5)
    y, y_post, _ = _impact(scene, 0)

    def w3(yy):
        return yy[10:13] @ qt.body_axis(yy[3:7])

    assert abs(w3(y_post) - w3(y)) < 1e-15 * abs(w3(y))


@pytest.mark.parametrize("gamma", [0.0, 0.4, 0.9])
def test_impact_energy_loss_matches_restitution(gamma):
    """ΔE = −½ (1 − γ²) u⁻² / (J M⁻¹ Jᵀ): elastic keeps energy, plastic loses the most."""
    scene = make_scene(n=4, gamma=gamma)
    y, y_post, res = _impact(scene, 3)
    w_eff = -(1 + gamma) * res.u_pre / res.impulse  # J M⁻¹ Jᵀ
    expect = -0.5 * (1 - gamma**2) * res.u_pre**2 / w_eff
    assert abs(_energy(scene, y_post) - _energy(scene, y) - expect) < 1e-14 * _energy(scene, y)


def test_impulse_is_the_papers_closed_form():
    """ζ = −(1 + γ) u⁻ / (1/m + (r × e_z)·I⁻¹(r × e_z)) (paper eq. F), with the inverse
    inertia formed here from the body axis, independently of the core."""
    scene = make_scene(n=5, gamma=0.7)
    y, _, res = _impact(scene, 2)
    i1, _, i3 = scene.body.inertia_diag
    e3 = qt.body_axis(y[3:7])
    Iinv = np.eye(3) / i1 + (1 / i3 - 1 / i1) * np.outer(e3, e3)
    ang = 2 * np.pi * 2 / 5
    r = qt.rotate(y[3:7], [np.cos(ang), np.sin(ang), 0.0])
    c = np.cross(r, [0.0, 0.0, 1.0])
    zeta = -(1 + 0.7) * res.u_pre / (1 / scene.body.mass + c @ Iinv @ c)
    assert abs(res.impulse - zeta) < 1e-14 * abs(zeta)
