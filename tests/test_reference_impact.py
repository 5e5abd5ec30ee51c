"""Single-point Newtonian impacts: the law, the momenta and the energy."""

from __future__ import annotations

import numpy as np
import pytest

from reference import quaternion as qt
from reference.body import BodyModel
from reference.impact import impact_impulse
from tests.conftest import make_scene


def _state_on_vertex(model, k=0):
    y = np.zeros(13)
    y[3:7] = qt.from_rotation_vector([0.05, -0.08, 0.3])
    y[7:10] = [0.1, -0.2, -0.9]
    y[10:13] = [0.4, 0.3, 1.2]
    gap = model.contacts(y)[0]
    y[2] = -(gap[k] - y[2])
    return y


@pytest.mark.parametrize("gamma", [0.0, 0.3, 0.5, 1.0])
@pytest.mark.parametrize("ground", ["flat", "three_point"])
def test_post_impact_normal_velocity_is_minus_gamma_times_pre(gamma, ground):
    model = BodyModel.from_scene(make_scene(n=6, gamma=gamma, ground=ground))
    y = _state_on_vertex(model, 1)
    res = impact_impulse(model, y, 1, gamma)
    assert res.u_pre < 0
    assert abs(res.u_post + gamma * res.u_pre) < 4e-16 * abs(res.u_pre)
    # independent check of the post-impact normal velocity from the new state
    vn = model.contacts(res.y_post)[3][1]
    assert abs(vn + gamma * res.u_pre) < 4e-16 * abs(res.u_pre)


@pytest.mark.parametrize("gamma", [0.0, 0.5, 1.0])
def test_impact_keeps_horizontal_momentum_and_vertical_angular_momentum(gamma):
    model = BodyModel.from_scene(make_scene(n=5, gamma=gamma))
    y = _state_on_vertex(model, 2)
    res = impact_impulse(model, y, 2, gamma)
    p0, p1 = model.mass * y[7:9], model.mass * res.y_post[7:9]
    assert np.max(np.abs(p1 - p0)) <= 1e-15 * np.linalg.norm(p0)
    Lz0 = model.angular_momentum(y)[2]
    Lz1 = model.angular_momentum(res.y_post)[2]
    assert abs(Lz1 - Lz0) <= 1e-14 * abs(Lz0)


def test_impact_on_three_point_keeps_spin_about_the_face_normal():
    model = BodyModel.from_scene(make_scene(ground="three_point", gamma=0.5))
    y = _state_on_vertex(model, 0)
    res = impact_impulse(model, y, 0, 0.5)
    w3 = lambda yy: yy[10:13] @ qt.body_axis(yy[3:7])  # noqa: E731
    assert abs(w3(res.y_post) - w3(y)) < 1e-15 * abs(w3(y))


@pytest.mark.parametrize("gamma", [0.0, 0.4, 0.9])
def test_impact_energy_loss_matches_restitution(gamma):
    """ΔE = −½ (1 − γ²) u⁻² / (J M⁻¹ Jᵀ): elastic keeps energy, plastic loses the most."""
    model = BodyModel.from_scene(make_scene(n=4, gamma=gamma))
    y = _state_on_vertex(model, 3)
    res = impact_impulse(model, y, 3, gamma)
    w_eff = -(1 + gamma) * res.u_pre / res.impulse  # J M⁻¹ Jᵀ
    expect = -0.5 * (1 - gamma**2) * res.u_pre**2 / w_eff
    dE = model.energy(res.y_post) - model.energy(y)
    assert abs(dE - expect) < 1e-14 * model.energy(y)
