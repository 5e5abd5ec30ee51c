"""Metrics on hand-made Trajectory pairs whose answers are known in closed form."""

from __future__ import annotations

import math

import numpy as np
import pytest

from harness import metrics as M
from reference import quaternion as qt
from reference.trajectory import ImpactEvent, Status, Trajectory

TILT = 0.02  # rad, the synthetic body's constant inclination
SPIN = 0.5  # rad/s about the vertical


def tilted_spin(t: np.ndarray) -> np.ndarray:
    """Exact attitude of a body tilted by TILT about x and turning about z at SPIN."""
    tilt = qt.from_rotation_vector([TILT, 0.0, 0.0])
    return np.array([qt.multiply(qt.from_rotation_vector([0, 0, SPIN * s]), tilt) for s in t])


def step_energy(t: np.ndarray, impacts: list[float], levels: list[float]) -> np.ndarray:
    """Energy levels[k] between impacts k-1 and k (post-impact value at an impact time)."""
    return np.array([levels[np.searchsorted(impacts, s, side="right")] for s in t])


def make(
    t,
    impacts=(),
    contacts=None,
    energy=None,
    quaternion=None,
    dt=None,
    engine="synthetic",
    pre=None,
    post=None,
) -> Trajectory:
    t = np.asarray(t, dtype=float)
    n = len(t)
    contacts = list(contacts) if contacts is not None else [0] * len(impacts)
    pre = list(pre) if pre is not None else [-1.0] * len(impacts)
    post = list(post) if post is not None else [0.5] * len(impacts)
    events = [
        ImpactEvent(t=float(ti), contact=c, impulse=1.0, v_normal_pre=a, v_normal_post=b)
        for ti, c, a, b in zip(impacts, contacts, pre, post, strict=True)
    ]
    return Trajectory(
        engine=engine,
        scene="synthetic",
        t=t,
        position=np.zeros((n, 3)),
        quaternion=tilted_spin(t) if quaternion is None else np.asarray(quaternion),
        velocity=np.zeros((n, 3)),
        angular_velocity=np.zeros((n, 3)),
        kinetic_energy=np.ones(n) if energy is None else np.asarray(energy, dtype=float),
        potential_energy=np.zeros(n),
        impacts=events,
        status=Status.T_END,
        t_final=float(t[-1]) if n else 0.0,
        dt=dt,
    )


def tol(run: Trajectory, ref: Trajectory) -> M.MatchTolerance:
    return M.match_tolerance(run, ref, gravity=1.0)


REF_IMPACTS = [0.25, 0.5, 0.75, 1.0, 1.25, 1.5]
REF_CONTACTS = [0, 2, 4, 1, 3, 0]
LEVELS = [1.0, 0.9, 0.8, 0.7, 0.6, 0.5, 0.4]


def reference() -> Trajectory:
    """Event-driven style: a sample grid plus a pre- and a post-impact sample per impact."""
    grid = np.linspace(0.0, 2.0, 41)
    t = np.sort(np.concatenate([grid, REF_IMPACTS, REF_IMPACTS]))
    e = step_energy(t, REF_IMPACTS, LEVELS)
    for ti in REF_IMPACTS:  # first sample at an impact time is the pre-impact one
        i = np.flatnonzero(t == ti)[0]
        e[i] = LEVELS[REF_IMPACTS.index(ti)]
    return make(t, REF_IMPACTS, REF_CONTACTS, energy=e, engine="reference")


def engine_like(dt=1e-3, shift=None, contacts=REF_CONTACTS, energy_offset=0.0) -> Trajectory:
    """A fixed-step run on its own grid, exact except for the given impact shifts."""
    times = list(REF_IMPACTS)
    for i, d in (shift or {}).items():
        times[i] += d
    t = np.arange(0.0, 2.0 + dt / 2, dt)
    e = step_energy(t, times, LEVELS) + energy_offset * LEVELS[0]
    return make(t, times, contacts, energy=e, dt=dt, engine="engine")


# ----------------------------------------------------------------------------- impacts


def test_identical_trajectories_match_every_impact_with_zero_errors():
    ref = reference()
    run = reference()
    m = M.evaluate(run, ref, gravity=1.0)
    assert m.impacts_matched == len(REF_IMPACTS) == m.reference_impacts
    assert m.impact_time_error == 0.0
    assert m.energy_error == 0.0
    assert m.attitude_error == pytest.approx(0.0, abs=1e-15)
    assert m.first_divergence_time is None


def test_impact_shift_within_tolerance_is_matched_and_measured():
    run = engine_like(dt=1e-3, shift={3: 2e-3})  # window 3e-3 + 1e-2 * 1.0 = 1.3e-2
    ref = reference()
    assert M.impacts_matched(run, ref, tol(run, ref)) == 6
    assert M.impact_time_error(run, ref, tol(run, ref)) == pytest.approx(2e-3, rel=1e-9)


def test_impact_shifted_beyond_tolerance_stops_matching_there():
    ref = reference()
    window = 3 * 1e-3 + 1e-2 * REF_IMPACTS[3]
    run = engine_like(dt=1e-3, shift={3: 1.5 * window})
    m = M.match_impacts(run, ref, tol(run, ref))
    assert m.n_matched == 3
    assert m.mismatch_time == REF_IMPACTS[3]  # the earlier of the two disagreeing times
    t_div, why = M.first_divergence_time(run, ref, tol(run, ref))
    assert t_div == REF_IMPACTS[3] and "window" in why


def test_wrong_contact_stops_matching_even_at_the_right_time():
    contacts = list(REF_CONTACTS)
    contacts[2] = 3
    run = engine_like(contacts=contacts)
    ref = reference()
    assert M.impacts_matched(run, ref, tol(run, ref)) == 2


def test_missed_and_spurious_impacts_stop_matching():
    ref = reference()
    t = np.linspace(0, 2, 201)
    missed = make(t, REF_IMPACTS[:4], REF_CONTACTS[:4], dt=0.01)
    spurious = make(t, [*REF_IMPACTS, 1.8], [*REF_CONTACTS, 2], dt=0.01)
    assert M.match_impacts(missed, ref, tol(missed, ref)).n_matched == 4
    assert M.match_impacts(missed, ref, tol(missed, ref)).mismatch_time == REF_IMPACTS[4]
    assert M.match_impacts(spurious, ref, tol(spurious, ref)).n_matched == 6
    assert M.match_impacts(spurious, ref, tol(spurious, ref)).mismatch_time == 1.8


def test_run_impacts_after_the_reference_stops_are_not_spurious():
    ref = reference()
    short = make(ref.t[ref.t <= 1.6], REF_IMPACTS, REF_CONTACTS, engine="reference")
    run = make(np.linspace(0, 2, 201), [*REF_IMPACTS, 1.8], [*REF_CONTACTS, 2], dt=0.01)
    m = M.match_impacts(run, short, tol(run, short))
    assert (m.n_matched, m.mismatch_time) == (6, None)


def test_window_is_capped_at_half_the_gap_between_same_contact_impacts():
    # chatter: contact 0 at 1.0, 1.001, 1.0015; the run misses the middle impact.  Its
    # next impact (1.0015) is within 3 dt of 1.001, but closer to the reference's own
    # 1.0015, so it must not be matched to 1.001.
    ref_times = [1.0, 1.001, 1.0015]
    ref = make(np.linspace(0, 2, 2001), ref_times, engine="reference")
    run = make(np.linspace(0, 2, 2001), [1.0, 1.0015], dt=1e-3)
    windows = M.impact_windows(ref, tol(run, ref))
    assert windows == pytest.approx([0.0005, 0.00025, 0.00025])
    assert M.impacts_matched(run, ref, tol(run, ref)) == 1


CHATTER_T = [0.2, 0.6, 0.8, 0.801, 1.2]
CHATTER_C = [0, 0, 0, 0, 1]


def chatter_pair(tail_speeds: list[float], tail_in_reference: bool = True):
    """Reference and run agreeing except that one of them lists two more bounces of
    contact 0 (approach speeds `tail_speeds`) before contact 1 hits."""
    t = np.linspace(0.0, 2.0, 2001)
    full = make(t, CHATTER_T, CHATTER_C, pre=[-1.0, -0.5, *tail_speeds, -1.0], dt=1e-3)
    cut = [0, 1, 4]
    short = make(
        t,
        [CHATTER_T[i] for i in cut],
        [CHATTER_C[i] for i in cut],
        pre=[-1.0, -0.5, -1.0],
        dt=1e-3,
    )
    if tail_in_reference:
        full.dt = None
        return full, short
    short.dt = None
    return short, full


def test_slow_chatter_tail_missing_from_the_run_is_skipped_not_a_mismatch():
    ref, run = chatter_pair([-0.004, -0.002])  # below 10 g dt = 0.01
    m = M.match_impacts(run, ref, tol(run, ref))
    assert (m.n_matched, m.skipped_reference, m.skipped_run) == (3, 2, 0)
    assert m.mismatch_time is None
    assert m.pairs.tolist() == [[0, 0], [1, 1], [4, 2]]


def test_slow_chatter_tail_only_in_the_run_is_skipped_too():
    ref, run = chatter_pair([-0.004, -0.002], tail_in_reference=False)
    m = M.match_impacts(run, ref, tol(run, ref))
    assert (m.n_matched, m.skipped_reference, m.skipped_run) == (3, 0, 2)


def test_fast_bounces_are_not_a_tail_and_missing_them_is_a_mismatch():
    ref, run = chatter_pair([-0.4, -0.3])
    m = M.match_impacts(run, ref, tol(run, ref))
    assert (m.n_matched, m.skipped_reference) == (2, 0)
    assert m.mismatch_time == CHATTER_T[2]


def test_alternating_two_contact_tail_is_skipped_but_a_third_contact_is_not():
    t = np.linspace(0.0, 2.0, 2001)
    pre = [-1.0, -0.5, -0.004, -0.003, -0.002, -1.0]
    ref = make(t, [0.2, 0.6, 0.8, 0.801, 0.802, 1.2], [0, 1, 0, 1, 2, 3], pre=pre)
    run = make(t, [0.2, 0.6, 1.2], [0, 1, 3], pre=[-1.0, -0.5, -1.0], dt=1e-3)
    m = M.match_impacts(run, ref, tol(run, ref))
    # 0.8 (contact 0) and 0.801 (contact 1) are the tail of the episode that began with
    # contacts 0 and 1; 0.802 at contact 2 is new to it, however slow
    assert (m.n_matched, m.skipped_reference, m.mismatch_time) == (2, 2, 0.802)


def test_interleaved_tails_skip_the_earlier_extra_bounce_not_the_later_match():
    # both list slow bounces of contacts 4 then 3; the run has one more bounce at 4
    # before contact 3 takes over: that one is skipped, the contact-3 bounces match
    t = np.linspace(0.0, 2.0, 2001)
    ref = make(t, [0.2, 0.5, 0.9, 1.0], [4, 4, 3, 3], pre=[-1.0, -0.004, -0.003, -0.002])
    run = make(
        t, [0.2, 0.5, 0.6, 0.9, 1.0], [4, 4, 4, 3, 3], pre=[-1, -0.004, -0.002, -0.003, -0.002]
    )
    run.dt = 1e-3
    m = M.match_impacts(run, ref, tol(run, ref))
    assert m.pairs.tolist() == [[0, 0], [1, 1], [2, 3], [3, 4]]
    assert (m.skipped_reference, m.skipped_run, m.mismatch_time) == (0, 1, None)


def test_tolerance_is_three_steps_plus_one_percent_of_time():
    fixed = make([0.0, 1.0], dt=1e-4)
    event = make([0.0, 1.0])
    ref = reference()
    assert float(tol(fixed, ref).window(2.0)) == pytest.approx(3e-4 + 2e-2)
    assert float(tol(event, ref).window(2.0)) == pytest.approx(1e-9 + 2e-2)


# ----------------------------------------------------------------------------- energy


def test_energy_offset_is_measured_relative_to_initial_reference_energy():
    run = engine_like(energy_offset=0.01)
    ref = reference()
    assert M.energy_error(run, ref, tol(run, ref)) == pytest.approx(0.01, rel=1e-9)


def test_energy_is_interpolated_within_phases_not_across_impacts():
    # reference sampled on a grid only (no sample at its impact at 0.35): a naive
    # interpolation would blend 1.0 and 0.5 between 0.3 and 0.4.
    t_ref = np.linspace(0.0, 1.0, 11)
    ref = make(t_ref, [0.35], energy=step_energy(t_ref, [0.35], [1.0, 0.5]))
    t_run = np.arange(0.0, 1.0, 1e-3)
    run = make(t_run, [0.35], energy=step_energy(t_run, [0.35], [1.0, 0.5]), dt=1e-3)
    naive = np.interp(t_run, t_ref, ref.energy)
    assert np.max(np.abs(naive - run.energy)) > 0.2  # the trap is real
    assert M.energy_error(run, ref, tol(run, ref)) == 0.0


def test_energy_timing_offset_is_left_to_the_impact_time_error():
    # run's impacts 10 ms late (within tolerance): energies differ by a whole jump for
    # those 10 ms, which must not count as energy error.
    run = engine_like(dt=5e-3, shift={i: 1e-2 for i in range(6)})
    ref = reference()
    assert M.impacts_matched(run, ref, tol(run, ref)) == 6
    assert M.energy_error(run, ref, tol(run, ref)) == 0.0


def test_energy_error_counts_a_wrong_post_impact_energy():
    ref = reference()
    run = engine_like()
    e = run.kinetic_energy.copy()
    e[(run.t > 0.3) & (run.t < 0.5)] -= 0.05  # wrong energy after impact 0
    run.kinetic_energy = e
    assert M.energy_error(run, ref, tol(run, ref)) == pytest.approx(0.05, rel=1e-9)


def test_energy_error_before_divergence_excludes_what_follows_it():
    contacts = list(REF_CONTACTS)
    contacts[3] = 2  # diverges at impact 3, t = 1.0
    run = engine_like(contacts=contacts)
    e = run.kinetic_energy.copy()
    e[run.t > 1.2] += 0.2  # different motion after the divergence
    run.kinetic_energy = e
    m = M.evaluate(run, reference(), gravity=1.0)
    assert m.first_divergence_time == 1.0
    assert m.energy_error == pytest.approx(0.2, rel=1e-9)
    assert m.energy_error_agreeing == 0.0


# ----------------------------------------------------------------------------- attitude


def test_rotation_by_a_known_angle_gives_that_attitude_error():
    ref = reference()
    run = engine_like()
    axis = np.array([1.0, 2.0, -2.0]) / 3.0
    turn = qt.from_rotation_vector(0.003 * axis)
    run.quaternion = np.array([qt.multiply(q, turn) for q in run.quaternion])
    assert M.attitude_error(run, ref) == pytest.approx(0.003, rel=1e-9)


def test_attitude_error_ignores_the_quaternion_sign():
    ref = reference()
    run = engine_like()
    run.quaternion = -run.quaternion
    assert M.attitude_error(run, ref) == pytest.approx(0.0, abs=1e-15)


def test_reference_attitude_is_interpolated_exactly_for_a_steady_rotation():
    # uniform rotation about a fixed axis: slerp between coarse samples is exact
    axis = np.array([0.0, 0.6, 0.8])
    t_ref = np.linspace(0.0, 2.0, 9)
    t_run = np.linspace(0.0, 2.0, 1001)
    rot = [qt.from_rotation_vector(1.3 * s * axis) for s in t_ref]
    ref = make(t_ref, quaternion=rot)
    run = make(t_run, quaternion=[qt.from_rotation_vector(1.3 * s * axis) for s in t_run])
    assert M.attitude_error(run, ref) < 1e-14


def test_attitude_divergence_is_first_sample_above_a_tenth_of_the_tilt():
    ref = reference()
    run = engine_like(dt=1e-3)
    rate = 0.0043  # rad/s about the vertical: crosses 0.1 TILT at t = 0.4651...
    run.quaternion = np.array(
        [
            qt.multiply(qt.from_rotation_vector([0, 0, rate * s]), q)
            for s, q in zip(run.t, run.quaternion, strict=True)
        ]
    )
    threshold = M.attitude_threshold(run, ref)
    assert threshold == pytest.approx(0.1 * TILT, rel=1e-12)
    t_div, why = M.first_divergence_time(run, ref, tol(run, ref))
    expected = run.t[np.flatnonzero(rate * run.t > 0.1 * TILT)[0]]
    assert t_div == pytest.approx(expected, abs=1e-12) and "attitude" in why
    assert M.attitude_error(run, ref) == pytest.approx(rate * 2.0, rel=1e-9)


def test_largest_tilt_of_a_body_tilted_by_a_known_angle():
    ref = make([0.0, 1.0], quaternion=[qt.from_rotation_vector([0, 1e-9, 0])] * 2)
    assert M.largest_tilt(ref) == pytest.approx(1e-9, rel=1e-12)


# ----------------------------------------------------------------------------- restitution


def test_effective_restitution_from_known_velocities_skips_slow_contacts():
    t = np.linspace(0.0, 1.0, 11)
    pre = [-1.0, -0.8, -0.5, -1e-4]  # the last is below 10 g dt = 1e-3
    post = [0.5, 0.42, 0.24, 1e-4]
    run = make(t, [0.1, 0.2, 0.3, 0.4], pre=pre, post=post, dt=1e-4)
    r = M.effective_restitution(run, gravity=1.0)
    assert r.n == 3
    assert r.speed_threshold == pytest.approx(1e-2)  # 1 % of the fastest approach
    assert r.median == pytest.approx(0.5)
    assert r.range == pytest.approx((0.48, 0.525))


def test_effective_restitution_threshold_follows_gravity_and_dt():
    run = make(np.linspace(0, 1, 11), [0.1], pre=[-0.05], post=[0.04], dt=1e-2)
    r = M.effective_restitution(run, gravity=9.81)  # 10 g dt = 0.981 > 0.05
    assert (r.n, r.median, r.speed_threshold) == (0, None, pytest.approx(0.981))


# ----------------------------------------------------------------------------- edges


def test_a_run_without_samples_scores_nothing_and_does_not_raise():
    empty = make([])
    m = M.evaluate(empty, reference(), gravity=1.0)
    assert m.common_window is None
    assert (m.impacts_matched, m.energy_error, m.attitude_error) == (0, None, None)


def test_metrics_document_is_plain_json():
    import json

    doc = M.evaluate(engine_like(), reference(), gravity=1.0).to_dict()
    text = json.dumps(doc, allow_nan=False)
    assert math.isclose(json.loads(text)["time_tolerance"]["relative"], 0.01)
