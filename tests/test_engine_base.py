"""Shared engine machinery: vectorised kinematics equal the reference's geometry, and
impacts derived from contact activity on a hand-made impulse record."""

from __future__ import annotations

import numpy as np
import pytest

from engines.base import contact_kinematics, energies, impacts_from_contact_activity
from reference import quaternion as qt
from tests.conftest import make_scene
from tests.oracle.body import BodyModel


@pytest.mark.parametrize("ground", ["flat", "three_point"])
def test_vectorised_kinematics_and_energies_equal_the_reference_geometry(ground):
    scene = make_scene(n=7, ground=ground)
    model = BodyModel.from_scene(scene)
    rng = np.random.default_rng(1)
    states = []
    for _ in range(20):
        y = np.zeros(13)
        y[0:3] = rng.normal(size=3) * [0.1, 0.1, 0.05] + [0, 0, 0.1]
        y[3:7] = qt.from_rotation_vector(rng.normal(size=3) * 0.2)
        y[7:13] = rng.normal(size=6)
        states.append(y)
    states = np.array(states)
    gaps, vns = contact_kinematics(scene, states)
    ke, pe = energies(scene, states)
    for i, y in enumerate(states):
        g, _, _, vn, _ = model.contacts(y)
        assert np.allclose(gaps[i], g, rtol=0, atol=1e-15)
        assert np.allclose(vns[i], vn, rtol=0, atol=1e-14)
        assert abs(ke[i] - model.kinetic_energy(y)) < 1e-14
        assert abs(pe[i] - model.potential_energy(y)) < 1e-15


def test_one_bounce_becomes_one_impact_with_its_velocities_and_impulse():
    """A point falling at 1, hitting at t = 0.25 between rows, bouncing at 0.5."""
    t = np.arange(0, 1.0, 0.1)
    gap = 0.25 - t  # crosses zero at t = 0.25
    vn = np.full_like(t, -1.0)
    imp = np.zeros_like(t)
    gap[3] = 0.25 - t[3]  # seen penetrating at the onset row (-0.05)
    gap[4:] = gap[3] + 0.5 * (t[4:] - t[3])
    vn[3:] = 0.5
    imp[3] = 1.5
    events = impacts_from_contact_activity(t, imp[:, None], gap[:, None], vn[:, None])
    assert len(events) == 1
    e = events[0]
    assert abs(e.t - 0.25) < 1e-12
    assert e.v_normal_pre == -1.0 and e.v_normal_post == 0.5 and e.impulse == 1.5
