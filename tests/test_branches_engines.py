"""`harness branches --engine`: engines started just before the first undecidable state
and set against every branch (harness.branches.engines).  A plug-in engine that is the
exact reference under one law is found to follow that law at distance ~0; the verdict
rule (factor 3, distance falling with dt); the suite's landings start on their
contacts."""

from __future__ import annotations

import json

import numpy as np
import pytest

from harness import simulators
from harness.branches import engines as E
from harness.branches.suite import LANDINGS, landing
from harness.cli import main
from harness.horizon.state import flown
from reference.geometry import initial_state, scene_contact_kinematics
from reference.scene import velocity_unit

ENGINE = """
from engines.interface import engine_entry
from reference import ReferenceOptions, simulate as _simulate


def _law_engine(law):
    @engine_entry(fixed_step=False)
    def simulate(scene, *, dt=None, t_end=None):
        return _simulate(scene, t_end=t_end, options=ReferenceOptions(impact_law=law))
    return simulate


moreau = _law_engine("moreau")
compliant = _law_engine("compliant")
"""


@pytest.fixture
def law_engines(tmp_path, monkeypatch):
    """Engines `as-moreau` and `as-compliant`: the reference under that law."""
    info = tmp_path / "law_engines-0.1.dist-info"
    info.mkdir()
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: law-engines\nVersion: 0.1\n")
    (info / "entry_points.txt").write_text(
        "[harness.engines]\nas-moreau = law_engines:moreau\nas-compliant = law_engines:compliant\n"
    )
    (tmp_path / "law_engines.py").write_text(ENGINE)
    monkeypatch.syspath_prepend(str(tmp_path))
    simulators.refresh()
    yield
    simulators.refresh()


@pytest.mark.parametrize("law", ["moreau", "compliant"])
def test_an_engine_that_is_the_reference_under_a_law_follows_that_law(law_engines, law):
    """(On the flat triangle every vertex has one effective mass, so `compliant` and
    `compliant-mass` are one outcome there.)"""
    st = E.study(landing("landing-triangle-spin"), [f"as-{law}"], [None])
    (run,) = st.runs
    (name,) = [n for n in run.distances if law in n.split(" = ")]
    assert run.verdict == f"follows {name}"
    assert run.distances[name] <= 1e-9
    others = [d for n, d in run.distances.items() if n != name]
    assert min(others) >= 1e-3


def test_the_json_names_every_outcome_and_the_verdict(law_engines, capsys):
    assert main(["branches", "landing-square-edge", "--engine", "as-moreau", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    (st,) = doc["studies"]
    assert st["t_u"] == 0.0 and st["contacts"] == [0, 1]
    names = [o["name"] for o in st["outcomes"]]
    branches = {b for o in st["outcomes"] for b in o["branches"]}
    assert {"moreau", "sequential", "compliant", "compliant-mass", "sequential[1,0]"} <= branches
    (run,) = st["runs"]
    assert run["verdict"] == "follows moreau" and set(run["distances"]) == set(names)


def _run(dt, distances):
    return E.EngineAtImpact("e", dt, "done", distances)


def test_follows_needs_a_factor_three_and_a_distance_falling_with_dt():
    runs = [_run(1e-3, {"a": 0.2, "b": 0.9}), _run(1e-4, {"a": 0.05, "b": 0.9})]
    E.verdicts(runs)
    assert [r.verdict for r in runs] == ["follows a", "follows a"]
    runs = [_run(1e-3, {"a": 0.05, "b": 0.9}), _run(1e-4, {"a": 0.2, "b": 0.9})]
    E.verdicts(runs)
    assert [r.verdict for r in runs] == ["none of the laws", "none of the laws"]
    runs = [_run(1e-3, {"a": 0.1, "b": 0.25})]
    E.verdicts(runs)
    assert runs[0].verdict == "between a and b"
    runs = [_run(1e-3, {"a": 0.1, "b": 0.9})]
    E.verdicts(runs)
    assert runs[0].verdict == "undecided"


def test_a_distance_that_barely_falls_with_dt_is_not_following():
    runs = [_run(1e-3, {"a": 0.072, "b": 0.9}), _run(1e-4, {"a": 0.054, "b": 0.9})]
    E.verdicts(runs)
    assert [r.verdict for r in runs] == ["none of the laws", "none of the laws"]


def test_a_fixed_step_engine_meets_the_impact_mid_step():
    scene = landing("landing-triangle-spin")
    lead, dt = 0.02, 1e-3
    y_u = initial_state(scene.initial)
    y0, lead0 = E.start_before(scene, 0.0, y_u, lead)
    y_dt, lead_dt = E.mid_step_start(scene, 0.0, y_u, y0, lead0, dt)
    assert lead_dt == lead0 + 0.5 * dt
    # its start is the common start carried back half a step by free flight
    assert np.allclose(flown(scene, y_dt, 0.5 * dt), y0, rtol=0, atol=1e-14)
    assert E.mid_step_start(scene, 0.0, y_u, y0, lead0, None) == (y0, lead0)


@pytest.mark.parametrize("name", list(LANDINGS))
def test_each_landing_starts_on_several_contacts(name):
    scene = landing(name)
    from reference.geometry import initial_state

    y = initial_state(scene.initial)
    gap, vn = scene_contact_kinematics(scene, y[None, :])
    touching = np.flatnonzero(gap[0] <= 1e-14)
    assert len(touching) >= 2
    assert vn[0, touching].min() < -0.1 * velocity_unit(scene)


def test_the_plot_is_written_and_named(law_engines, tmp_path, capsys):
    out = tmp_path / "laws.png"
    argv = ["branches", "landing-hexagon", "--engine", "as-compliant", "--json", "--plot", str(out)]
    assert main(argv) == 0
    doc = json.loads(capsys.readouterr().out)
    assert out.stat().st_size > 0 and doc["plot"] == str(out)
    (run,) = doc["studies"][0]["runs"]
    assert run["verdict"].startswith("follows compliant")  # six contacts: its own law


def test_the_study_text_names_every_outcome_and_contact_in_words(law_engines, capsys):
    """One row per outcome by its name, one column per run, the contacts as v0, v1, and
    no numbered outcome to look up; every line within 100 columns."""
    assert main(["branches", "landing-square-edge", "--engine", "as-moreau"]) == 0
    text = capsys.readouterr().out
    lines = text.splitlines()
    assert "contacts v0, v1;" in text and "(1)" not in text
    top = next(i for i, line in enumerate(lines) if line.startswith("outcome"))
    assert lines[top].split()[-1] == "as-moreau"
    names = [line.rsplit(None, 1)[0].strip() for line in lines[top + 2 :] if "  " in line]
    assert "moreau" in names and "compliant = compliant-mass" in names
    assert "  as-moreau: follows moreau (at roundoff" in text
    assert max(map(len, lines)) <= 100


def test_the_suite_shows_progress_on_stderr_and_only_json_on_stdout(
    law_engines, monkeypatch, capsys
):
    from harness import progress

    monkeypatch.setattr(progress, "PLAIN_FIRST_S", 0.0)  # a line at every run
    monkeypatch.setattr(progress, "PLAIN_EVERY_S", 0.0)
    monkeypatch.setattr(progress, "bars_wanted", lambda: False)
    argv = ["branches", "--suite", "--engine", "as-moreau", "--engine", "as-compliant", "--json"]
    assert main(argv) == 0
    out, err = capsys.readouterr()
    doc = json.loads(out)
    runs = 2 * len(LANDINGS)
    assert len(doc["studies"]) == len(LANDINGS)
    assert f"branches: 1/{runs} runs" in err and f"branches: {runs}/{runs} runs in" in err
    assert "now landing-hexagon: as-compliant" in err


def test_the_laws_figure_has_one_legend_naming_every_law_drawn(monkeypatch):
    """Every curve of every panel is named: one legend for the figure, each law its own
    style, the legend's, in every panel."""
    from matplotlib.figure import Figure

    from harness.branches.plot import plot_engines

    saved = []
    monkeypatch.setattr(Figure, "savefig", lambda fig, *a, **k: saved.append(fig))
    laws = ["moreau", "compliant", "compliant-mass"]
    runs = [E.EngineAtImpact("e", dt, "t_end", {law: d * (i + 1) for i, law in enumerate(laws)})
            for dt, d in ((1e-3, 1e-2), (1e-4, 1e-3))]  # fmt: skip
    outcomes = [E.Outcome([law], law, None, np.zeros(13)) for law in laws]
    st = E.ImpactStudy("s", 0.0, [0, 1], 0.02, 0.02, outcomes, runs)
    plot_engines([st, st], "unused.png")
    (fig,) = saved
    (legend,) = fig.legends
    assert [t.get_text() for t in legend.get_texts()] == laws

    def style(line):
        return line.get_color(), line.get_linestyle(), line.get_marker()

    legend_styles = [style(h) for h in legend.legend_handles]
    assert len(set(legend_styles)) == len(laws)
    for ax in fig.axes:
        assert ax.get_legend() is None
        assert [style(line) for line in ax.get_lines()] == legend_styles
