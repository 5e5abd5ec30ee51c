"""The transition study (harness transition): regimes from the contact kinds
that act, their figures on a MuJoCo run of the short rolling scene, the takeover tilt
against the face's geometric reach, and the command's refusals."""

from __future__ import annotations

import numpy as np
import pytest

from engines.mujoco import simulate_mujoco
from harness.cli import main
from harness.transition.regimes import (
    BUMPS_ONLY,
    MIXED,
    RIM_ONLY,
    Activity,
    classify,
    regime_spans,
    takeover,
    tilt,
)
from harness.transition.scene import transition_scene
from harness.transition.study import transition_document
from reference import quaternion as qt


def act(rim, bump):
    return Activity(rim=np.array(rim, dtype=float), bump=np.array(bump, dtype=float))


def test_a_run_where_no_bump_acts_is_rim_only():
    assert regime_spans(act([0.1, 0.2], []), 0.0, 1.0) == [(RIM_ONLY, 0.0, 1.0)]


def test_regimes_split_at_the_first_bump_and_the_last_rim_contact():
    spans = regime_spans(act([0.1, 0.5, 0.7], [0.4, 0.8, 0.9]), 0.0, 1.0)
    assert spans == [(RIM_ONLY, 0.0, 0.4), (MIXED, 0.4, 0.7), (BUMPS_ONLY, 0.7, 1.0)]


def test_a_run_on_the_bumps_from_the_start_is_bumps_only():
    assert regime_spans(act([], [0.0, 0.3]), 0.0, 1.0) == [(BUMPS_ONLY, 0.0, 1.0)]


def test_tilt_is_the_angle_of_the_axis_from_the_vertical():
    y = np.zeros((2, 13))
    y[0, 3:7] = qt.from_rotation_vector(np.array([0.3, -0.4, 0.2]))
    y[1, 3:7] = qt.from_rotation_vector(np.array([1e-12, 0.0, 5.0]))
    e3z = [qt.body_axis(q)[2] for q in y[:, 3:7]]
    assert tilt(y)[0] == pytest.approx(np.arccos(e3z[0]), rel=1e-12)
    assert tilt(y)[1] == pytest.approx(1e-12, rel=1e-9)


@pytest.fixture(scope="module")
def mujoco_run():
    """MuJoCo (dt = 1e-4) on the 30-gon (γ = 0) rolling at tilt 0.01 over bumps of Δ = 1e-4 m
    (Δ/a = 2e-3) to rest on the bumps (about 0.1 s)."""
    scene = transition_scene(delta=1e-4, tilt=0.01, n=30, restitution=0.0, t_end=0.3)
    return scene, simulate_mujoco(scene, dt=1e-4)


def test_the_rolling_polygon_passes_through_the_three_regimes_in_order(mujoco_run):
    scene, traj = mujoco_run
    _, _, regimes = classify(traj, scene)
    assert [r["regime"] for r in regimes] == [RIM_ONLY, MIXED, BUMPS_ONLY]
    rim_only, mixed, bumps_only = regimes
    assert rim_only["impacts"]["bump"] == 0 and rim_only["impacts"]["rim"] > 10
    assert mixed["impacts"]["bump"] >= 1 and mixed["impacts"]["rim"] >= 1
    assert bumps_only["impacts"]["rim"] == 0 and bumps_only["impacts"]["bump"] >= 1
    total = sum(r["impacts"]["rim"] + r["impacts"]["bump"] for r in regimes)
    assert total == len(traj.impacts)
    assert sum(r["duration"] for r in regimes) == pytest.approx(regimes[-1]["t_end"], rel=1e-12)
    # the tilt falls through the regimes
    assert rim_only["tilt_start"] > mixed["tilt_start"] > bumps_only["tilt_start"]


def test_the_bumps_first_act_where_the_face_reaches_them(mujoco_run):
    """Rolling about a centre that stays over the axis, the face passes a bump at radius
    b as low as (a − b) sin α over its foot: the first bump impact comes at the tilt
    Δ/(a − b) = 2 Δ/a, to the few per cent the centre wanders."""
    scene, traj = mujoco_run
    series, activity, _ = classify(traj, scene)
    tk = takeover(series, activity, scene)
    assert tk["face_reach_tilt"] == pytest.approx(2 * tk["delta_over_a"], rel=1e-12)
    assert tk["first_bump_tilt"] == pytest.approx(tk["face_reach_tilt"], rel=0.1)
    assert tk["last_rim_tilt"] < tk["first_bump_tilt"]


def test_the_document_carries_every_impact_with_its_kind(mujoco_run):
    scene, traj = mujoco_run
    doc = transition_document(traj, scene, "mujoco")
    kinds = ["rim" if e.contact < scene.body.n else "bump" for e in traj.impacts]
    assert doc["impacts"]["kind"] == kinds
    assert doc["t_f_source"] == "last_impact"
    assert doc["impacts"]["time_to_singularity"][-1] == 0.0


def test_transition_refuses_a_scene_without_bumps(capsys):
    assert main(["transition", "pentagon-bounce"]) == 2
    assert "bumpy ground" in capsys.readouterr().err


def test_transition_refuses_a_scene_together_with_the_study_options(capsys):
    assert main(["transition", "pentagon-bounce", "--delta", "1e-5"]) == 2
    assert "not both" in capsys.readouterr().err


def test_the_linear_model_refuses_the_bumpy_ground(capsys):
    assert main(["simulate", "bumpy-rolling", "--engine", "linear"]) == 2
    assert "not bumpy" in capsys.readouterr().err
