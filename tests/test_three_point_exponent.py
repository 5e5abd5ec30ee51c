"""The energy exponent on the three-point ground: the level the motion
ends at, the time it ends, and c of the paper's three-bump model (section 4.3)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from reference import ReferenceOptions, simulate
from reference.exponent import excess_energy_of, trajectory_exponent
from reference.geometry import excess_energy, resting_energy
from reference.quaternion import from_rotation_vector
from reference.scene import Body, Ground, RunSettings, Scene, initial_from_linear
from tests.conftest import make_scene
from tests.oracle.quaternion import to_matrix as oracle_rotation


def _three_point_excess_by_hand(scene, y):
    """E − ½ m |v_h|² − ½ I3 ω3² from the world inertia matrix R diag(I1, I1, I3) Rᵀ."""
    m, g = scene.body.mass, scene.gravity
    i1, _, i3 = scene.body.inertia_diag
    R = oracle_rotation(y[3:7])
    inertia = R @ np.diag([i1, i1, i3]) @ R.T
    v, w = y[7:10], y[10:13]
    energy = 0.5 * m * v @ v + 0.5 * w @ inertia @ w + m * g * y[2]
    w3 = w @ R[:, 2]
    return energy - 0.5 * m * (v[0] ** 2 + v[1] ** 2) - 0.5 * i3 * w3**2


def test_three_point_excess_is_the_energy_of_the_tilt_and_the_height():
    """Random tilted, sliding, spinning states: the excess is the energy less what the
    flat disk keeps when it lies on the bumps (its horizontal velocity and spin)."""
    scene = make_scene(n=3, ground="three_point", rho=0.5, bump=0.5)
    rng = np.random.default_rng(7)
    states = np.zeros((50, 13))
    for y in states:
        y[0:3] = rng.normal(0, 1e-2, 3)
        y[3:7] = from_rotation_vector(rng.normal(0, 0.05, 3))
        y[7:10] = rng.normal(0, 1.0, 3)
        y[10:13] = rng.normal(0, 3.0, 3)
    expected = np.array([_three_point_excess_by_hand(scene, y) for y in states])
    got = excess_energy(scene, states)
    assert np.allclose(got, expected, rtol=1e-12, atol=1e-14 * np.abs(expected).max())


def test_a_flat_disk_sliding_and_spinning_on_the_bumps_is_at_rest():
    """Flat on the bumps (z = 0, e3 = ẑ), moving horizontally at 0.4 and spinning at 3:
    nothing is left to dissipate; its resting energy is ½ m |v_h|² + ½ I3 ω3² (by hand:
    m = 1, I3 = 2 m (ρ a)² = 0.5 for ρ = 0.5)."""
    scene = make_scene(n=3, ground="three_point", rho=0.5, bump=0.5)
    y = np.zeros(13)
    y[3] = 1.0
    y[7:9] = (0.24, -0.32)
    y[12] = 3.0
    assert excess_energy(scene, y[None])[0] == 0.0
    assert resting_energy(scene, y[None])[0] == pytest.approx(0.5 * 0.4**2 + 0.5 * 0.5 * 9.0)


GAMMAS = (0.2, 0.4, 0.6, 0.8)  # the study's --restitution 0.2:0.8:4


def _benchmark_scene(gamma: float, sample: int) -> Scene:
    """A run of benchmarks/law_exponents.py (seed 0, b = 0.5 a): the sweep's χ in the
    three-point-disk scale, q = (0.01 χ3, 0.01 χ4, 0.02), p = (0.05 χ1, 0.05 χ2, −0.05)."""
    from harness.sweep.grid import chi

    x = chi(0, GAMMAS.index(gamma), 0, sample)
    q0, p0 = (0.01 * x[2], 0.01 * x[3], 0.02), (0.05 * x[0], 0.05 * x[1], -0.05)
    return Scene(
        name="three-point-study",
        body=Body(n=3, gyration=0.5),
        ground=Ground(kind="three_point", bump_radius=0.5),
        initial=initial_from_linear(q0, p0),
        restitution=gamma,
        gravity=1.0,
        run=RunSettings(t_end=200.0, max_impacts=20000),
    )


def test_a_completed_chatter_that_lays_the_disk_down_ends_at_its_accumulation_time():
    """The run ends 'all contacts down' when the chatter of the third bump beside two
    held ones is completed: t_singularity is that chatter's accumulation time, after the
    impact that began it, and agrees with the run that resolves the bounces one by one
    (chatter_tol = 0) to a small part of the skipped series' duration."""
    scene = _benchmark_scene(0.8, 0)
    completed = simulate(scene, options=ReferenceOptions(chatter_tol=1e-7))
    # strictly sequential: its bounces come closer than the default window
    strict = ReferenceOptions(chatter_tol=0.0, simultaneity_window=0.0)
    one_by_one = simulate(scene, options=strict)
    assert completed.message.startswith("all contacts down")
    t_last = completed.impacts[-1].t
    assert completed.t_singularity == completed.stats["chatter_accumulation_times"][-1]
    skipped = one_by_one.t_singularity - t_last
    assert skipped > 1e-9
    assert abs(completed.t_singularity - one_by_one.t_singularity) < 0.1 * skipped


@pytest.mark.parametrize("gamma", [0.2, 0.8])
@pytest.mark.parametrize("law", ["paper", "moreau"])
def test_the_three_point_ground_gives_the_exponent_two(gamma, law):
    """ρ = 0.5 on bumps at b = 0.5 a (the paper's triangle with ρ a/b = 1, outside the
    complete-chatter region, where gravity stays significant): c = 2 (paper, appendix
    A), fitted over at least 6 decades of energy."""
    scene = _benchmark_scene(gamma, 1)
    traj = simulate(scene, options=ReferenceOptions(sample_dt=200.0, impact_law=law))
    fit = trajectory_exponent(traj, energy=excess_energy_of(traj, scene))
    assert traj.status.value == "singularity"
    assert fit.fit_decades >= 6
    assert fit.c == pytest.approx(2.0, abs=0.05)
    assert math.isfinite(fit.c_stderr)


def test_an_elastic_disk_sliding_off_the_bumps_does_not_end_at_the_singularity():
    """γ = 1 keeps the energy, so the motion has no end: the tumbling disk slides off
    the bumps (`left_model`).  On its way its centre passes beyond the bumps' triangle,
    where the excess (the energy of the tilt and the height) is negative; that is not
    an exhausted energy."""
    from reference.scene import scene_from_dict

    scene = scene_from_dict(
        {
            "restitution": 1.0,
            "body": {"n": 3, "gyration": 0.45},
            "ground": {"kind": "three_point", "bump_radius": 0.5, "floor_depth": math.inf},
            "initial": {"q": [0.012, -0.007, 0.05], "p": [0.2, -0.15, -0.5]},
            "run": {"t_end": 1e4, "max_impacts": 20_000},
        }
    )
    traj = simulate(scene)
    assert traj.status.value == "left_model"
    assert excess_energy_of(traj, scene).min() < 0
