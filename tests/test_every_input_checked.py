"""One check of every input on every path: a Scene handed to the Python API however it
was built (`dataclasses.replace`, the constructors) and every ReferenceOptions field are
checked like the command line's scene keys and options, before any work; coincident
bumps and windows wider than the motion's time unit are refused; options an engine does
not read are refused with one sentence.  Hypothesis fuzzes the scene fields through the
API and scene files through the command line."""

from __future__ import annotations

import dataclasses
import math

import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

import reference
from harness.cli import main
from harness.simulators import run_simulator
from reference import Body, Ground, ReferenceOptions, SceneError, load_scene, scene_from_dict
from reference.checks import check_reference_options, run_horizon
from reference.linear.simulate import simulate_linear
from reference.scene import MIN_BUMP_SPACING, RunSettings, check_scene

ENTRY_POINTS = {
    "simulate": lambda scene: reference.simulate(scene),
    "simulate_linear": lambda scene: simulate_linear(scene),
    "run_simulator": lambda scene: run_simulator("reference", scene),
}


@pytest.fixture(scope="module")
def triangle():
    return load_scene("triangle-chatter")


BAD_FIELDS = [
    ({"restitution": 5.0}, "restitution must be in"),
    ({"restitution": -0.1}, "restitution must be in"),
    ({"gravity": -1.0}, "gravity must be"),
    ({"gravity": math.nan}, "gravity must be"),
    ({"body": Body(n=0)}, "body.n must be in"),
    ({"body": Body(n=3, radius=0.0)}, "body.radius must be"),
    ({"body": Body(n=3, gyration=-1.0)}, "body.gyration must be"),
    ({"body": Body(n=True)}, "body.n must be an integer"),
    ({"ground": Ground(kind="bogus")}, "ground.kind must be"),
    ({"ground": Ground(kind="three_point", bump_radius=1.5)}, "ground.bump_radius"),
    ({"ground": Ground(kind="flat", floor_depth=0.1)}, "floor_depth belongs"),
    ({"run": RunSettings(max_impacts=-5)}, "max_impacts must be"),
    ({"run": RunSettings(t_end=0.0)}, "t_end must be"),
    ({"impact_law": "bogus"}, "impact_law must be"),
    ({"simultaneity_window": -1.0}, "simultaneity_window must be"),
    ({"simultaneity_window": 1e10}, "simultaneity_window must be at most"),
    ({"name": 5}, "name must be a string"),
]


@pytest.mark.parametrize("entry", sorted(ENTRY_POINTS))
@pytest.mark.parametrize("change,message", BAD_FIELDS, ids=lambda x: repr(x)[:40])
def test_a_scene_built_past_the_file_checks_is_refused_by_every_entry_point(
    triangle, entry, change, message
):
    with pytest.raises(SceneError, match=message):
        ENTRY_POINTS[entry](dataclasses.replace(triangle, **change))


def test_bumps_given_as_tuples_are_checked_like_the_files_lists(triangle):
    ground = Ground(kind="bumpy", bumps=((0.1, 0.0, 0.0), (0.1, 0.0, 0.0)))
    with pytest.raises(SceneError, match="coincides"):
        check_scene(dataclasses.replace(triangle, ground=ground))


def bumpy_file(bumps) -> dict:
    return {
        "body": {"n": 20, "gyration": 0.5},
        "ground": {"kind": "bumpy", "bumps": bumps},
        "initial": {
            "position": [0.0, 0.0, 0.3],
            "rotation_vector": [0.0, 0.0, 0.0],
            "velocity": [0.0, 0.0, 0.0],
            "angular_velocity": [0.0, 0.0, 0.0],
        },
    }


@pytest.mark.parametrize(
    "bumps",
    [
        [[0.2, 0.0, 0.01], [0.2, 0.0, 0.01]],  # duplicate
        [[0.2, 0.0, 0.01], [0.2, 0.0, 0.02]],  # same place, another height
        [[0.2, 0.0, 0.01], [0.2 + 0.5 * MIN_BUMP_SPACING, 0.0, 0.01]],  # closer than the spacing
    ],
)
def test_coincident_bumps_are_refused_at_load(bumps):
    with pytest.raises(SceneError, match=r"ground.bumps\[1\] coincides with ground.bumps\[0\]"):
        scene_from_dict(bumpy_file(bumps))


def test_bumps_the_spacing_apart_load():
    scene = scene_from_dict(bumpy_file([[0.2, 0.0, 0.01], [0.2 + 2 * MIN_BUMP_SPACING, 0.0, 0.0]]))
    assert len(scene.ground.bumps) == 2


def test_the_window_bound_is_the_motions_time_unit(triangle):
    """sqrt(a/g) for this scene (a = 1, g = 1): 1 is accepted, just above it is not."""
    unit = math.sqrt(triangle.body.radius / triangle.gravity)
    run_horizon(dataclasses.replace(triangle, simultaneity_window=unit))
    with pytest.raises(SceneError, match="at most the motion's time unit"):
        run_horizon(dataclasses.replace(triangle, simultaneity_window=unit * (1 + 1e-9)))


def test_the_window_bound_scales_with_the_scene(triangle):
    """A quarter of the gravity: twice the time unit sqrt(a/g)."""
    slow = dataclasses.replace(triangle, gravity=0.25, simultaneity_window=1.9)
    with pytest.raises(SceneError, match="at most"):
        run_horizon(dataclasses.replace(triangle, simultaneity_window=1.9))
    assert run_horizon(slow) == slow.run.t_end


BAD_OPTIONS = [
    (dict(simultaneity_window="1e-11"), "simultaneity_window must be"),
    (dict(simultaneity_window=True), "simultaneity_window must be"),
    (dict(simultaneity_window=math.inf), "simultaneity_window must be"),
    (dict(simultaneity_window=1e10), "at most the motion's time unit"),
    (dict(impact_law="bogus"), "impact_law must be"),
    (dict(impact_law=3), "impact_law must be"),
    (dict(sequential_order=(99,), impact_law="sequential"), r"in \[0, 3\), got 99"),
    (dict(sequential_order=(-1, 0), impact_law="sequential"), "got -1"),
    (dict(sequential_order=(0, 0), impact_law="sequential"), "names a contact twice"),
    (dict(sequential_order=(True,), impact_law="sequential"), "got True"),
    (dict(sequential_order=(), impact_law="sequential"), "non-empty"),
    (dict(sequential_order="01", impact_law="sequential"), "non-empty tuple"),
    (dict(sequential_order=(0, 1)), "applies to impact_law = 'sequential' only"),
    (dict(window_search=1), "window_search"),
    (dict(work_budget=True), "work_budget"),
    (dict(max_samples=2.0), "max_samples"),
]


@pytest.mark.parametrize("options,message", BAD_OPTIONS, ids=lambda x: repr(x)[:50])
def test_unusable_reference_options_are_refused_before_the_run(triangle, options, message):
    with pytest.raises(SceneError, match=message):
        reference.simulate(triangle, options=ReferenceOptions(**options))


def test_options_that_are_no_options_are_refused(triangle):
    with pytest.raises(SceneError, match="ReferenceOptions"):
        reference.simulate(triangle, options={"chatter_tol": 1e-6})


def test_a_sequential_order_of_the_scenes_contacts_runs(triangle):
    traj = reference.simulate(
        triangle,
        t_end=0.1,
        options=ReferenceOptions(impact_law="sequential", sequential_order=(2, 0, 1)),
    )
    assert traj.impact_law == "sequential" and traj.status.value == "t_end"


# ------------------------------------------------------------------ fuzzing the API


def _scene_changes():
    number = st.one_of(
        st.floats(allow_nan=True, allow_infinity=True),
        st.integers(-(10**400), 10**400),
        st.booleans(),
        st.text(max_size=3),
        st.none(),
    )
    body = st.builds(Body, n=st.one_of(st.integers(-5, 10), number), radius=number)
    ground = st.builds(
        Ground,
        kind=st.sampled_from(["flat", "three_point", "bumpy", "bogus", ""]),
        bump_radius=number,
        bump_height=number,
    )
    return st.fixed_dictionaries(
        {},
        optional={
            "restitution": number,
            "gravity": number,
            "body": body,
            "ground": ground,
            "simultaneity_window": number,
            "impact_law": st.sampled_from(["paper", "moreau", "sequential", "x", None]),
            "run": st.builds(RunSettings, t_end=number, max_impacts=number),
        },
    )


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(changes=_scene_changes())
def test_any_scene_the_api_gets_is_checked_or_accepted_never_a_crash(triangle, changes):
    """A scene changed at random either passes the one check or raises SceneError: never
    TypeError, ZeroDivisionError, a math domain error or OverflowError."""
    scene = dataclasses.replace(triangle, **changes)
    try:
        run_horizon(scene)
    except SceneError:
        return
    assert 0.0 <= scene.restitution <= 1.0 and scene.gravity >= 0.0
    assert 2 <= scene.body.n and scene.run.max_impacts >= 0


@settings(max_examples=150, deadline=None)
@given(
    window=st.one_of(st.none(), st.floats(), st.booleans(), st.text(max_size=4)),
    law=st.one_of(st.none(), st.sampled_from(["paper", "moreau", "sequential", "x"])),
    order=st.one_of(st.none(), st.lists(st.integers(-3, 5), max_size=4).map(tuple)),
    tol=st.one_of(st.floats(), st.integers(-2, 2), st.booleans()),
)
def test_any_options_are_checked_or_accepted_never_a_crash(triangle, window, law, order, tol):
    opts = ReferenceOptions(
        simultaneity_window=window, impact_law=law, sequential_order=order, chatter_tol=tol
    )
    try:
        check_reference_options(opts, triangle)
    except SceneError:
        return
    assert order is None or (len(set(order)) == len(order) and min(order) >= 0)


@settings(
    max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(
    key=st.sampled_from(["restitution", "gravity", "simultaneity_window"]),
    value=st.one_of(
        st.floats(), st.integers(-(2**63) + 1, 2**63 - 1), st.booleans(), st.text("abc", max_size=4)
    ),
)
@example(key="gravity", value=2**53 + 1)  # no float equals it: the nearest one is kept
def test_the_command_line_and_the_api_agree_on_a_scene_key(tmp_path_factory, key, value):
    """The same value refused by the file's loader is refused by the API on a replaced
    scene, and the reverse."""
    base = load_scene("triangle-chatter")
    q, p = (", ".join(repr(x) for x in v) for v in (base.initial.q, base.initial.p))
    text = f"{key} = {_toml(value)}\n[body]\nn = 3\ngyration = 0.3\n"
    text += f"[initial]\nq = [{q}]\np = [{p}]\n"
    path = tmp_path_factory.mktemp("scene") / "s.toml"
    path.write_text(text)
    try:
        file_scene = reference.scene.load_scene_file(path)
        file_ok = True
    except SceneError:
        file_ok = False
    try:
        run_horizon(dataclasses.replace(base, **{key: value}))
        api_ok = True
    except SceneError:
        api_ok = False
    assert file_ok == api_ok, (key, value)
    if file_ok:  # a TOML integer is read as the float nearest to it (2**53 + 1 included)
        expected = float(value) if type(value) is int else value
        assert getattr(file_scene, key) == expected


def _toml(value) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return f'"{value}"'
    if isinstance(value, float) and not math.isfinite(value):
        return "nan" if math.isnan(value) else ("inf" if value > 0 else "-inf")
    return repr(value)


# ------------------------------------------------------- options an engine does not read

GRID = ["--gyration", "0.5", "--restitution", "0.5", "--samples", "1"]


@pytest.mark.parametrize(
    "argv",
    [
        ["simulate", "triangle-chatter", "--engine", "mujoco", "--impact-law", "moreau"],
        ["simulate", "triangle-chatter", "--engine", "mujoco", "--simultaneity-window", "1e-3"],
        ["sweep", "exponent", *GRID, "--engine", "mujoco", "--impact-law", "moreau", "--out", "x"],
        [
            "sweep",
            "exponent",
            *GRID,
            "--engine",
            "mujoco",
            "--simultaneity-window",
            "1e-3",
            "--out",
            "x",
        ],
    ],
)
def test_law_options_for_an_engine_that_does_not_read_them_are_refused(argv, capsys, tmp_path):
    argv = [str(tmp_path / a) if a == "x" else a for a in argv]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "applies to the reference and linear engines only" in err[0], err
    assert not (tmp_path / "x").exists()


def test_a_window_beyond_the_bound_is_refused_on_the_command_line(capsys):
    argv = ["simulate", "triangle-chatter", "--impact-law", "sequential"]
    assert main([*argv, "--simultaneity-window", "1e10"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "at most the motion's time unit" in err[0]
