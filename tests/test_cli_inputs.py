"""Every bad or extreme input: exit status 2 with one clear line, nothing damaged; valid
but degenerate states: exit 0 with a real status.  The named cases of the hostile probe
(docs/inputs.md), run in-process through harness.cli.main."""

from __future__ import annotations

import hashlib
import json
import math
import os
from pathlib import Path

import pyarrow.parquet as pq
import pytest

from harness.cli import main
from reference.trajectory import Status

STATUSES = {s.value for s in Status}

TRIANGLE = """name = "keep"
gravity = 1.0
restitution = 0.5
[body]
n = 3
radius = 1.0
mass = 1.0
gyration = 0.3
[initial]
q = [0.02, 0.0, 0.05]
p = [0.0, 0.0, 0.0]
[run]
t_end = 0.2
"""


def full_state(**kw) -> str:
    """A triangle scene with a full initial state; keyword = TOML value text."""
    state = {
        "position": "[0.0, 0.0, 0.1]",
        "rotation_vector": "[0.02, 0.0, 0.0]",
        "velocity": "[0.0, 0.0, 0.0]",
        "angular_velocity": "[0.0, 0.0, 0.0]",
    }
    head = {"gravity": "1.0", "n": "3", "mass": "1.0", "radius": "1.0", "gyration": "0.3"}
    for k in list(kw):
        if k in head:
            head[k] = kw.pop(k)
    state.update(kw)
    return (
        f'name = "s"\ngravity = {head["gravity"]}\n[body]\nn = {head["n"]}\n'
        f"radius = {head['radius']}\nmass = {head['mass']}\ngyration = {head['gyration']}\n"
        "[initial]\n" + "".join(f"{k} = {v}\n" for k, v in state.items()) + "[run]\nt_end = 0.1\n"
    )


def snapshot(folder: Path) -> dict[str, str]:
    return {
        str(p.relative_to(folder)): hashlib.sha256(p.read_bytes()).hexdigest()
        for p in sorted(folder.rglob("*"))
        if p.is_file()
    }


@pytest.fixture
def cli(tmp_path, monkeypatch, capsys):
    """run(argv, files) in a fresh folder → (code, stdout, stderr lines, folder); the
    folder's content before the command is in run.before."""
    monkeypatch.chdir(tmp_path)

    def run(argv, files=None):
        for rel, content in (files or {}).items():
            p = tmp_path / rel
            p.parent.mkdir(parents=True, exist_ok=True)
            p.write_bytes(content if isinstance(content, bytes) else content.encode())
        run.before = snapshot(tmp_path)
        code = main(list(argv))
        out, err = capsys.readouterr()
        return code, out, [x for x in err.splitlines() if x.strip()], tmp_path

    return run


def assert_bad_input(cli, argv, files=None, fragment=""):
    code, out, err, folder = cli(argv, files)
    assert code == 2, (argv, err)
    assert len(err) == 1 and err[0].startswith("harness: error: "), err
    assert "Traceback" not in err[0]
    assert fragment in err[0], err[0]
    assert snapshot(folder) == cli.before  # nothing changed, nothing left behind
    return err[0]


# ----------------------------------------------------------------------------- numbers

EXTREME_SCENES = {
    "omega-1e300": (full_state(angular_velocity="[1e300, 0.0, 0.0]"), "initial speed"),
    "mass-1e-320": (full_state(mass="1e-320"), "body.mass must be in"),
    "velocity--1e300": (full_state(velocity="[0.0, 0.0, -1e300]"), "initial speed"),
    "gyration-1e-200": (full_state(gyration="1e-200"), "body.gyration must be in"),
    "radius-1e-200": (full_state(radius="1e-200"), "body.radius must be in"),
    "gravity-1e300": (full_state(gravity="1e300"), "gravity must be 0 or in"),
    "rotation-1e300": (full_state(rotation_vector="[1e300, 0.0, 0.0]"), "rotation vector"),
    "n-1e10": (full_state(n="10000000000"), "body.n must be in"),
    "scale-1e200": (TRIANGLE.replace("[run]", "scale = 1e200\n[run]"), "initial.scale must be in"),
    "huge-integer": (full_state(mass="1" + "0" * 400), "body.mass must be"),
    "position-1e20": (full_state(position="[0.0, 0.0, 1e20]"), "initial position"),
}


@pytest.mark.parametrize("case", sorted(EXTREME_SCENES))
def test_extreme_numbers_in_a_scene_are_refused(cli, case):
    text, fragment = EXTREME_SCENES[case]
    assert_bad_input(cli, ["simulate", "s.toml", "--json"], {"s.toml": text}, fragment)


@pytest.mark.parametrize(
    "argv,fragment",
    [
        (["--scale", "1e200"], "--scale"),
        (["--scale", "-1"], "must be > 0"),
        (["--engine", "mujoco", "--dt", "-1e-3"], "must be > 0"),
        (["--engine", "mujoco", "--dt=-1e-3"], "must be > 0"),
        (["--engine", "mujoco", "--dt", "-inf"], "must be > 0"),
        (["--engine", "mujoco", "--dt", "nan"], "--dt"),
        (["--engine", "mujoco", "--dt", "1e-320"], "--dt"),
        (["--engine", "mujoco", "--dt", "10", "--t-end", "0.1"], "must not exceed t_end"),
        (["--engine", "pybullet", "--dt", "1e-12"], "exceeds the ceiling"),
        (["--engine", "mujoco", "--t-end", "1e12"], "exceeds the ceiling"),
        (["--engine", "mujoco", "--t-end", "0.1", "--max-steps", "10"], "exceeds the ceiling"),
        (["--t-end", "1e300"], "--t-end"),
        (["--t-end", "-1e-3"], "must be > 0"),
        (["--engine", "nonsense"], "unknown engine"),
    ],
)
def test_bad_numbers_on_the_command_line_are_refused(cli, argv, fragment):
    assert_bad_input(cli, ["simulate", "triangle-chatter", *argv], fragment=fragment)


def test_scale_gets_the_same_below_ground_check_as_the_scene_file(cli):
    """Tilt φ and height h both scale by ε², but the lowest vertex is at h − a sin φ sin
    60°: on the ground at ε = 1 (h = sin(0.2) sin 60°), 1e-5 a inside it at ε = 0.1."""
    h = math.sin(0.2) * math.sin(math.pi / 3)
    scene = TRIANGLE.replace("q = [0.02, 0.0, 0.05]", f"q = [0.2, 0.0, {h!r}]")
    code, _, err, _ = cli(["simulate", "s.toml", "--t-end", "0.01"], {"s.toml": scene})
    assert code == 0, err
    assert_bad_input(cli, ["simulate", "s.toml", "--scale", "0.1"], fragment="below the ground")
    in_file = scene.replace("[run]", "scale = 0.1\n[run]")
    assert_bad_input(cli, ["simulate", "t.toml"], {"t.toml": in_file}, "below the ground")


@pytest.mark.parametrize(
    "argv,fragment",
    [
        (["selfsimilar", "--n", "2"], "--n must be >= 3"),
        (["selfsimilar", "--n", "10000000000"], "--n"),
        (["chatter", "--gyration", "1e300"], "--gyration"),
        (["chatter", "--gyration", "1e-300"], "--gyration"),
        (["selfsimilar", "--gyration", "0"], "must be > 0"),
        (["chatter", "--restitution", "1.5"], "--restitution"),
    ],
)
def test_bad_analysis_parameters_are_refused(cli, argv, fragment):
    base = {"--n": "3", "--gyration": "0.3", "--restitution": "0.5"}
    kind, *rest = argv
    opts = dict(base)
    opts.update(dict(zip(rest[::2], rest[1::2], strict=True)))
    flat = [x for kv in opts.items() for x in kv]
    assert_bad_input(cli, ["analyze", kind, *flat], fragment=fragment)


# ----------------------------------------------------------------------------- files


@pytest.mark.parametrize(
    "name,content,fragment",
    [
        ("s.toml", b"\xff\xfe\x00garbage\x80", "not UTF-8"),
        ("s.toml", ("a = " + "[" * 3000 + "]" * 3000 + "\n").encode(), "nested too deeply"),
        ("s.toml", b"name = [unclosed\n", "malformed TOML"),
        ("s.toml", b"", "no [body] table"),
        ("s.toml", (TRIANGLE + "#" + "x" * (1 << 20)).encode(), "larger than"),
        ("x" * 300 + ".toml", None, "cannot read scene file"),
    ],
    ids=["binary", "deep", "malformed", "empty", "huge", "long-name"],
)
def test_unreadable_scene_files_are_refused(cli, name, content, fragment):
    files = {name: content} if content is not None else None
    assert_bad_input(cli, ["simulate", name], files, fragment)


def test_a_directory_or_device_is_not_a_scene(cli, tmp_path):
    assert_bad_input(cli, ["simulate", "."], fragment="not a regular file")
    os.symlink("/dev/zero", tmp_path / "zero.toml")
    code, _, err, _ = cli(["simulate", "zero.toml"])
    assert code == 2 and len(err) == 1 and "not a regular file" in err[0]


# ----------------------------------------------------------------------------- outputs


@pytest.fixture
def no_run(monkeypatch):
    """Fail the test if any simulation, bench, sweep run or figure starts.  Each
    function's code is replaced, not a module's name for it: the modules that import it
    by name (`from ..simulators import run_simulator`) hold the function itself, so a
    name replaced in its own module would not reach them, and one imported during the
    test would keep the replacement after it."""

    def forbidden(*a, **k):
        raise AssertionError("the work started although an output was refused")

    import harness.bench
    import harness.figures
    import harness.simulators
    import harness.sweep.run

    work = (
        harness.simulators.run_simulator,
        harness.bench.bench,
        harness.figures.make_figures,
        harness.sweep.run.run_chunk,
    )
    for function in work:
        monkeypatch.setattr(function, "__code__", forbidden.__code__)


KEEP = {"keep.toml": TRIANGLE}
SWEEP = ["sweep", "exponent", "--gyration", "0.3", "--restitution", "0.5", "--samples", "1"]


@pytest.mark.parametrize(
    "argv,files,fragment",
    [
        (["simulate", "keep.toml", "--out", "keep.toml"], KEEP, "is an input"),
        (["simulate", "keep.toml", "--out", "keep.toml", "--force"], KEEP, "is an input"),
        (
            ["simulate", "keep.toml", "--out", "old.parquet"],
            {**KEEP, "old.parquet": "x"},
            "--force",
        ),
        (
            ["simulate", "keep.toml", "--out", "r.parquet"],
            {**KEEP, "r.impacts.parquet": "x"},
            "--force",
        ),
        (["simulate", "keep.toml", "--out", "/proc/x.parquet"], KEEP, "cannot write"),
        (["simulate", "keep.toml", "--out", "keep.toml/x.parquet"], KEEP, "not a directory"),
        (["simulate", "keep.toml", "--out", "."], KEEP, "directory"),
        (["simulate", "keep.toml", "--out", "y" * 300 + ".parquet"], KEEP, "longer than"),
        (["simulate", "keep.toml", "--record", "/proc/x.rrd"], KEEP, "cannot write"),
        (["simulate", "keep.toml", "--record", "keep.toml/x.rrd"], KEEP, "not a directory"),
        (["simulate", "keep.toml", "--record", "./keep.toml"], KEEP, "is an input"),
        (["simulate", "keep.toml", "--record", "./a.rrd", "--out", "./a.rrd"], KEEP, "two outputs"),
        (["compare", "keep.toml", "--engine", "linear", "--record", "/proc/x.rrd"], KEEP, "cannot"),
        (["bench", "keep.toml", "--engine", "linear", "--plot", "/proc/x.png"], KEEP, "cannot"),
        (["bench", "keep.toml", "--engine", "linear", "--plot", "x.nope"], KEEP, "image format"),
        (
            ["bench", "keep.toml", "--engine", "linear", "--out", "o.json"],
            {**KEEP, "o.json": "x"},
            "--force",
        ),
        (["bench", "keep.toml", "--engine", "linear", "--out", "."], KEEP, "is a directory"),
        (["figures", "--out", "/proc/figs"], {}, "cannot write"),
        (["figures", "--out", "keep.toml"], KEEP, "not a directory"),
        (["figures", "--out", "f"], {"f/boundaries.png": "x"}, "--force"),
        ([*SWEEP, "--out", "/proc/sw"], {}, "cannot write"),
        ([*SWEEP, "--out", "keep.toml"], KEEP, "not a directory"),
        ([*SWEEP, "--out", "d"], {"d/linear/notes.txt": "mine"}, "not a sweep directory"),
        ([*SWEEP, "--out", "d"], {"d/readme.md": "mine"}, "not a sweep directory"),
    ],
)
def test_outputs_are_refused_before_any_work(cli, no_run, argv, files, fragment):
    assert_bad_input(cli, argv, files, fragment)


def test_force_replaces_an_output_atomically_and_leaves_no_temporary(cli):
    code, _, err, folder = cli(
        ["simulate", "keep.toml", "--out", "r.parquet", "--force", "--t-end", "0.05"],
        {**KEEP, "r.parquet": "old"},
    )
    assert code == 0, err
    assert pq.read_table(folder / "r.parquet").num_rows > 0
    assert sorted(snapshot(folder)) == ["keep.toml", "r.impacts.parquet", "r.parquet"]
    meta = pq.read_schema(folder / "r.parquet").metadata[b"summary"]
    json.loads(meta, parse_constant=lambda c: pytest.fail(f"{c} in the Parquet summary"))


# ----------------------------------------------------------------------------- sweeps


def test_a_grid_too_large_is_refused_before_the_manifest_and_the_fix_then_runs(
    cli, no_sweep_figures
):
    huge = ["--gyration", "0.1:0.5:10000", "--restitution", "0:0.5:10000"]
    base = ["sweep", "exponent", "--samples", "1", "--out", "sw"]
    assert_bad_input(cli, [*base, *huge], fragment="at most")
    code, out, err, folder = cli([*base, "--gyration", "0.3", "--restitution", "0.5", "--json"])
    assert code == 0, err
    assert json.loads(out)["tasks"]["rows"] == 1


def test_rho_zero_in_a_sweep_is_refused_like_simulate_and_analyze(cli):
    argv = ["sweep", "exponent", "--gyration", "0:0.5:3", "--restitution", "0.5"]
    assert_bad_input(cli, [*argv, "--samples", "1", "--out", "sw"], fragment="rho = 0")


# ----------------------------------------------------------------------------- valid edges

DEGENERATE = {
    "flat-at-rest": full_state(position="[0.0, 0.0, 0.0]", rotation_vector="[0.0, 0.0, 0.0]"),
    "zero-gravity": full_state(gravity="0.0", velocity="[0.0, 0.0, -0.5]"),
    "zero-gravity-at-rest": full_state(gravity="0.0"),
    "resting-on-bumps": full_state(
        n="16", position="[0.0, 0.0, 0.0]", rotation_vector="[0.0, 0.0, 0.0]"
    ).replace("[initial]", '[ground]\nkind = "three_point"\nbump_radius = 0.5\n[initial]'),
}


@pytest.mark.parametrize("engine", ["reference", "linear", "mujoco", "pybullet"])
@pytest.mark.parametrize("case", sorted(DEGENERATE))
def test_valid_degenerate_states_end_with_a_real_status(cli, case, engine):
    if engine == "linear" and case == "resting-on-bumps":
        pytest.skip("the linear model is built for flat ground")
    argv = ["simulate", "s.toml", "--engine", engine, "--t-end", "0.05", "--json"]
    code, out, err, _ = cli(argv, {"s.toml": DEGENERATE[case]})
    assert code == 0, err
    doc = json.loads(out, parse_constant=lambda c: pytest.fail(f"{c} in the JSON"))
    assert doc["status"] in STATUSES
    if doc["status"] != "failed":
        q = doc["final_state"]["quaternion_wxyz"]
        assert abs(math.hypot(*q) - 1.0) < 1e-6
