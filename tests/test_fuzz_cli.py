"""Property-based fuzzing of the command line (hypothesis): generated scene files and
command lines, with numbers across many orders of magnitude, NaN, infinities, wrong types
and odd paths.  Whatever the input:

- the exit status is 0 (done) or 2 (bad input), never a traceback; exit 2 is exactly one
  line on stderr;
- with --json, stdout is exactly one JSON document, without NaN or Infinity; a Parquet
  output's summary is strict JSON too;
- the input scene file is unchanged and nothing is left behind (no temporary file, no
  MUJOCO_LOG.TXT).

Each example is bounded: the base scene runs 0.05 s with at most 200 impacts, and
fixed-step engines always get --max-steps <= 20000.  The profile is derandomized (fixed
examples, no example database), so every run of the suite checks the same inputs.
Three tests (event-driven simulators, fixed-step engines, analyses and sweeps) share the
examples, so that a parallel run (pytest-xdist) spreads them.
"""

from __future__ import annotations

import hashlib
import json
import math
import os
import tempfile
from pathlib import Path

from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st

from harness.cli import main

# examples per test, 300 in all (the command mix of one test of 300 examples: simulate
# 4/6, of which fixed-step engines 2/5; analyze and sweep 2/6)
EXAMPLES = {"event-driven": 120, "fixed-step": 80, "analyses": 100}

BASE = {
    "name": "fuzz",
    "gravity": 1.0,
    "restitution": 0.5,
    "body": {"n": 3, "radius": 1.0, "mass": 1.0, "gyration": 0.3},
    "ground": {"kind": "flat"},
    "initial": {"q": [0.02, 0.0, 0.05], "p": [0.0, 0.0, -0.1]},
    "run": {"t_end": 0.05, "max_impacts": 200},
}
FULL_INITIAL = {
    "position": [0.0, 0.0, 0.1],
    "rotation_vector": [0.02, 0.0, 0.0],
    "velocity": [0.0, 0.0, 0.0],
    "angular_velocity": [0.0, 0.0, 0.0],
}
FIELDS = [
    ("gravity",),
    ("restitution",),
    ("body", "n"),
    ("body", "radius"),
    ("body", "mass"),
    ("body", "gyration"),
    ("ground", "bump_radius"),
    ("initial", "q", 0),
    ("initial", "q", 2),
    ("initial", "p", 1),
    ("initial", "p", 2),
    ("initial", "scale"),
    ("initial", "position", 2),
    ("initial", "rotation_vector", 0),
    ("initial", "velocity", 0),
    ("initial", "angular_velocity", 2),
    ("run", "t_end"),
    ("run", "max_impacts"),
    ("name",),
    ("body", "colour"),
]

# ----------------------------------------------------------------------------- values

magnitudes = st.sampled_from(
    [0.0, 1e-320, 1e-300, 1e-60, 1e-50, 1e-12, 1e-6, 1e-3, 0.3, 1.0, 7.0, 1e3, 1e6]
    + [1e12, 1e50, 1e60, 1e300]
)
wide_floats = st.one_of(
    st.builds(lambda m, s: s * m, magnitudes, st.sampled_from([1.0, -1.0])),
    st.floats(allow_nan=True, allow_infinity=True),
    st.sampled_from([math.nan, math.inf, -math.inf]),
)
# values a careful user would write: most examples should run and end with a status
plausible = st.sampled_from([1e-4, 1e-3, 0.01, 0.05, 0.1, 0.3, 0.5, 1.0, 2.0])
hostile = st.one_of(
    wide_floats,
    st.integers(min_value=-(10**30), max_value=10**30),
    st.sampled_from([True, "3", "", [], [1.0, 2.0], {"a": 1}, 10**400]),
    st.text(max_size=5),
)
field_value = st.one_of(plausible, plausible, hostile)
number_text = st.one_of(
    plausible.map(repr),
    plausible.map(repr),
    wide_floats.map(repr),
    st.sampled_from(["-1e-3", "-0", "1e400", "-inf", "nan", "abc", "", "0x10", "1_000", "2e7"]),
    st.integers(min_value=-(10**12), max_value=10**12).map(str),
)


def toml_value(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, float):
        if math.isnan(v):
            return "nan"
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return repr(v)
    if isinstance(v, int):
        return str(v)
    if isinstance(v, str):
        return json.dumps(v)
    if isinstance(v, list):
        return "[" + ", ".join(toml_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{" + ", ".join(f"{k} = {toml_value(x)}" for k, x in v.items()) + "}"
    raise TypeError(type(v))


def toml_text(scene: dict) -> str:
    top = [f"{k} = {toml_value(v)}" for k, v in scene.items() if not isinstance(v, dict)]
    tables = [
        f"[{k}]\n" + "".join(f"{kk} = {toml_value(vv)}\n" for kk, vv in v.items())
        for k, v in scene.items()
        if isinstance(v, dict)
    ]
    return "\n".join(top) + "\n" + "".join(tables)


@st.composite
def scenes(draw, hostile_ok: bool = True) -> str:
    """A valid base scene (linear or full initial state, flat or three-point ground) with
    up to two fields replaced (plausible or hostile values), occasionally cut or with
    stray bytes; only plausible replacements when not `hostile_ok`."""
    scene = json.loads(json.dumps(BASE))
    if draw(st.booleans()):
        scene["initial"] = json.loads(json.dumps(FULL_INITIAL))
    if draw(st.integers(0, 4)) == 0:
        scene["ground"] = {"kind": "three_point", "bump_radius": 0.5}
        scene["body"]["n"] = 16
    k = draw(st.integers(0, 2))
    for path in draw(st.permutations(FIELDS))[:k]:
        value = draw(field_value if hostile_ok else plausible)
        if len(path) == 1:
            scene[path[0]] = value
        elif len(path) == 2:
            scene[path[0]][path[1]] = value
        elif path[1] in scene["initial"]:  # a component of an initial vector
            scene["initial"][path[1]][path[2]] = value
    text = toml_text(scene)
    cut = draw(st.integers(0, 12)) if hostile_ok else -1
    if cut == 0:
        text = text[: draw(st.integers(0, len(text)))]
    elif cut == 1:
        text += draw(st.sampled_from(["\x00", "\ufffd", "[[", "a = 1\na = 2"]))
    return text


ODD_PATHS = [
    "out.parquet",
    "sub/dir/out.parquet",
    "scene.toml",
    "scene.toml/x.parquet",
    "/proc/harness-fuzz.parquet",
    ".",
    "",
    "y" * 300 + ".parquet",
    "exists.parquet",
]


# the simulators `simulate` fuzzes, in two groups (two tests: the suite runs them in
# parallel): the event-driven ones and the fixed-step engines
EVENT_DRIVEN = ("reference", "reference", "linear")
FIXED_STEP = ("mujoco", "pybullet")


@st.composite
def command_lines(
    draw, hostile_ok: bool = True, commands=("simulate",), engines=EVENT_DRIVEN
) -> list[str]:
    numbers = number_text if hostile_ok else plausible.map(repr)
    command = draw(st.sampled_from(commands))
    if command == "analyze":
        kind = draw(st.sampled_from(["selfsimilar", "chatter"]))
        argv = ["analyze", kind]
        for opt, default in (("--n", "3"), ("--gyration", "0.3"), ("--restitution", "0.5")):
            argv += [opt, draw(st.one_of(st.just(default), numbers))]
        return argv + ["--json"]
    if command == "sweep":
        grid = st.sampled_from(["0.3", "0.2:0.4:2"])
        if hostile_ok:
            grid = st.one_of(grid, st.sampled_from(["0:0.5:3", "0.1:0.5:100000000"]), numbers)
        samples = ["1", "2", "0", "-1", "1e10"] if hostile_ok else ["1", "2"]
        outs = ["sw", "scene.toml", "/proc/sw", "."] if hostile_ok else ["sw"]
        return [
            "sweep", "exponent", "--gyration", draw(grid), "--restitution", draw(grid),
            "--samples", draw(st.sampled_from(samples)), "--out", draw(st.sampled_from(outs)),
            "--workers", "1", "--json",
        ]  # fmt: skip
    engine = draw(st.sampled_from(engines))
    argv = ["simulate", "scene.toml", "--engine", engine, "--json"]
    if engine in ("mujoco", "pybullet"):
        steps = ["20000", "100", "0", "-5", "abc"] if hostile_ok else ["20000"]
        argv += ["--max-steps", draw(st.sampled_from(steps))]
    for opt in ("--dt", "--t-end", "--scale"):
        if draw(st.integers(0, 2)) == 0:
            value = draw(numbers)
            argv += [f"{opt}={value}"] if draw(st.booleans()) else [opt, value]
    if draw(st.integers(0, 2)) == 0:
        argv += ["--out", draw(st.sampled_from(ODD_PATHS if hostile_ok else ODD_PATHS[:2]))]
    if draw(st.integers(0, 4)) == 0:
        argv += ["--force"]
    return argv


@st.composite
def cases(draw, **commands) -> tuple[str, list[str]]:
    """(scene text, command line): a third of the cases careful (plausible values only,
    so that runs happen and their output is checked), the rest anything.  `commands`:
    which commands and engines (command_lines)."""
    hostile_ok = draw(st.integers(0, 2)) > 0
    return draw(scenes(hostile_ok)), draw(command_lines(hostile_ok, **commands))


# ----------------------------------------------------------------------------- checks


def strict_json(text: str):
    def refuse(constant):
        raise AssertionError(f"{constant} in JSON output")

    return json.loads(text, parse_constant=refuse)


def digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def check_outputs(folder: Path, argv: list[str]) -> None:
    leftovers = [p.name for p in folder.rglob("*") if p.name.startswith(".harness-tmp-")]
    assert leftovers == [] and not (folder / "MUJOCO_LOG.TXT").exists(), argv
    for part in folder.rglob("*.parquet"):
        if part.name == "exists.parquet" or "sw" in part.parts:
            continue
        import pyarrow.parquet as pq

        strict_json(pq.read_schema(part).metadata[b"summary"])


FUZZ = settings(
    deadline=None,
    derandomize=True,
    database=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture],
)


@settings(FUZZ, max_examples=EXAMPLES["event-driven"])
@given(case=cases(commands=("simulate",), engines=EVENT_DRIVEN))
def test_any_input_to_the_event_driven_simulators_gives_a_result_or_one_clear_line(
    case, tmp_path, capfd
):
    check_case(case, tmp_path, capfd)


@settings(FUZZ, max_examples=EXAMPLES["fixed-step"])
@given(case=cases(commands=("simulate",), engines=FIXED_STEP))
def test_any_input_to_the_engines_gives_a_result_or_one_clear_line(case, tmp_path, capfd):
    check_case(case, tmp_path, capfd)


@settings(FUZZ, max_examples=EXAMPLES["analyses"])
@given(case=cases(commands=("analyze", "sweep")))
def test_any_input_to_the_analyses_gives_a_result_or_one_clear_line(
    case, tmp_path, capfd, no_sweep_figures
):
    check_case(case, tmp_path, capfd)


def check_case(case, tmp_path, capfd) -> None:
    """The checks of the module docstring on one (scene, command line)."""
    scene, argv = case
    folder = Path(tempfile.mkdtemp(dir=tmp_path))
    (folder / "scene.toml").write_text(scene, encoding="utf-8", errors="surrogatepass")
    (folder / "exists.parquet").write_text("someone's file")
    before = {name: digest(folder / name) for name in ("scene.toml", "exists.parquet")}
    cwd = os.getcwd()
    os.chdir(folder)
    try:
        capfd.readouterr()
        code = main(argv)
        out, err = capfd.readouterr()
    finally:
        os.chdir(cwd)
    lines = [x for x in err.splitlines() if x.strip()]
    event(f"{argv[0]} {argv[1] if argv[0] != 'simulate' else argv[3]}: exit {code}")
    assert code in (0, 2), (argv, scene, err)
    assert "Traceback" not in err, (argv, scene, err)
    if code == 2:
        assert len(lines) == 1 and lines[0].startswith("harness: error: "), (argv, lines)
    else:
        doc = strict_json(out)
        final = doc.get("final_state") if isinstance(doc, dict) else None
        if final is not None and doc["status"] != "failed":
            assert abs(math.hypot(*final["quaternion_wxyz"]) - 1.0) < 1e-6, (argv, doc)
    assert digest(folder / "scene.toml") == before["scene.toml"], argv  # never, even with --force
    if "--force" not in argv:
        assert digest(folder / "exists.parquet") == before["exists.parquet"], argv
    check_outputs(folder, argv)
