"""The linearised model's building blocks (paper §2.4-2.6) against independent values."""

import math

import numpy as np
import pytest

from reference import quaternion as qt
from reference.linear.model import (
    LinearModel,
    full_states,
    impact_matrix,
    linear_state,
    polygon_points,
)
from reference.scene import initial_from_linear, scene_from_dict
from tests.oracle.body import BodyModel, initial_state


def _scene(n=5, ground="flat", q=(0.0, 0.0, 1.0), p=(0.0, 0.0, 0.0), rho=0.4, bump=0.5):
    return scene_from_dict(
        {
            "restitution": 0.5,
            "body": {"n": n, "radius": 1.0, "mass": 2.0, "gyration": rho},
            "ground": {"kind": ground, "bump_radius": bump},
            "initial": {"q": list(q), "p": list(p)},
        }
    )


@pytest.mark.parametrize("ground", ["flat", "three_point"])
def test_linear_gaps_match_full_geometry_to_second_order(ground):
    """f_kᵀq is the gap of contact k up to O(α²): the error shrinks 100× per 10× of φ."""
    rng = np.random.default_rng(1)
    direction = rng.normal(size=2)
    errs = []
    for s in (1e-2, 1e-3):
        q = (s * direction[0], s * direction[1], 3.0 * s * np.linalg.norm(direction))
        sc = _scene(ground=ground, q=q)
        gaps_full = BodyModel.from_scene(sc).contacts(initial_state(sc))[0]
        gaps_lin = LinearModel.from_scene(sc).F @ np.array(q)
        errs.append(np.max(np.abs(gaps_full - gaps_lin)))
    assert errs[0] < 2e-4 and errs[1] < errs[0] / 50


def test_impact_matrix_obeys_newton_restitution_and_momentum_balance():
    m = LinearModel.polygon(7, 0.37, 0.6)
    f, th = m.F[3], m.theta
    U = m.U(3)
    p = np.array([0.3, -0.7, -1.1])
    pp = U @ p
    assert f @ pp == pytest.approx(-0.6 * (f @ p), rel=1e-14)
    # Θ Δp is along f (an impulse along the normal at the contact)
    d = th * (pp - p)
    assert np.linalg.norm(np.cross(d, f)) < 1e-14 * np.linalg.norm(d)
    # energy lost: (1 − γ²) v² / (2 fᵀΘ⁻¹f)
    dE = 0.5 * p @ (th * p) - 0.5 * pp @ (th * pp)
    assert dE == pytest.approx((1 - 0.36) * (f @ p) ** 2 / (2 * f @ (f / th)), rel=1e-13)
    # velocities that do not move the contact (fᵀx = 0) are left alone
    x = np.cross(f, [0.3, 1.0, 0.0])
    assert np.allclose(U @ x, x, atol=1e-15)
    assert np.allclose(impact_matrix(f, th, 0.6), U)


def test_rotation_maps_contact_k_to_k_plus_1_and_conjugates_impacts():
    m = LinearModel.polygon(9, 0.3, 0.4)
    R = m.R
    for k in range(9):
        assert np.allclose(R @ m.F[k], m.F[(k + 1) % 9], atol=1e-15)
        assert np.allclose(m.U((k + 1) % 9), R @ m.U(k) @ R.T, atol=1e-14)


def test_contact_acceleration_holds_the_vertex_and_lowers_all_others():
    """η = m g / (1 + ρ⁻²) (paper), zero normal acceleration at the held vertex, every
    other vertex accelerating downwards (paper §2.5)."""
    rho, m_, g = 0.45, 2.0, 9.81
    m = LinearModel.polygon(11, rho, 0.0, gravity=g, mass=m_)
    a = m.a_contact(0)
    eta = m_ * g / (1 + rho**-2)
    assert a[2] == pytest.approx(eta / m_ - g, rel=1e-14)
    assert m.F[0] @ a == pytest.approx(0.0, abs=1e-14)
    assert np.all(m.F[1:] @ a < 0)


def test_three_point_model_uses_bump_positions_and_body_inertia():
    sc = _scene(n=64, ground="three_point", bump=0.4, rho=0.5)
    m = LinearModel.from_scene(sc)
    ang = 2 * np.pi * np.arange(3) / 3
    assert np.allclose(m.points, 0.4 * np.stack([np.cos(ang), np.sin(ang)], 1), atol=1e-15)
    assert m.inertia == pytest.approx(2.0 * 0.25)
    assert m.symmetry == 3


def test_rod_is_rank_two_and_polygon_points_are_exactly_symmetric():
    assert LinearModel.polygon(2, 0.5, 0.5).rank == 2
    assert LinearModel.polygon(5, 0.5, 0.5).rank == 3
    pts = polygon_points(4)
    assert pts[1, 0] == 0.0 and pts[2, 1] == 0.0


def test_models_on_one_polygon_share_its_contact_vectors_and_their_rank():
    """F (rows (y_k, −x_k, 1), eq. fi) and its rank depend on the points alone: formed
    once for every (ρ, γ) of a polygon, and another polygon's are its own."""
    a, b = LinearModel.polygon(6, 0.3, 0.2), LinearModel.polygon(6, 0.7, 0.9)
    assert a.F is b.F and a.rank == b.rank == 3
    ang = 2 * np.pi * np.arange(6) / 6
    assert np.allclose(a.F, np.column_stack([np.sin(ang), -np.cos(ang), np.ones(6)]), atol=1e-15)
    rod = LinearModel.polygon(2, 0.3, 0.2)
    assert rod.F is not a.F and rod.rank == 2 and rod.F.shape == (2, 3)
    assert LinearModel.polygon(6, 0.3, 0.2, radius=2.0).F is not a.F


def test_full_state_mapping_matches_the_scene_mapping():
    q, p = np.array([1e-3, -2e-3, 0.05]), np.array([0.3, 0.1, -0.2])
    y = full_states(q, p)[0]
    ini = initial_from_linear(q, p)
    assert np.allclose(y[3:7], qt.from_rotation_vector(ini.rotation_vector), atol=1e-16)
    assert np.allclose(y[0:3], ini.position) and np.allclose(y[7:10], ini.velocity)
    assert np.allclose(y[10:13], ini.angular_velocity)
    # tiny rotations keep their digits
    yt = full_states(np.array([1e-14, 0, 0]), np.zeros(3))[0]
    assert yt[4] == pytest.approx(0.5e-14, rel=1e-15)


def test_linear_state_read_off_a_full_state_scene():
    sc = scene_from_dict(
        {
            "body": {"n": 4},
            "initial": {
                "position": [0.0, 0.0, 0.1],
                "rotation_vector": [0.01, -0.02, 0.0],
                "velocity": [0.0, 0.0, -0.3],
                "angular_velocity": [0.5, 0.25, 0.0],
            },
        }
    )
    q, p = linear_state(sc)
    assert np.allclose(q, [0.01, -0.02, 0.1]) and np.allclose(p, [0.5, 0.25, -0.3])


def test_energy_is_the_quadratic_form():
    m = LinearModel.polygon(3, 0.5, 0.5, gravity=2.0, mass=3.0)
    q, p = np.array([0.1, 0.2, 0.3]), np.array([1.0, 2.0, 3.0])
    assert m.energy(q, p) == pytest.approx(0.5 * (0.75 * (1 + 4) + 3 * 9) + 3 * 2 * 0.3, rel=1e-15)
    assert math.isfinite(m.energy(q, p))
