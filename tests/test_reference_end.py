"""The end of a motion whose tilt decays below double precision's range: an explicit
singularity, never an exception (two runs of the reference exponent map reach
α ≈ 4e-296, where a division by the tilt would divide by zero)."""

import numpy as np
import pytest

from reference.options import ReferenceOptions
from reference.scene import Body, Ground, RunSettings, Scene, initial_from_linear
from reference.simulate import simulate
from reference.trajectory import Status
from tests.conftest import angular_momentum, empty_output, states_of
from tests.oracle.simulate import simulate as oracle_simulate

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
    # the energy floor off (1e-300): the tilt floor, or for γ = 0 the contacts all
    # landing, ends the run (which of the two comes first is decided by roundoff along
    # the chaotic γ = 0 run; both are the singularity; measured: all contacts down
    # at α ≈ 9e-58, so that case covers the end of the run, not the floor itself)
    traj = simulate(scene, options=ReferenceOptions(energy_floor=1e-300))
    assert traj.status is Status.SINGULARITY
    ends = ("inclination below 1e-150",) + (("all contacts down",) if gamma == 0 else ())
    assert any(end in traj.message for end in ends), traj.message
    if "inclination below" in traj.message:
        assert traj.inclination[-1] < 1e-149
    assert traj.t_singularity >= traj.t_final
    # the physics held up to the floor: finite states, energy never gained, and the
    # flat-ground invariants (horizontal momentum, vertical angular momentum) kept
    Y = states_of(traj)
    assert np.all(np.isfinite(Y)) and np.all(np.isfinite(traj.energy))
    assert np.all(np.diff(traj.energy) <= 1e-14 * abs(traj.energy[0]))
    p = Y[:, 7:9]
    Lz = angular_momentum(scene, Y)[:, 2]
    assert np.max(np.abs(p - p[0])) <= 1e-12 * (np.max(np.abs(p)) + np.max(np.abs(Y[:, 9])))
    i1 = scene.body.inertia_diag[0]
    scale_L = np.max(np.abs(Lz)) + i1 * np.max(np.linalg.norm(Y[:, 10:12], axis=1))
    assert np.max(np.abs(Lz - Lz[0])) <= 1e-12 * scale_L


def test_singularity_time_is_extrapolated_over_alternating_intervals():
    """A triangle's vertices take turns: its intervals alternate (A qʲ, B qʲ), so single
    ratios swing about 1 while pairs shrink by q.  The extrapolated t_f is the sum of the
    whole geometric series, t_0 + (A + B)/(1 − q)."""
    from collections import namedtuple

    from reference.core.loop import extrapolate_singularity
    from reference.core.records import N_IMPACTS

    A, B, q, n = 1e-3, 1.3e-3, 0.7, 13
    tau = [(A if k % 2 == 0 else B) * q ** (k // 2) for k in range(n - 1)]
    t = np.concatenate([[0.5], 0.5 + np.cumsum(tau)])
    impacts = np.zeros((n, 6))
    impacts[:, 0] = t
    counts = np.zeros(8, dtype=np.int64)
    counts[N_IMPACTS] = n
    out = namedtuple("Out", "counts impacts")(counts, impacts)
    t_f = extrapolate_singularity(out, t[-1])
    assert t_f == pytest.approx(0.5 + (A + B) / (1 - q), rel=0, abs=1e-14)


def test_released_contacts_whose_gaps_still_fall_land_and_the_run_ends():
    """A fast-spinning 16-gon (γ = 0.5) ends with several vertices down: after a
    chatter completion the LCP releases contacts at zero gap, rate and acceleration
    whose gaps still fall (the spin's jerk; a tie the acceleration-level LCP cannot
    see), so the chunk's crossing is located below the clock's resolution.  They land
    (held with the others) and the run reaches the end of the motion, not zero-length
    chunks for ever.  How it ends there (vertices held: singularity, or the
    last ones landing together: simultaneous) is decided at roundoff.  The independent
    oracle gives the same impacts and the same end time (measured: its 764 impact times
    within 1.1e-8 of the reference's, the separation of two chaotic runs); energy never
    rose and no vertex went below the ground beyond roundoff."""
    from reference.scene import scene_from_dict

    scene = scene_from_dict(
        {
            "restitution": 0.5,
            "body": {"n": 16, "gyration": 0.5},
            "initial": {
                "position": [0.0, 0.0, np.sin(0.02) + 0.01],
                "rotation_vector": [0.02, 0.0, 0.0],
                "velocity": [0.0, 0.0, -0.1],
                "angular_velocity": [0.0, 0.3, 20.0],
            },
            "run": {"t_end": 1e4, "max_impacts": 20_000},
        }
    )
    traj = simulate(scene, options=ReferenceOptions(sample_dt=1e4))
    assert traj.status in (Status.SINGULARITY, Status.SIMULTANEOUS_IMPACT), traj.message
    truth = oracle_simulate(scene)
    assert len(traj.impacts) == len(truth.impacts)
    assert np.max(np.abs(traj.impact_times() - truth.impact_times())) <= 1e-7
    assert abs(traj.t_final - truth.t_final) <= 1e-7
    assert traj.stats.loop_steps < 5 * len(traj.impacts)
    assert np.all(np.diff(traj.energy) <= 1e-12 * abs(traj.energy[0]))
    assert traj.stats.max_penetration <= 1e-15  # roundoff of a = 1


def test_a_loop_that_stops_advancing_is_ended_by_the_stall_guard():
    """loop._stalled: MAX_STALL_STEPS steps in a row with the same time and event count
    end the run; a step that advances time, or records an event, starts the count again."""
    from reference.core import records as R
    from reference.core.loop import _stalled
    from reference.core.tolerances import MAX_STALL_STEPS
    from reference.simulate import initial_record

    state = initial_record(np.zeros(13))
    out = empty_output()
    counts = out.counts
    state["t_hi"] = 1.0
    assert not _stalled(state[0], out)  # a new time: the count starts
    assert not any(_stalled(state[0], out) for _ in range(MAX_STALL_STEPS))
    counts[R.N_IMPACTS] += 1  # an event: the count starts again
    assert not any(_stalled(state[0], out) for _ in range(MAX_STALL_STEPS + 1))
    assert _stalled(state[0], out)
