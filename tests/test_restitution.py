"""`harness restitution`: the study's own arithmetic on the exact reference, small engine
runs, the command line and the report section."""

from __future__ import annotations

import json

import numpy as np
import pytest

from harness.cli import main
from harness.restitution.drops import drop_scene, watched_point
from harness.restitution.study import EVENT_LEAD, Grid, run_study
from reference.geometry import initial_state
from tests.conftest import require_extra
from tests.oracle.body import BodyModel
from tests.oracle.impact import impact_impulse


@pytest.fixture(scope="module")
def reference_study():
    grid = Grid(gammas=(0.3, 0.8), speeds=(1e-3, 1.0), dts=(1e-4,), geometries=("vertex", "bump"))
    return run_study(["reference"], grid)["engines"][0]


def test_reference_bounces_with_gamma_to_1e12(reference_study):
    for r in reference_study["rows"]:
        assert r["outcome"] == "ok"
        assert abs(r["e_eff"] - r["gamma"]) <= 1e-12
        assert r["faithful"] and r["penetration"] == 0.0 and r["contact_time"] == 0.0


def test_reference_loses_the_exact_energy_with_the_oracles_w(reference_study):
    """ΔE = −(1 − γ²) ½ u⁻²/w, w from the independent oracle (J M⁻¹ Jᵀ in numpy) at the
    impact: the drop's attitude (no rotation before it), its centre lowered by the
    initial gap along the normal."""
    for r in reference_study["rows"]:
        scene = drop_scene(r["geometry"], r["gamma"], r["speed"], EVENT_LEAD, 1e-2)
        model = BodyModel.from_scene(scene)
        y = initial_state(scene.initial)
        gap, normal, *_ = model.contacts(y, np.array([0]))
        y[2] -= gap[0] / normal[0][2]
        oracle = impact_impulse(model, y, 0, r["gamma"])
        w = -(1 + r["gamma"]) * oracle.u_pre / oracle.impulse
        assert r["w"] == pytest.approx(w, rel=1e-12)
        loss = (1 - r["gamma"] ** 2) * 0.5 * r["u_pre"] ** 2 / w
        assert r["energy_loss_exact"] == pytest.approx(loss, rel=1e-12)
        assert r["energy_change"] == pytest.approx(-loss, rel=1e-9)
        assert not r["energy_gained"]


def test_reference_edge_is_undecidable_and_left_out_of_the_contract():
    grid = Grid(gammas=(0.5,), speeds=(0.1,), dts=(1e-4,), geometries=("edge", "vertex"))
    doc = run_study(["reference"], grid)["engines"][0]
    edge = next(r for r in doc["rows"] if r["geometry"] == "edge")
    assert edge["outcome"].startswith("run simultaneous_impact") and not edge["applicable"]
    everything = next(c for c in doc["contract"] if c["geometry"] == "all")
    assert everything["range"] == [0.1, 0.1]


def test_edge_watches_the_midpoint_of_two_vertices_at_one_height():
    scene = drop_scene("edge", 0.5, 1.0, 1e-4, 1e-2)
    from reference.geometry import scene_contact_kinematics

    gap, vn = scene_contact_kinematics(scene, initial_state(scene.initial)[None])
    assert gap[0, 0] == pytest.approx(gap[0, 1], abs=1e-15)
    assert np.all(gap[0, 2:] > gap[0, 0] + 0.05)
    pts, flat = watched_point("edge")
    assert flat and np.linalg.norm(pts[0]) == pytest.approx(np.cos(np.pi / 5))


@pytest.mark.parametrize("engine", ["mujoco", "pybullet", "drake"])
def test_engine_bounces_within_one_percent_at_dt_1e4_fast_impacts(engine):
    """A fast vertex impact (u⁻ = 1) at dt = 1e-4, γ = 0.8, at the three default onset
    phases: every adapter's mapping gives γ within 1 %, loses energy (no gain) and
    penetrates for a finite time."""
    if engine == "drake":
        require_extra("pydrake", "drake")
    grid = Grid(gammas=(0.8,), speeds=(1.0,), dts=(1e-4,), geometries=("vertex",))
    rows = run_study([engine], grid)["engines"][0]["rows"]
    assert len(rows) == 3
    for row in rows:
        assert row["outcome"] == "ok"
        assert abs(row["e_error"]) <= 0.01
        assert row["energy_change"] < 0 and not row["energy_gained"]
        assert row["penetration"] > 0 and row["contact_time"] > 0


def test_drake_sap_bounce_depends_on_the_onset_phase():
    """SAP's mapping is exact at the middle phase; at γ = 0.3 (16-step contact) an onset
    early in the step bounces more than γ and a late one less, by more than 1 %."""
    require_extra("pydrake", "drake")
    grid = Grid(gammas=(0.3,), speeds=(1.0,), dts=(1e-4,), geometries=("vertex",))
    rows = run_study(["drake"], grid)["engines"][0]["rows"]
    err = {r["phase"]: r["e_error"] for r in rows}
    assert err[0.1] > 0.01 and err[0.9] < -0.01 and abs(err[0.5]) < 0.01


def test_mujoco_slow_impacts_lose_gamma_to_gravity_in_the_contact():
    """At u⁻ = g dt the one-step contact's gravity impulse is not small: MuJoCo's e_eff
    falls below γ by more than 1 % (what the contract's lower speed limit says)."""
    pytest.importorskip("mujoco")
    grid = Grid(gammas=(0.5,), speeds=(1e-3,), dts=(1e-3,), geometries=("vertex",), phases=(0.5,))
    (row,) = run_study(["mujoco"], grid)["engines"][0]["rows"]
    assert row["e_error"] < -0.01 and not row["faithful"]


def test_cli_json_plot_and_out(tmp_path, capsys):
    out = tmp_path / "r.json"
    args = ["restitution", "--engine", "reference", "--gamma", "0.5", "--speed", "0.1"]
    args += ["--geometry", "vertex", "--plot", str(tmp_path / "plots"), "--out", str(out)]
    assert main([*args, "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["kind"] == "restitution" and "provenance" in doc
    assert doc["engines"][0]["rows"][0]["e_eff"] == pytest.approx(0.5, abs=1e-12)
    assert (tmp_path / "plots" / "restitution-reference.png").stat().st_size > 1000
    assert json.loads(out.read_text())["kind"] == "restitution"
    # again without --force: refused before any run, nothing replaced
    before = out.read_text()
    assert main(args) == 2
    assert out.read_text() == before


@pytest.mark.parametrize(
    "bad", [["--gamma", "0"], ["--gamma", "1.5"], ["--speed", "-1"], ["--dt", "0.5"],
            ["--phase", "0"], ["--geometry", "corner"], ["--engine", "nope"]],
)  # fmt: skip
def test_cli_bad_input_is_one_line_and_exit_2(bad, capsys, tmp_path):
    assert main(["restitution", *bad, "--out", str(tmp_path / "x.json")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("harness: error:")
    assert not (tmp_path / "x.json").exists()


def test_text_fits_100_columns():
    from harness.restitution.text import format_restitution

    grid = Grid(gammas=(0.3, 0.5), speeds=tuple(10.0**k for k in range(-6, 3)), dts=(1e-4,))
    doc = run_study(["reference"], Grid(gammas=(0.5,), speeds=(0.1,), geometries=("vertex",)))
    doc["grid"] = grid.to_dict()
    assert max(len(line) for line in format_restitution(doc).splitlines()) <= 100


def test_report_has_a_restitution_section_with_escaped_text(tmp_path):
    """The HTML report reads the command's JSON (kind "restitution"): the engine's table,
    its faithful range and figure; strings from the document are escaped."""
    grid = Grid(gammas=(0.5,), speeds=(0.1, 1.0), dts=(1e-4,), geometries=("vertex", "edge"))
    doc = run_study(["reference"], grid)
    doc["engines"][0]["mapping"] = "<b>damper</b> & co"
    path = tmp_path / "r.json"
    path.write_text(json.dumps(doc))
    out = tmp_path / "r.html"
    assert main(["report", str(path), "--out", str(out)]) == 0
    html = out.read_text()
    assert "restitution" in html and "faithful range" in html
    assert "&lt;b&gt;damper&lt;/b&gt; &amp; co" in html and "<b>damper" not in html
    assert "data:image/png;base64," in html
    assert "simultaneous_impact" in html  # the reference's edge, shown as such


def test_the_study_names_each_engine_as_it_starts():
    """The progress line's "now" is the engine being run (the default runs every
    installed fixed-step engine, some of them slow)."""
    seen, ticks = [], []
    grid = Grid(gammas=(0.5,), speeds=(1.0,), dts=(1e-3,), geometries=("vertex",), phases=(0.5,))
    run_study(["reference", "mujoco"], grid, tick=ticks.append, now=seen.append)
    assert seen == ["reference", "mujoco"]
    assert len(ticks) == len(grid.cells(False)) + len(grid.cells(True))
