"""Shared fixtures: scenes built in code (independent of the shipped TOML files), and the
rule for engines that come with a pip extra: their tests are skipped with a one-line reason
where the extra is missing (`require_extra`), and a CI run (environment CI=true, .ci/run)
fails when any of them was skipped, since CI installs every extra (`make test`).

JAX keeps what it compiles (the MJX engine's scans, ~10 s of CPU each) in .cache/jax at
the repository's root, as numba keeps the core's functions in __pycache__: a test run
after the first, and a second worker of the same run, load them instead of compiling.
`make setup` fills it before the first run (tests/warm_mjx.py)."""

from __future__ import annotations

import importlib
import os

import numpy as np
import pytest

from reference import quaternion as qt
from reference.process_exit import exit_now
from reference.scene import Body, Ground, InitialState, RunSettings, Scene, initial_from_linear
from tests.schedule import JAX_AT_COLLECTION, jax_loaded, ordered
from tests.warm_mjx import JAX_CACHE_DIR

os.environ.setdefault("JAX_COMPILATION_CACHE_DIR", str(JAX_CACHE_DIR))


def make_scene(
    n=5,
    rho=0.5,
    gamma=0.5,
    q=(0.01, -0.006, 0.05),
    p=(0.05, 0.02, -0.1),
    ground="flat",
    bump=0.5,
    bump_height=0.0,
    floor_depth=None,
    t_end=3.0,
    max_impacts=100_000,
    state=None,
    name="test",
) -> Scene:
    """A scene from linear coordinates (q, p) or from a full 13-state `state`
    (floor_depth: the three_point ground's floor, None for its default)."""
    if state is not None:
        y = np.asarray(state, dtype=float)
        initial = InitialState(
            tuple(y[0:3]), tuple(qt.to_rotation_vector(y[3:7])), tuple(y[7:10]), tuple(y[10:13])
        )
    else:
        initial = initial_from_linear(q, p)
    return Scene(
        name=name,
        body=Body(n=n, gyration=rho),
        ground=Ground(
            kind=ground, bump_radius=bump, bump_height=bump_height, floor_depth=floor_depth
        ),
        initial=initial,
        restitution=gamma,
        gravity=1.0,
        run=RunSettings(t_end=t_end, max_impacts=max_impacts),
    )


def tilted_spinning_state() -> np.ndarray:
    """A body tilted about all three axes, falling, moving sideways and spinning: the
    generic pre-impact state the single- and multi-contact impact tests start from."""
    y = np.zeros(13)
    y[3:7] = qt.from_rotation_vector([0.05, -0.08, 0.3])
    y[7:10] = [0.1, -0.2, -0.9]
    y[10:13] = [0.4, 0.3, 1.2]
    return y


def without_sweep_figures(monkeypatch) -> None:
    """Sweeps that skip their PNGs (2-3 s each): for tests of a sweep's input, its rows
    or its document; the README commands test and test_sweep's resumed run draw the
    figures."""
    import harness.sweep.plots

    monkeypatch.setattr(harness.sweep.plots, "make_sweep_figures", lambda *a, **k: {})


@pytest.fixture
def no_sweep_figures(monkeypatch):
    """`without_sweep_figures` for one test."""
    without_sweep_figures(monkeypatch)


@pytest.fixture
def fork_children(monkeypatch):
    """Child processes fork even where another test has loaded JAX
    (harness.child_processes): a test's monkeypatches reach a child (a sweep worker, a
    capped run) by fork only, a spawned child imports the modules afresh.  For tests
    whose children run no JAX: JAX's fork warning is expected there, and not shown
    (`pytest_collection_modifyitems`)."""
    import harness.child_processes

    monkeypatch.setattr(harness.child_processes, "THREADED_RUNTIMES", ())


def pytest_collection_modifyitems(config, items) -> None:
    """The test files in the order `make test`'s workers take them (tests/schedule.py);
    the tests that fork on purpose (`fork_children`) do not show JAX's fork warning; and
    whether collecting every test file loaded JAX, noted for tests/test_schedule.py."""
    config.stash[JAX_AT_COLLECTION] = jax_loaded()
    items[:] = ordered(items)
    for item in items:
        if "fork_children" in getattr(item, "fixturenames", ()):
            item.add_marker(pytest.mark.filterwarnings("ignore:os.fork:RuntimeWarning"))


@pytest.hookimpl(trylast=True)
def pytest_unconfigure(config) -> None:
    """A test worker (pytest-xdist) ends its process once its tests are over: it has sent
    its results (xdist's `workerfinished` event, after its last test) and every plugin
    has unconfigured.  Python's own teardown of a worker's modules (numba's, LLVM's, JAX's,
    Drake's state) takes 1-2 s, while the run waits for its last worker to exit."""
    if hasattr(config, "workerinput"):
        exit_now(0)


@pytest.fixture
def scene_factory():
    return make_scene


def core_model(scene: Scene):
    """(model record, contact points) of a scene, as the compiled core reads them."""
    from reference.simulate import model_record

    return model_record(scene)[0], np.array(scene.contacts.core_points, order="C")


def flight(scene: Scene, y0: np.ndarray, s: float) -> np.ndarray:
    """The state after a closed-form free flight of s from y0 (reference.core.flight)."""
    from reference.core.flight import flight_constants, free_flight

    i1, _, i3 = scene.body.inertia_diag
    out = np.empty(13)
    free_flight(np.asarray(y0, dtype=float), flight_constants(y0, i1, i3), scene.gravity, s, out)
    return out


def gaps(scene: Scene, y: np.ndarray) -> np.ndarray:
    """Contact gaps (k,) of one state."""
    from reference.geometry import scene_contact_kinematics

    return scene_contact_kinematics(scene, y)[0][0]


def angular_momentum(scene: Scene, states: np.ndarray) -> np.ndarray:
    """(N, 3) angular momentum about the centre of mass, I_w ω with
    I_w = i1 1 + (i3 − i1) e3 e3ᵀ, from the states (written here for the tests)."""
    states = np.atleast_2d(states)
    i1, _, i3 = scene.body.inertia_diag
    e3 = qt.body_axis(states[:, 3:7])
    w = states[:, 10:13]
    return i1 * w + (i3 - i1) * np.sum(w * e3, axis=1)[:, None] * e3


def states_of(traj) -> np.ndarray:
    """(N, 13) sample states of a Trajectory."""
    return np.hstack([traj.position, traj.quaternion, traj.velocity, traj.angular_velocity])


def empty_output():
    """The core's Output with one row per array and zero counts (for calling core
    functions that take it directly)."""
    from reference.core.output import Output

    return Output(
        np.zeros((1, 2)), np.zeros((1, 13)), np.zeros((1, 2)), np.zeros((1, 6)),
        np.zeros((1, 6)), np.zeros(1), np.zeros(5, dtype=np.int64),
    )  # fmt: skip


# ------------------------------------------------------------------ engines as extras
MISSING_EXTRA = "engine extra missing"


def harness_json(argv: list[str], out=None) -> dict:
    """`harness ARGV --json` run in this process (`harness.cli.main`: the document a
    separate process prints, without a new interpreter's imports); asserts exit 0 and
    returns the document, also written to `out` when given."""
    import contextlib
    import io
    import json

    from harness.cli import main

    stdout, stderr = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(stdout), contextlib.redirect_stderr(stderr):
        rc = main([*argv, "--json"])
    assert rc == 0, stderr.getvalue()
    if out is not None:
        out.write_text(stdout.getvalue())
    return json.loads(stdout.getvalue())


def require_extra(module: str, extra: str):
    """The module of an engine installed by the pip extra `extra`; the test (or the whole
    test module, at import) is skipped with a one-line reason when it is not installed.
    Under CI=true (`.ci/run`: `make test` installs every extra) it fails instead, so that
    no engine's tests go unrun there."""
    reason = f"{MISSING_EXTRA}: {module} (pip install 'euler-disk-harness[{extra}]')"
    if not _ci():
        return pytest.importorskip(module, reason=reason)
    try:
        return importlib.import_module(module)
    except ImportError as exc:
        pytest.fail(f"{reason}; CI installs every extra (`make test`): {exc}", pytrace=False)


def require_aot_core():
    """The reference's ahead-of-time module, fresh (reference.compiled.fresh_aot_module);
    the test is skipped without it, and fails under CI=true, where `make test` builds it:
    a failed build (the loop then compiled just in time) does not pass unseen."""
    from reference.compiled import fresh_aot_module

    module = fresh_aot_module()
    if module is None:
        reason = "no fresh ahead-of-time core (python -m reference.core.aot builds it)"
        if _ci():
            pytest.fail(f"{reason}; CI builds it (`make test`)", pytrace=False)
        pytest.skip(reason)
    return module


def _ci() -> bool:
    return os.environ.get("CI", "").strip().lower() in ("true", "1", "yes")
