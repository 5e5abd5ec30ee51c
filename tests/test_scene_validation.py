"""Bad scene input is rejected with one clear sentence; good input round-trips."""

from __future__ import annotations

import math

import pytest

from harness.scenes import builtin_names, resolve_scene
from reference.scene import SceneError, load_scene, scene_from_dict

GOOD = {
    "name": "s",
    "gravity": 1.0,
    "restitution": 0.5,
    "body": {"n": 3, "radius": 1.0, "mass": 1.0, "gyration": 0.3},
    "ground": {"kind": "flat"},
    "initial": {"q": [0.0003, -0.0002, 0.4], "p": [0.03, -0.02, -1.0]},
    "run": {"t_end": 1.0},
}


def _with(path, value):
    import copy

    d = copy.deepcopy(GOOD)
    node = d
    for key in path[:-1]:
        node = node[key]
    if value is _DELETE:
        del node[path[-1]]
    else:
        node[path[-1]] = value
    return d


_DELETE = object()


@pytest.mark.parametrize(
    "path,value,fragment",
    [
        (("body", "n"), 1, "body.n must be in [2, "),
        (("body", "n"), 2.5, "body.n must be an integer"),
        (("body", "gyration"), 0.0, "body.gyration must be in [1e-06, 1e+06]"),
        (("body", "gyration"), -0.3, "body.gyration must be in [1e-06, 1e+06]"),
        (("restitution",), 1.5, "restitution must be in [0, 1]"),
        (("restitution",), -0.1, "restitution must be in [0, 1]"),
        (("gravity",), math.nan, "gravity must be finite"),
        (("initial", "q"), [0.0, math.nan, 0.4], "initial.q[1] must be finite"),
        (("body", "colour"), "red", "unknown key(s) colour"),
        (("ground", "kind"), "bumpy", "ground.kind must be"),
        (("initial", "q"), [0.0, 0.5, 0.1], "starts below the ground"),
        (("initial", "p"), _DELETE, "needs both q and p"),
    ],
)
def test_bad_scene_is_rejected_with_a_clear_message(path, value, fragment):
    with pytest.raises(SceneError) as info:
        scene_from_dict(_with(path, value))
    assert fragment in str(info.value)
    assert "\n" not in str(info.value)


def test_missing_and_malformed_files_are_scene_errors(tmp_path):
    with pytest.raises(SceneError, match="not found"):
        load_scene(tmp_path / "nope.toml")
    bad = tmp_path / "bad.toml"
    bad.write_text("name = [unclosed\n")
    with pytest.raises(SceneError, match="malformed TOML"):
        load_scene(bad)


def test_linear_coordinates_map_to_the_contract_full_state():
    s = scene_from_dict(GOOD)
    assert s.initial.position == (0.0, 0.0, 0.4)
    assert s.initial.rotation_vector == (0.0003, -0.0002, 0.0)
    assert s.initial.velocity == (0.0, 0.0, -1.0)
    assert s.initial.angular_velocity == (0.03, -0.02, 0.0)
    t = s.scaled(0.1)
    assert t.initial.position[2] == pytest.approx(0.4 * 0.01, rel=1e-15)
    assert t.initial.angular_velocity[0] == pytest.approx(0.03 * 0.1, rel=1e-15)


def test_all_builtin_scenes_load_and_the_required_ones_exist():
    names = set(builtin_names())
    for required in (
        "triangle-chatter",
        "polygon25-rolling",
        "elastic-hexagon",
        "rod",
        "three-point-disk",
        "tiny-alpha",
        "grazing-contact",
        "near-simultaneous",
    ):
        assert required in names
    for name in names:
        resolve_scene(name)
