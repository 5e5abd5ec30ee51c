"""MJX adapter: the model is the `mujoco` engine's with diagexact off; float64 MJX steps
as MuJoCo C does on that model; `mjx` and `mujoco` give the same impact on
pentagon-bounce at dt = 1e-4 … 1e-9 while MuJoCo follows the reference; a vmapped batch
gives the serial runs' trajectories; the set-up's warm (tests/warm_mjx.py) compiles the
programs these tests run.

JAX is imported by the `mx` fixture, when the first of these tests runs, not when the file
is collected: a test process with JAX loaded starts its sweep pools by spawn rather than
fork (harness/child_processes.py), and every test process collects every file."""

from __future__ import annotations

import dataclasses

import mujoco
import numpy as np
import pytest

from engines.mujoco import simulate_mujoco, staggered_start, to_mujoco_state
from engines.mujoco_model import load_model
from reference import quaternion as qt
from reference.scene import InitialState
from reference.scenes import as_scene
from reference.simulate import simulate
from tests.conftest import require_extra
from tests.warm_mjx import batch_of_two, compile_the_scans

STEPS = 60  # steps of each short run: 30 before the first impact, 30 after


@pytest.fixture(scope="module")
def mx():
    """engines.mjx, imported (with JAX) when a test of this file first runs."""
    require_extra("jax", "mjx")
    require_extra("mujoco.mjx", "mjx")
    from engines import mjx

    return mjx


@pytest.fixture(scope="module")
def bounce():
    """pentagon-bounce and the reference's first impact."""
    scene = as_scene("pentagon-bounce")
    return scene, simulate(scene, t_end=0.2).impacts[0]


def _before_impact(scene, t_impact: float, dt: float):
    """The scene restarted from the reference's state (STEPS/2 − 1/2)·dt before its
    first impact, run for STEPS steps: the impact falls mid-step (on a step boundary the
    onset would be decided by roundoff)."""
    t0 = t_impact - (0.5 * STEPS - 0.5) * dt
    ref = simulate(scene, t_end=t0)
    y = np.concatenate([ref.position[-1], ref.quaternion[-1], ref.velocity[-1]])
    y = np.concatenate([y, ref.angular_velocity[-1]])
    initial = InitialState(
        tuple(y[0:3]), tuple(qt.to_rotation_vector(y[3:7])), tuple(y[7:10]), tuple(y[10:13])
    )
    return dataclasses.replace(scene, initial=initial).with_run(t_end=STEPS * dt), t0


def test_model_is_the_mujoco_engines_with_diagexact_off(bounce, mx):
    scene, _ = bounce
    ours, theirs = mx.build_model(scene, 1e-4), load_model(scene, 1e-4, "tuned")
    diagexact = int(mujoco.mjtEnableBit.mjENBL_DIAGEXACT)
    assert theirs.opt.enableflags & diagexact
    assert ours.opt.enableflags == theirs.opt.enableflags & ~diagexact
    for field in ("geom_size", "geom_pos", "geom_solref", "geom_solimp", "body_inertia"):
        assert np.array_equal(getattr(ours, field), getattr(theirs, field))
    assert ours.opt.timestep == theirs.opt.timestep and ours.opt.integrator == 0


def test_float64_mjx_steps_as_mujoco_c_on_the_same_model(bounce, mx):
    scene, first = bounce
    dt = 1e-4
    short, _ = _before_impact(scene, first.t, dt)
    run = mx.simulate_mjx(short, dt)
    model = mx.build_model(short, dt)
    data = mujoco.MjData(model)
    y0 = staggered_start(short, _y0(short), dt)
    data.qpos[:], data.qvel[:] = to_mujoco_state(y0)
    heights = []
    for _ in range(STEPS):
        mujoco.mj_step(model, data)
        heights.append(data.qpos[2])
    assert len(run.impacts) >= 1
    assert np.max(np.abs(run.position[1:, 2] - np.array(heights))) < 1e-12


def _y0(scene):
    from reference.geometry import initial_state

    return initial_state(scene.initial)


@pytest.mark.parametrize("dt", [1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9])
def test_mjx_and_mujoco_give_the_same_impact_while_mujoco_follows_the_reference(bounce, dt, mx):
    scene, first = bounce
    short, t0 = _before_impact(scene, first.t, dt)
    ours, theirs = mx.simulate_mjx(short, dt), simulate_mujoco(short, dt)
    assert [e.contact for e in ours.impacts] == [e.contact for e in theirs.impacts]
    assert [e.contact for e in theirs.impacts][:1] == [first.contact]
    assert abs(theirs.impacts[0].t + t0 - first.t) < 2 * dt  # MuJoCo follows the reference
    for a, b in zip(ours.impacts, theirs.impacts, strict=True):
        assert abs(a.t - b.t) < 1e-3 * dt
        assert a.v_normal_post == pytest.approx(b.v_normal_post, rel=1e-3)


def test_a_vmapped_batch_gives_the_serial_trajectories(bounce, mx):
    scene, first = bounce
    dt = 1e-4
    short, _ = _before_impact(scene, first.t, dt)
    scenes = batch_of_two(short)
    batch = mx.simulate_mjx_batch(scenes, dt=dt)
    for sc, b in zip(scenes, batch, strict=True):
        serial = mx.simulate_mjx(sc, dt)
        assert b.status == serial.status and len(b.t) == len(serial.t)
        assert np.allclose(b.position, serial.position, rtol=0, atol=1e-12)
        assert np.allclose(b.angular_velocity, serial.angular_velocity, rtol=0, atol=1e-10)
        assert [e.contact for e in b.impacts] == [e.contact for e in serial.impacts]
        assert [e.t for e in b.impacts] == pytest.approx([e.t for e in serial.impacts], abs=1e-12)
    assert not np.allclose(batch[0].angular_velocity, batch[1].angular_velocity)


def test_float32_mjx_runs_in_float32_and_finds_the_impact(bounce, mx):
    scene, first = bounce
    dt = 1e-4
    short, t0 = _before_impact(scene, first.t, dt)
    run = mx.simulate_mjx(short, dt, precision="float32")
    assert run.engine == "mjx-f32" and run.stats["precision"] == "float32"
    assert [e.contact for e in run.impacts][:1] == [first.contact]
    assert abs(run.impacts[0].t + t0 - first.t) < 2 * dt
    assert run.stats["compile_time_s"] >= 0 and run.stats["wall_time_s"] > 0


def test_runs_of_other_lengths_share_the_compiled_scan_and_agree_step_for_step(bounce, mx):
    """Runs of 60 and 50 steps both run the one compiled scan (CHUNK_STEPS steps): the
    second compiles nothing, and its rows are the first rows of the longer run, bit for
    bit (the angular velocity but at its last row, which the recording forms at the
    run's end)."""
    scene, first = bounce
    dt = 1e-4
    short, _ = _before_impact(scene, first.t, dt)
    longer = mx.simulate_mjx(short, dt)
    shorter = mx.simulate_mjx(short.with_run(t_end=50 * dt), dt)
    assert shorter.stats["compile_time_s"] == 0.0
    n = len(shorter.t)
    assert 50 <= n < len(longer.t)
    for field in ("position", "quaternion", "velocity"):
        assert np.array_equal(getattr(shorter, field), getattr(longer, field)[:n])
    assert np.array_equal(shorter.angular_velocity[:-1], longer.angular_velocity[: n - 1])


def test_the_set_ups_warm_compiles_the_programs_these_tests_run(bounce, mx, monkeypatch):
    """tests/warm_mjx.py (run by `make setup`) compiles the same three programs as the
    tests above, so that their workers load them from JAX's cache: the programs of these
    tests' runs (float64, float32, the batch) and of the warm's, each counted from an
    empty table of compiled programs, are the same."""
    scene, first = bounce
    short, _ = _before_impact(scene, first.t, 1e-4)
    monkeypatch.setattr(mx, "_COMPILED", {})
    mx.simulate_mjx(short, 1e-4)
    mx.simulate_mjx(short, 1e-4, precision="float32")
    mx.simulate_mjx_batch(batch_of_two(short), dt=1e-4)
    programs = set(mx._COMPILED)
    monkeypatch.setattr(mx, "_COMPILED", {})
    compile_the_scans()
    assert set(mx._COMPILED) == programs and len(programs) == 3
