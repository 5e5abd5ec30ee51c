"""The three-point ground's other model limit: it has no contact for the rim, so a floor
plane `floor_depth` below the bumps' tops (default 0.1 a) is not modelled, and the rim
reaching it ends the run `left_model` with that reason (reference.core.floor).  Times
are checked against values computed independently: a closed-form fall, the oracle's
closed-form flight (tests/oracle/flight.py) with brentq, and the oracle's run densely
sampled."""

import json
import math
from dataclasses import replace

import numpy as np
import pytest
from scipy.optimize import brentq

from harness.cli import main
from harness.scenes import resolve_scene
from reference.options import ReferenceOptions
from reference.scene import SceneError, scene_from_dict
from reference.simulate import simulate
from reference.trajectory import Status
from tests.oracle import quaternion as qt
from tests.oracle.body import BodyModel, initial_state
from tests.oracle.flight import flight_constants, free_flight
from tests.oracle.simulate import simulate as oracle_simulate


def _scene(initial, floor_depth=None, bump_radius=0.5, gamma=0.5, t_end=3.0):
    ground = {"kind": "three_point", "bump_radius": bump_radius}
    if floor_depth is not None:
        ground["floor_depth"] = floor_depth
    return scene_from_dict(
        {
            "name": "floor",
            "restitution": gamma,
            "body": {"n": 64, "gyration": 0.5},
            "ground": ground,
            "initial": initial,
            "run": {"t_end": t_end},
        }
    )


def _rim_above_floor(y, depth):
    """H = z + d − a|E| of an oracle state (a = 1): the rim's lowest point over the floor."""
    e3 = qt.body_axis(y[3:7])
    return y[2] + depth - math.hypot(e3[0], e3[1])


def _small_bumps():
    """The issue's probe: the three-point-disk scene on bumps of radius 1e-6."""
    return _scene({"q": [0.01, -0.006, 0.02], "p": [0.05, 0.03, -0.05]}, bump_radius=1e-6)


def test_a_tilted_disk_falling_past_the_bumps_ends_left_model_when_its_rim_reaches_the_floor():
    """Tilted by α = 0.3 and spinning about its own axis (which then stays put), the
    disk falls freely; its rim reaches z = −d, before the face meets a bump, at the
    root of z0 + v0 t − g t²/2 − a sin α + d = 0."""
    alpha, d, z0, v0 = 0.3, 0.05, 0.6, -0.2
    e3 = (math.sin(alpha), 0.0, math.cos(alpha))
    initial = {
        "position": [0.0, 0.0, z0],
        "rotation_vector": [0.0, alpha, 0.0],
        "velocity": [0.0, 0.0, v0],
        "angular_velocity": [5.0 * c for c in e3],
    }
    traj = simulate(_scene(initial, floor_depth=d))
    h = z0 - math.sin(alpha) + d
    t_floor = (v0 + math.sqrt(v0 * v0 + 2.0 * h)) / 1.0  # g = 1
    assert traj.status is Status.LEFT_MODEL
    assert len(traj.impacts) == 0
    assert "rim reached the floor plane z = -0.05" in traj.message
    assert "does not model" in traj.message
    assert traj.t_final == pytest.approx(t_floor, rel=4e-15)


def test_a_tumbling_disk_in_flight_reaches_the_floor_at_the_oracles_time():
    """Tumbling (its axis precessing), the rim's lowest point falls unevenly; the first
    zero of H on the oracle's closed-form flight (a 1e-3 grid, then brentq) is the time."""
    initial = {
        "position": [0.0, 0.0, 0.4],
        "rotation_vector": [0.25, 0.0, 0.0],
        "velocity": [0.0, 0.0, 0.1],
        "angular_velocity": [3.0, 1.0, 2.0],
    }
    d = 0.02
    scene = _scene(initial, floor_depth=d)
    traj = simulate(scene)
    fc = flight_constants(BodyModel.from_scene(scene), initial_state(scene))
    grid = np.arange(0.0, 3.0, 1e-3)
    H = np.array([_rim_above_floor(free_flight(fc, s), d) for s in grid])
    i = int(np.argmax(H <= 0.0))
    assert i > 0
    t_floor = brentq(
        lambda s: _rim_above_floor(free_flight(fc, s), d), grid[i - 1], grid[i], xtol=1e-15
    )
    assert traj.status is Status.LEFT_MODEL and len(traj.impacts) == 0
    assert traj.t_final == pytest.approx(t_floor, rel=1e-12)
    assert abs(_rim_above_floor(free_flight(fc, traj.t_final), d)) < 1e-13


def test_the_small_bump_probe_ends_left_model_where_the_oracle_crosses_the_floor():
    """On bumps of radius 1e-6 the disk pivots on one bump and tips over (to 38° by
    t = 3 without a floor); with the default floor 0.1 a below the bumps the run ends
    `left_model` during that contact phase, where the oracle's run (which has no floor)
    carries the rim through the plane: a cubic through its four samples around the
    crossing."""
    scene = _small_bumps()
    traj = simulate(scene)
    assert traj.status is Status.LEFT_MODEL
    assert traj.message.startswith("the rim reached the floor plane z = -0.1 ")
    assert traj.phases[-1].kind == "contact"
    oracle = oracle_simulate(scene, t_end=1.5, options=ReferenceOptions(sample_dt=1e-3))
    H = oracle.position[:, 2] + 0.1 - np.sin(oracle.inclination)
    i = int(np.argmax(H < 0.0))
    t, h = oracle.t[i - 2 : i + 2], H[i - 2 : i + 2]
    roots = np.roots(np.polyfit(t - t[1], h, 3)) + t[1]
    t_floor = min(r.real for r in roots if abs(r.imag) < 1e-12 and t[1] <= r.real <= t[2])
    assert traj.t_final == pytest.approx(t_floor, abs=1e-10)  # (measured: 4e-13)
    assert len(traj.impacts) == len(oracle.impacts)


def test_without_a_floor_the_probe_runs_on_as_before():
    """floor_depth = inf: no floor, the run goes to t_end (the rim far below the bumps)."""
    scene = _scene(
        {"q": [0.01, -0.006, 0.02], "p": [0.05, 0.03, -0.05]},
        floor_depth=math.inf,
        bump_radius=1e-6,
    )
    traj = simulate(scene)
    assert traj.status is Status.T_END
    assert np.degrees(traj.inclination.max()) > 30.0


def test_a_run_that_stays_above_the_floor_is_unchanged():
    """The built-in three-point-disk stays 0.09 a above the floor: the floor changes
    nothing (every impact of the run without it, bit for bit)."""
    scene = resolve_scene("three-point-disk")
    traj = simulate(scene)
    no_floor = simulate(replace(scene, ground=replace(scene.ground, floor_depth=math.inf)))
    assert traj.status is Status.SINGULARITY
    assert len(traj.impact_times()) == 303
    assert np.array_equal(traj.impact_times(), no_floor.impact_times())
    assert (traj.position[:, 2] + 0.1 - np.sin(traj.inclination)).min() > 0.09


def test_a_state_below_the_floor_is_refused_and_the_core_ends_it_at_the_start(monkeypatch):
    """A scene starting with its rim below the floor is bad input (like a contact below
    the ground), from a file and through the API; a state that reaches the core anyway
    (the API's check taken away) ends `left_model` at t = 0."""
    rest = {"velocity": [0, 0, 0], "angular_velocity": [0, 0, 0], "rotation_vector": [0, 0.8, 0]}
    with pytest.raises(SceneError, match="below the floor plane z = -0.1"):
        _scene({"position": [0.0, 0.0, 0.6], **rest})
    above = _scene({"position": [0.0, 0.0, 0.6], **rest}, floor_depth=0.2)
    below = replace(above, ground=replace(above.ground, floor_depth=0.1))
    with pytest.raises(SceneError, match="below the floor plane z = -0.1"):
        simulate(below)
    monkeypatch.setattr("reference.checks.check_scene", lambda scene: None)
    traj = simulate(below)
    assert traj.status is Status.LEFT_MODEL
    assert traj.t_final == 0.0
    assert "floor plane z = -0.1" in traj.message


@pytest.mark.parametrize(
    "ground",
    [
        {"kind": "flat", "floor_depth": 0.1},
        {"kind": "bumpy", "floor_depth": 0.1},
        {"kind": "three_point", "floor_depth": 0.0},
        {"kind": "three_point", "floor_depth": -1.0},
        {"kind": "three_point", "floor_depth": "deep"},
    ],
)
def test_a_floor_depth_off_the_three_point_ground_or_not_positive_is_refused(ground):
    with pytest.raises(SceneError, match="floor_depth"):
        scene_from_dict({"body": {"n": 8}, "ground": ground})


def test_harness_simulate_json_names_the_status_and_the_reason(tmp_path, capsys):
    """A result, not an error: exit 0 (docs/contract.md), the reason in the JSON."""
    path = tmp_path / "small-bumps.toml"
    path.write_text(
        'name = "small-bumps"\nrestitution = 0.5\n[body]\nn = 64\n'
        '[ground]\nkind = "three_point"\nbump_radius = 1e-6\n'
        "[initial]\nq = [0.01, -0.006, 0.02]\np = [0.05, 0.03, -0.05]\n[run]\nt_end = 3.0\n"
    )
    assert main(["simulate", str(path), "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["status"] == "left_model"
    assert "rim reached the floor plane z = -0.1" in doc["message"]
