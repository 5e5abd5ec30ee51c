"""`harness compare`: orchestration with stand-in simulators, then a real scene."""

from __future__ import annotations

import dataclasses
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


def test_without_an_undecidable_state_there_are_no_branches(calls):
    """A reference that does not end simultaneous_impact: `branch` and `branches` are
    null and the text has no branches paragraph."""
    result = C.compare(resolve_scene("pentagon-bounce"), ["mujoco"], dts=[1e-3])
    doc = result.to_dict()
    assert doc["branches"] is None and doc["engines"][0]["branch"] is None
    assert "undecidable state at t_u" not in C.format_compare(result)


def test_table_has_one_row_per_run(calls):
    result = C.compare(resolve_scene("pentagon-bounce"), ["pybullet", "mujoco"], dts=[1e-3])
    text = C.format_compare(result)
    assert "engine exploded" in text
    rows = [
        f
        for f in map(str.split, text.splitlines())
        if f[:2] in (["pybullet", "1e-03"], ["mujoco", "1e-03"]) and f[2] != "failed:"
    ]
    assert len(rows) == 2


def test_default_report_fits_100_columns_and_wide_has_every_column(calls):
    engines = ["pybullet-default", "mujoco-default", "linear", "mujoco"]
    result = C.compare(resolve_scene("pentagon-bounce"), engines, dts=[1e-3, 1e-4])
    text = C.format_compare(result)
    assert max(len(line) for line in text.splitlines()) <= 100
    wide = C.format_compare(result, wide=True)
    header = next(line for line in wide.splitlines() if line.startswith("engine"))
    columns = ("status", "matched  of", "ref skipped  run skipped", "t error [s]", "E error",
               "attitude window [rad]", "e_eff  e_eff impacts", "c  c stderr")  # fmt: skip
    for column in columns:
        assert column in header
    assert max(len(line) for line in wide.splitlines()) > 100


def test_wide_cells_hold_one_number_each(calls):
    """matched and of, the skipped tails of the reference and of the run, e_eff and its
    impacts are columns of their own: no cell of the wide table reads 'k/N' or 'n='."""
    result = C.compare(resolve_scene("pentagon-bounce"), ["mujoco"], dts=[1e-3])
    lines = C.format_compare(result, wide=True).splitlines()
    header = next(i for i, line in enumerate(lines) if line.startswith("engine"))
    row = lines[header + 2]
    assert "/" not in row and "n=" not in row
    m = result.runs[0].metrics
    cells = row.split()
    assert cells[5:9] == [str(m.impacts_matched), str(m.reference_impacts),
                          str(m.skipped_reference), str(m.skipped_run)]  # fmt: skip


def test_report_names_who_diverges_first_when_and_why(monkeypatch):
    """mujoco's second impact is 0.1 s late, linear's first hits another contact: linear
    diverges first, at its first impact, because of the contact."""

    def fake(engine, scene, dt=None, t_end=None, **_limits):
        traj = stand_in(engine, dt)
        if engine == "mujoco":
            traj.impacts[1] = ImpactEvent(0.7, 1, 1.0, -0.5, 0.25)
        if engine == "linear":
            traj.impacts[0] = ImpactEvent(0.3, 2, 1.0, -1.0, 0.5)
        return traj

    monkeypatch.setattr(C, "run_simulator", fake)
    result = C.compare(resolve_scene("pentagon-bounce"), ["mujoco", "linear"], dts=[1e-3])
    text = C.format_compare(result)
    first = next(line for line in text.splitlines() if line.startswith("First to diverge"))
    assert first.startswith("First to diverge: linear at t = 0.3 s")
    assert "it hit v2 instead" in text
    mujoco = next(line for line in text.splitlines() if line.startswith("mujoco 1e-03"))
    assert mujoco.split()[2] == "1" and "impact 1 (v1) 0.1 s late" in mujoco
    assert "Each run against the reference's 2 impacts" in text
    doc = result.to_dict()
    assert doc["first_to_diverge"]["engine"] == "linear"
    assert doc["engines"][0]["first_mismatch"]["kind"] == "time"
    assert doc["engines"][1]["first_mismatch"]["kind"] == "contact"
    assert doc["engines"][0]["verdict"].startswith("mujoco 1e-03: 1/2 impacts matched")


def test_no_exponent_for_runs_that_did_not_reach_the_singularity(calls):
    result = C.compare(resolve_scene("pentagon-bounce"), ["mujoco"], dts=[1e-3])
    row = result.to_dict()["engines"][0]
    assert row["exponent"]["c"] is None and "t_end" in row["exponent"]["reason"]


# ----------------------------------------------------------------------------- --out


def _diff(tmp_path, calls, name="diff.csv"):
    from harness.compare.diff import impact_diff
    from harness.io import write_table

    result = C.compare(resolve_scene("pentagon-bounce"), ["mujoco", "linear"], dts=[1e-3])
    return write_table(impact_diff(result), tmp_path / name), result


def test_impact_diff_pairs_every_reference_impact_with_the_run_impact(tmp_path, calls):
    import pyarrow.csv as pcsv

    path, result = _diff(tmp_path, calls)
    table = pcsv.read_csv(path).to_pylist()
    assert len(table) == 2 * len(result.reference.impacts)  # two runs × two impacts
    row = table[1]
    assert (row["run"], row["reference_impact"], row["status"]) == ("mujoco 1e-03", 1, "matched")
    assert row["reference_t"] == 0.6 and row["run_t"] == pytest.approx(0.601)
    assert row["d_t"] == pytest.approx(1e-3)
    assert row["d_v_normal_pre"] == 0.0 and row["run_contact"] == row["reference_contact"] == 1
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]  # no temp file left


def test_impact_diff_marks_the_first_mismatch_and_what_follows(monkeypatch, tmp_path):
    from harness.compare.diff import impact_diff

    def fake(engine, scene, dt=None, t_end=None, **_limits):
        traj = stand_in(engine, dt)
        if engine == "mujoco":
            traj.impacts[0] = ImpactEvent(0.3, 3, 1.0, -1.0, 0.5)
        return traj

    monkeypatch.setattr(C, "run_simulator", fake)
    result = C.compare(resolve_scene("pentagon-bounce"), ["mujoco"], dts=[1e-3])
    rows = impact_diff(result).to_pylist()
    assert [r["status"] for r in rows] == ["mismatch", "after_divergence"]
    assert rows[0]["mismatch_kind"] == "contact" and rows[0]["run_contact"] == 3
    assert rows[1]["run_t"] is None and rows[1]["d_t"] is None


def test_out_refuses_to_overwrite_unless_forced_and_writes_parquet(tmp_path, calls, capsys):
    import pyarrow.parquet as pq

    from harness.cli import main

    out = tmp_path / "diff.parquet"
    out.write_text("a user's file")
    argv = ["compare", "pentagon-bounce", "--engine", "mujoco", "--dt", "1e-3", "--out", str(out)]
    assert main(argv) == 2
    assert "exists" in capsys.readouterr().err and out.read_text() == "a user's file"
    assert calls == []  # refused before running anything
    assert main([*argv, "--force"]) == 0
    assert pq.read_table(out).num_rows == 2
    assert main(["compare", "pentagon-bounce", "--engine", "mujoco", "--out", "x.txt"]) == 2


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


def test_the_horizon_table_gives_the_10_and_90_percent_values_in_columns_of_their_own(
    monkeypatch,
):
    """The grid model's and the perturbed model's 10 % and 90 % matched counts, each a
    cell, in the default report and in --wide (no '15–22' range to decode)."""
    from harness.horizon.verdict import Horizon

    def fake(engine, scene, dt=None, t_end=None, **_limits):
        traj = stand_in(engine, dt)
        if engine == "mujoco":  # its second impact 0.1 s late: it diverges
            traj.impacts[1] = ImpactEvent(0.7, 1, 1.0, -0.5, 0.25)
        return traj

    monkeypatch.setattr(C, "run_simulator", fake)
    result = C.compare(resolve_scene("pentagon-bounce"), ["mujoco", "linear"], dts=[1e-3])
    mujoco, linear = result.runs
    mujoco.horizon = Horizon(2, [1.0, 2.0, 3.0], 1e-3, 0, [4.0, 5.0, 7.0], None, 0.1, 24, 0, 1e-3)
    linear.horizon = Horizon(2, None, 2e-3, 0, [6.0, 6.0, 8.0], None, 0.1, 24, 0, None)
    lines = C.format_compare(result).splitlines()
    top = next(
        i for i, line in enumerate(lines) if line.startswith("simulator  ") and "grid" in line
    )
    assert lines[top] == (
        "simulator     matched  grid 10 %  grid 90 %  within  own error  own 10 %  own 90 %"
    )
    assert lines[top + 2].split() == ["mujoco", "1e-03", "2", "1", "3", "yes", "1.0e-03", "4", "7"]
    assert lines[top + 3].split() == ["linear", "2", "-", "-", "-", "2.0e-03", "6", "8"]
    assert not any("–" in line for line in lines[top : top + 4])
    wide = C.format_compare(result, wide=True).splitlines()
    header = next(i for i, line in enumerate(wide) if line.startswith("engine"))
    assert wide[header + 2].split()[-6:] == ["1", "3", "yes", "1.0e-03", "4", "7"]


def test_a_horizon_table_too_wide_for_long_engine_names_is_split_in_two(monkeypatch):
    """Past 100 columns the columns after `matched` go into a second table, each with the
    simulator and its matched count."""
    from harness.horizon.verdict import Horizon

    def fake(engine, scene, dt=None, t_end=None, **_limits):
        traj = stand_in(engine, dt)
        if engine != "reference":  # its second impact 0.1 s late: it diverges
            traj.impacts[1] = ImpactEvent(0.7, 1, 1.0, -0.5, 0.25)
        return traj

    monkeypatch.setattr(C, "run_simulator", fake)
    result = C.compare(resolve_scene("pentagon-bounce"), ["mujoco"], dts=[1e-3])
    (run,) = result.runs
    run.engine = "an-engine-with-a-long-name"
    run.horizon = Horizon(2, [1.0, 2.0, 3.0], 1e-3, 0, [4.0, 5.0, 7.0], None, 0.1, 24, 0, 1e-3)
    lines = C.format_compare(result).splitlines()
    assert max(map(len, lines)) <= 100
    heads = [line for line in lines if line.startswith("simulator  ") and "matched" in line]
    assert len(heads) == 3  # the verdict table and the horizon's two
    assert "own 90 %" in heads[2] and "grid 10 %" in heads[1]


def test_a_long_engine_name_is_broken_over_lines_within_100_columns(calls):
    """A plug-in engine's long name: the verdict table breaks it over lines of its own
    (the row's cells beside its first line) rather than pass 100 columns."""
    result = C.compare(resolve_scene("pentagon-bounce"), ["mujoco"], dts=[1e-3])
    name = "an-engine-plugin-whose-name-alone-takes-up-more-than-fifty-columns-of-text"
    run = dataclasses.replace(result.runs[0], engine=name)
    text = C.format_compare(dataclasses.replace(result, runs=[run]))
    assert max(len(line) for line in text.splitlines()) <= 100
    lines = text.splitlines()
    header = next(i for i, line in enumerate(lines) if line.startswith("simulator"))
    width = len(lines[header + 1].split("  ")[0])  # the first column's dashes
    label, pieces = run.label.replace(" ", ""), ""
    for i, line in enumerate(lines[header + 2 :]):
        assert (line[width:].strip() != "") == (i == 0)  # the row's cells on its first line
        pieces += line[:width].strip().replace(" ", "")
        if pieces == label:
            break
    assert pieces == label
