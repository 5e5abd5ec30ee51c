"""Bad scene input is rejected with one clear sentence; good input round-trips."""

from __future__ import annotations

import math

import pytest

from harness.scenes import builtin_names, resolve_scene
from reference.scene import SceneError, scene_from_dict
from reference.scenes import load_scene

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
        (("ground", "kind"), "hilly", "ground.kind must be"),
        (("ground", "bump_height"), 0.1, "belong to kind = 'bumpy'"),
        (("initial", "q"), [0.0, 0.5, 0.1], "starts below the ground"),
        (("initial", "p"), _DELETE, "needs both q and p"),
    ],
)
def test_bad_scene_is_rejected_with_a_clear_message(path, value, fragment):
    with pytest.raises(SceneError) as info:
        scene_from_dict(_with(path, value))
    assert fragment in str(info.value)
    assert "\n" not in str(info.value)


@pytest.mark.parametrize(
    "ground,fragment",
    [
        ({"bumps": [[0.1, 0.0, 0.01]], "bump_height": 0.01}, "not both"),
        ({"bumps": []}, "ground.bumps must be a list of 1 to 64"),
        ({"bumps": [[0.1, 0.0]]}, "ground.bumps[0] must be [x, y, height]"),
        ({"bumps": [[1.0, 0.2, 0.01]]}, "must lie under the disk"),
        ({"bumps": [[0.1, 0.0, -0.01]]}, "ground.bumps[0] height must be in [0, body.radius)"),
        ({"bump_height": 1.0}, "ground.bump_height must be in [0, body.radius)"),
        ({"bump_radius": 1.2}, "ground.bump_radius must be in"),
    ],
)
def test_bad_bumpy_ground_is_rejected_with_a_clear_message(ground, fragment):
    with pytest.raises(SceneError) as info:
        scene_from_dict(_with(("ground",), {"kind": "bumpy", **ground}))
    assert fragment in str(info.value)


def test_bumpy_ground_lists_the_rim_vertices_then_the_bumps():
    """bump_radius and bump_height are lengths, like three_point's bump_radius."""
    doc = _with(("body", "radius"), 2.0)
    doc["ground"] = {"kind": "bumpy", "bump_radius": 1.0, "bump_height": 0.004}
    doc["initial"] = {"q": [0.0003, -0.0002, 0.4], "p": [0.03, -0.02, -1.0]}
    contacts = scene_from_dict(doc).contacts
    assert contacts.n_rim == 3 and contacts.n == 6
    assert math.hypot(*contacts.floor_points[1][:2]) == pytest.approx(1.0, rel=1e-15)
    assert list(contacts.floor_points[:, 2]) == [0.004] * 3
    doc["ground"] = {"kind": "bumpy", "bumps": [[0.1, 0.2, 0.003], [-0.3, 0.0, 0.0]]}
    assert scene_from_dict(doc).contacts.floor_points.tolist() == [
        [0.1, 0.2, 0.003],
        [-0.3, 0.0, 0.0],
    ]


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


# ----------------------------------------------------------------------------- ranges


@pytest.mark.parametrize(
    "path,inside,beyond",
    [
        (("body", "radius"), 1e-50, 9e-51),
        (("body", "radius"), 1e50, 1.1e50),
        (("body", "mass"), 1e-50, 1e-320),
        (("body", "gyration"), 1e-6, 9e-7),
        (("body", "gyration"), 1e6, 1.1e6),
        (("gravity",), 1e-50, 1e-60),
        (("gravity",), 0.0, -1e-300),
        (("run", "t_end"), 1e-50, 0.0),
        (("run", "max_impacts"), 10_000_000, 10_000_001),
        (("initial", "scale"), 1.0, 1e-60),
    ],
)
def test_range_edges_are_accepted_and_just_beyond_refused(path, inside, beyond):
    def scene(value):
        d = _with(path, value)
        h = 0.4 * (value if path[-1] == "radius" else 1.0)  # level, at rest, 0.4 a up
        d["initial"] = {"q": [0.0, 0.0, h], "p": [0.0, 0.0, 0.0]} | (
            {"scale": value} if path[-1] == "scale" else {}
        )
        return d

    scene_from_dict(scene(inside))
    with pytest.raises(SceneError) as info:
        scene_from_dict(scene(beyond))
    assert path[-1] in str(info.value)


def full_state_scene(velocity: float, gravity: float, t_end: float) -> dict:
    return {
        "gravity": gravity,
        "body": {"n": 3},
        "initial": {
            "position": [0.0, 0.0, 1.0],
            "rotation_vector": [0.0, 0.0, 0.0],
            "velocity": [velocity, 0.0, 0.0],
            "angular_velocity": [0.0, 0.0, 0.0],
        },
        "run": {"t_end": t_end},
    }


def test_the_speed_group_uses_sqrt_g_a_or_a_over_t_end_whichever_is_larger():
    """U = max(√(g a), a / t_end); the initial speed may be 1000 U."""
    scene_from_dict(full_state_scene(999.0, 1.0, 3.0))  # U = 1
    with pytest.raises(SceneError, match="initial speed"):
        scene_from_dict(full_state_scene(1001.0, 1.0, 3.0))
    scene_from_dict(full_state_scene(1e5, 1.0, 1e-3))  # a short run: U = 1000
    s = scene_from_dict(full_state_scene(400.0, 0.0, 1.0))  # no gravity: U = a / t_end
    s.with_run(t_end=2.0)
    with pytest.raises(SceneError, match="initial speed"):
        s.with_run(t_end=10.0)


def test_scaling_keeps_the_below_ground_check():
    """The lowest vertex of a tilted triangle is at h − a sin φ sin 60°: exactly on the
    ground at ε = 1, 1.2e-5 a inside it at ε = 0.1 (tilt and height both scale by ε²)."""
    h = math.sin(0.2) * math.sin(math.pi / 3)
    s = scene_from_dict(_with(("initial",), {"q": [0.2, 0.0, h], "p": [0.0, 0.0, 0.0]}))
    with pytest.raises(SceneError, match="below the ground"):
        s.scaled(0.1)
    with pytest.raises(SceneError, match="scale"):
        s.scaled(1e200)


def test_unusable_files_are_one_line_scene_errors(tmp_path):
    cases = {
        "binary.toml": b"\xff\xfe\x00\x80",
        "deep.toml": b"a = " + b"[" * 3000 + b"]" * 3000 + b"\n",
        "big.toml": b"# " + b"x" * (1 << 20) + b"\n",
    }
    for name, content in cases.items():
        (tmp_path / name).write_bytes(content)
    paths = [tmp_path / n for n in cases] + [tmp_path, tmp_path / ("x" * 300 + ".toml")]
    for path in paths:
        with pytest.raises(SceneError) as info:
            load_scene(path)
        assert "\n" not in str(info.value) and len(str(info.value)) < 200
