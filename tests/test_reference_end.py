"""The end of a motion whose tilt decays below double precision's range: an explicit
singularity, never an exception (two runs of the reference exponent map that used to
divide by zero at α ≈ 4e-296)."""

import math

import pytest

from reference.scene import Body, Ground, RunSettings, Scene, initial_from_linear
from reference.simulate import simulate
from reference.trajectory import Status

CASES = {  # (ρ, γ, q0, p0) of the sweep (n = 3, a = m = g = 1)
    "rho0.15-gamma0.1": (
        0.15,
        0.1,
        (-0.00037738022408078433, 6.0774436562210045e-05, 1.0),
        (0.03851882535101042, 0.036999224022998135, -1.0),
    ),
    "rho0.9-gamma0": (
        0.9,
        0.0,
        (0.00014769545508176574, 1.368833984092055e-05, 1.0),
        (-0.025909563290190875, -0.01579313470223852, -1.0),
    ),
}


@pytest.mark.parametrize("name", sorted(CASES))
def test_a_tilt_decaying_below_the_floor_ends_at_the_singularity(name):
    rho, gamma, q0, p0 = CASES[name]
    scene = Scene(
        name=name,
        body=Body(n=3, gyration=rho),
        ground=Ground(),
        initial=initial_from_linear(q0, p0),
        restitution=gamma,
        gravity=1.0,
        run=RunSettings(t_end=200.0, max_impacts=20000),
    )
    traj = simulate(scene)
    assert traj.status is Status.SINGULARITY
    assert "inclination below 1e-150" in traj.message
    assert traj.inclination[-1] < 1e-149  # the last sample is at the floor
    assert traj.t_singularity >= traj.t_final
    assert all(math.isfinite(x) for x in traj.energy)
