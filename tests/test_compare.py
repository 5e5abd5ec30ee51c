"""`harness compare`: orchestration with stand-in simulators, then a real scene."""

from __future__ import annotations

import json

import numpy as np
import pytest

from harness import compare as C
from harness.cli.common import finite
from harness.scenes import resolve_scene
from reference.scene import SceneError
from reference.trajectory import ImpactEvent, Status, Trajectory

CONTRACT_ROW = {
    "engine",
    "dt",
    "status",
    "wall_time_s",
    "impacts",
    "impacts_matched",
    "impact_time_error",
    "energy_error",
    "attitude_error",
    "effective_restitution",
}


def stand_in(engine: str, dt: float | None, delay: float = 0.0) -> Trajectory:
    """A tilted body at rest with two impacts; `delay` shifts the impacts."""
    t = np.linspace(0.0, 1.0, 101)
    n = len(t)
    q = np.tile([np.cos(0.005), np.sin(0.005), 0.0, 0.0], (n, 1))
    return Trajectory(
        engine=engine,
        scene="stand-in",
        t=t,
        position=np.zeros((n, 3)),
        quaternion=q,
        velocity=np.zeros((n, 3)),
        angular_velocity=np.zeros((n, 3)),
        kinetic_energy=np.ones(n),
        potential_energy=np.zeros(n),
        impacts=[
            ImpactEvent(0.3 + delay, 0, 1.0, -1.0, 0.5),
            ImpactEvent(0.6 + delay, 1, 1.0, -0.5, 0.25),
        ],
        status=Status.T_END,
        t_final=1.0,
        dt=dt,
    )


@pytest.fixture
def calls(monkeypatch):
    """Replace the simulators: record every call; 'pybullet' raises."""
    made: list[tuple[str, float | None]] = []

    def fake(engine, scene, dt=None, t_end=None, **_limits):
        made.append((engine, dt))
        if engine == "pybullet":
            raise RuntimeError("engine exploded")
        return stand_in(engine, dt, delay=0.0 if engine == "reference" else 1e-3)

    monkeypatch.setattr(C, "run_simulator", fake)
    return made


def test_reference_runs_once_and_fixed_step_engines_at_every_dt(calls):
    scene = resolve_scene("pentagon-bounce")
    lines: list[str] = []
    result = C.compare(scene, ["linear", "mujoco"], dts=[1e-3, 1e-4], progress=lines.append)
    assert calls == [("reference", None), ("linear", None), ("mujoco", 1e-3), ("mujoco", 1e-4)]
    assert [(r.engine, r.dt) for r in result.runs] == calls[1:]
    assert len(lines) == 4 and all("s)" in line for line in lines)


def test_default_dt_is_the_registry_default(calls):
    C.compare(resolve_scene("pentagon-bounce"), ["mujoco-default"], dts=None)
    assert calls[1] == ("mujoco-default", C.DEFAULT_DT)


def test_reference_as_engine_reuses_the_reference_run(calls):
    result = C.compare(resolve_scene("pentagon-bounce"), ["reference"])
    assert calls == [("reference", None)]
    assert result.runs[0].metrics.impacts_matched == 2
    assert result.runs[0].metrics.impact_time_error == 0.0


def test_a_failing_engine_is_a_failed_row_not_a_crash(calls):
    result = C.compare(resolve_scene("pentagon-bounce"), ["pybullet", "mujoco"], dts=[1e-3])
    failed, ok = result.to_dict()["engines"]
    assert failed["status"] == "failed" and "engine exploded" in failed["message"]
    assert failed["impacts_matched"] == 0 and failed["attitude_error"] is None
    assert ok["status"] == "t_end" and ok["impacts_matched"] == 2
    assert ok["impact_time_error"] == pytest.approx(1e-3)


def test_bad_input_still_stops_the_command(monkeypatch):
    def bad(engine, scene, dt=None, t_end=None, **_limits):
        raise SceneError("--dt must be > 0")

    monkeypatch.setattr(C, "run_simulator", bad)
    with pytest.raises(SceneError):
        C.compare(resolve_scene("pentagon-bounce"), ["mujoco"])


def test_document_has_the_contract_fields_and_is_strict_json(calls):
    result = C.compare(resolve_scene("pentagon-bounce"), ["linear", "mujoco"], dts=[1e-3])
    doc = json.loads(json.dumps(finite(result.to_dict()), allow_nan=False))
    assert doc["scene"] == "pentagon-bounce"
    assert "impacts" not in doc["reference"] and doc["reference"]["status"] == "t_end"
    for row in doc["engines"]:
        assert CONTRACT_ROW <= set(row)
    assert doc["engines"][0]["dt"] is None and doc["engines"][1]["dt"] == 1e-3
    assert doc["engines"][1]["effective_restitution"] == pytest.approx(0.5)


def test_table_has_one_row_per_run(calls):
    result = C.compare(resolve_scene("pentagon-bounce"), ["pybullet", "mujoco"], dts=[1e-3])
    text = C.format_compare(result)
    assert "engine exploded" in text
    rows = [
        f
        for f in map(str.split, text.splitlines())
        if f[:2] in (["pybullet", "0.001"], ["mujoco", "0.001"])
    ]
    assert len(rows) == 2


# ----------------------------------------------------------------------------- real runs


def _available(module: str, name: str) -> bool:
    try:
        mod = __import__(module, fromlist=[name])
        return hasattr(mod, name)
    except Exception:
        return False


needs_reference = pytest.mark.skipif(
    not _available("reference.simulate", "simulate"), reason="reference simulator not built"
)


@needs_reference
def test_reference_against_itself_on_a_real_scene_agrees_exactly():
    scene = resolve_scene("pentagon-bounce").with_run(t_end=1.0)
    result = C.compare(scene, ["reference"])
    m = result.runs[0].metrics
    assert m.impacts_matched == len(result.reference.impacts) > 0
    assert (m.impact_time_error, m.energy_error) == (0.0, 0.0)
    assert m.attitude_error < 1e-15  # roundoff of q⁻¹q for a not exactly unit q


needs_engines = pytest.mark.skipif(
    not (
        _available("engines.mujoco", "simulate_mujoco")
        and _available("engines.pybullet", "simulate_pybullet")
    ),
    reason="engine adapters not built",
)


@needs_reference
@needs_engines
def test_tuned_engines_reproduce_the_first_pentagon_impacts_and_restitution():
    scene = resolve_scene("pentagon-bounce").with_run(t_end=1.0)
    result = C.compare(scene, ["mujoco", "pybullet"], dts=[1e-4])
    n_ref = len(result.reference.impacts)
    assert n_ref >= 10
    for run in result.runs:
        m = run.metrics
        assert m.impacts_matched == m.reference_impacts == n_ref, run.engine
        assert m.restitution.median == pytest.approx(scene.restitution, rel=0.01), run.engine


needs_linear = pytest.mark.skipif(
    not _available("reference.linear.simulate", "simulate_linear"), reason="no linear model"
)


@needs_reference
@needs_linear
def test_linear_model_matches_the_reference_at_tiny_inclination_through_chatter():
    # α ~ 1e-9: the linearisation error is negligible; the two simulators complete chatter
    # sequences at different bounces, which the tail rule must not call a divergence
    result = C.compare(resolve_scene("tiny-alpha"), ["linear"])
    m = result.runs[0].metrics
    assert m.impacts_matched + m.skipped_reference == m.reference_impacts
    assert m.impacts_matched > 100
    assert m.impact_time_error < 1e-6 * result.reference.t_final
    assert m.first_divergence_time is None
