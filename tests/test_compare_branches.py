"""`harness compare` past the reference's undecidable state: the branch each run follows
(harness.branches.follow) on runs built from one branch's own impacts and energy, on the
demo scene with real engines, in --json and in `harness report`."""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest

from harness.branches.follow import follow_branches
from harness.branches.spread import branches
from harness.cli import main
from harness.compare import compare, format_compare
from harness.compare.branch_text import branch_sentence
from harness.scenes import resolve_scene
from reference.trajectory import ImpactEvent
from tests.test_impact_law_runs import STARTS, _on_ground

BRANCH_FIELDS = {
    "branch", "law", "order", "impacts", "skipped", "of", "until", "distance",
    "impacts_distance", "energy_distance", "t_u", "t_energy", "energy_run",
    "followed_reference", "margin", "decided", "candidates", "sentence",
}  # fmt: skip


@pytest.fixture(scope="module")
def flat_triangle():
    """A triangle starting flat on its three vertices: undecidable at t = 0, and ten
    branches (moreau, sequential, compliant, compliant-mass, the sequential law in each
    order)."""
    n, rotation, velocity, omega = STARTS["three (a flat triangle)"]
    scene, _ = _on_ground(n, rotation, velocity, omega)
    return scene, branches(scene)


def engine_like(branch_traj, dt: float, delay: float):
    """A fixed-step run made of a branch's own samples and impacts, each impact seen
    `delay` late (as an engine sees it at the end of a step)."""
    seen = [dataclasses.replace(e, t=e.t + delay, t_lo=0.0) for e in branch_traj.impacts]
    return dataclasses.replace(branch_traj, engine="synthetic", dt=dt, impacts=seen)


def _same_run(a, b) -> bool:
    return np.array_equal(a.impact_times(), b.impact_times()) and np.array_equal(
        a.impact_contacts(), b.impact_contacts()
    )


@pytest.mark.parametrize("which", range(10))
def test_a_run_made_of_one_branch_follows_that_branch_to_its_end(flat_triangle, which):
    scene, spread = flat_triangle
    built = spread.branches[which]
    run = engine_like(built.trajectory, dt=1e-4, delay=5e-5)
    follow = follow_branches(run, spread, scene, first_divergence=None)
    chosen = follow.nearest
    chosen_traj = next(b.trajectory for b in spread.branches if b.name == chosen.branch)
    # the branch it was built from, or one that is the same run (sequential is one order)
    assert chosen.branch == built.name or _same_run(chosen_traj, built.trajectory)
    assert follow.decided and chosen.energy_distance == 0.0
    after = int(np.sum(built.trajectory.impact_times() > 0.0))
    assert chosen.of == after and chosen.impacts + chosen.skipped == after
    assert chosen.until == pytest.approx(built.trajectory.t[-1])
    others = [c for c in follow.candidates if c.distance > chosen.distance]
    if chosen.of:  # a branch without impacts after t_u (compliant: it flies off) ties at 0
        assert all(c.impacts < chosen.impacts for c in others)


def test_the_sequential_law_in_its_own_order_is_one_branch(flat_triangle):
    """`sequential` (fastest approach first) is the same run as one of its orders: the
    two are at one distance from any run."""
    scene, spread = flat_triangle
    by_name = {b.name: b for b in spread.branches}
    twins = [n for n, b in by_name.items() if n != "sequential"
             and _same_run(b.trajectory, by_name["sequential"].trajectory)]  # fmt: skip
    assert len(twins) == 1
    run = engine_like(by_name["moreau"].trajectory, dt=1e-4, delay=5e-5)
    d = {c.branch: c.distance for c in follow_branches(run, spread, scene, None).candidates}
    assert d["sequential"] == d[twins[0]]


@pytest.fixture(scope="module")
def demo(request):
    """compare triangle-chatter with MuJoCo (the demo's first engine), no horizons."""
    pytest.importorskip("mujoco")
    return compare("triangle-chatter", ["mujoco"], horizon_runs=0)


def _check_engine_branch(result, label):
    run = next(r for r in result.runs if r.label == label)
    t_u = result.reference.t_final
    assert result.reference.status.value == "simultaneous_impact"
    names = [b.name for b in result.spread.branches]
    follow = run.branch
    assert follow is not None and follow.nearest.branch in names
    assert len(follow.candidates) == len(names)
    n = follow.nearest
    assert n.impacts + n.skipped <= n.of and n.until >= t_u
    assert n.distance == pytest.approx(n.impacts_distance + n.energy_distance)
    t_div = run.metrics.first_divergence_time
    assert follow.followed_reference == (t_div is None or t_div >= t_u)
    text = format_compare(result)
    assert max(len(line) for line in text.splitlines()) <= 100
    row = next(line for line in text.splitlines()[::-1] if line.startswith(label))
    if follow.followed_reference:
        assert row.split()[2] == n.branch
    else:  # it left the reference before t_u: no branch named
        assert row == f"{label}: left the reference before t_u: no branch"
        assert not follow.decided
        assert branch_sentence(run) == f"{label} left the reference before t_u: no branch."


def test_the_demo_scene_names_the_branch_mujoco_follows(demo):
    _check_engine_branch(demo, "mujoco 1e-04")
    from harness.recording import branch_notes

    notes = branch_notes(demo)  # the recording's summary tab
    assert any(line.startswith("- mujoco 1e-04") for line in notes)


@pytest.mark.slow
def test_the_demo_scene_names_the_branch_pybullet_follows():
    pytest.importorskip("pybullet")
    result = compare("triangle-chatter", ["pybullet"], horizon_runs=0)
    _check_engine_branch(result, "pybullet 1e-04")


def test_the_json_has_every_branch_field_and_the_report_reads_it(demo, tmp_path):
    from harness.cli.common import finite

    doc = json.loads(json.dumps(finite(demo.to_dict()), allow_nan=False))
    row = doc["engines"][0]
    assert set(row["branch"]) == BRANCH_FIELDS
    assert {c["branch"] for c in row["branch"]["candidates"]} == {
        b["branch"] for b in doc["branches"]["branches"]
    }
    assert doc["branches"]["undecidable"]["t"] == doc["reference"]["t_final"]
    path = tmp_path / "compare.json"
    path.write_text(json.dumps(doc))
    out = tmp_path / "report.html"
    assert main(["report", str(path), "--out", str(out)]) == 0
    assert row["branch"]["sentence"] in out.read_text().replace("&#x27;", "'")


def _resting_after(traj, t_end: float, extra_impacts=()):
    """The run `traj` held at its last state until t_end, with `extra_impacts` added."""

    def longer(a):
        return np.concatenate([a, a[-1:]])

    return dataclasses.replace(
        traj, engine="synthetic", t=np.append(traj.t, t_end), position=longer(traj.position),
        quaternion=longer(traj.quaternion), velocity=longer(traj.velocity),
        angular_velocity=longer(traj.angular_velocity),
        kinetic_energy=longer(traj.kinetic_energy),
        potential_energy=longer(traj.potential_energy),
        impacts=[*traj.impacts, *extra_impacts],
    )  # fmt: skip


def test_a_branch_at_rest_is_left_by_the_first_real_bounce_after_it():
    """triangle-chatter's moreau branch ends at the singularity: a run that is that
    branch and then rests stays with it to its end; one that bounces (at a speed no
    chatter tail has) after the branch came to rest leaves it at that bounce."""
    scene = resolve_scene("triangle-chatter")
    spread = branches(scene)
    moreau = next(b for b in spread.branches if b.name == "moreau")
    assert moreau.status == "singularity"
    t_rest = moreau.trajectory.t[-1]
    rests = _resting_after(moreau.trajectory, 1.0)
    follow = follow_branches(rests, spread, scene, None)
    by_name = {c.branch: c for c in follow.candidates}
    assert by_name["moreau"].until == 1.0
    bounce = ImpactEvent(t_rest + 0.1, 0, 1.0, -1.0, 0.5)
    bounces = _resting_after(moreau.trajectory, 1.0, [bounce])
    by_name = {c.branch: c for c in follow_branches(bounces, spread, scene, None).candidates}
    assert by_name["moreau"].until == bounce.t


def test_the_branches_figure_names_every_branch_once_in_one_legend(flat_triangle, monkeypatch):
    """One legend for both panels; branches whose curves are the same to roundoff are one
    line named together (compliant = compliant-mass), every other branch its own line."""
    from matplotlib.figure import Figure

    from harness.branches.plot import plot_spread

    _, spread = flat_triangle
    saved = []
    monkeypatch.setattr(Figure, "savefig", lambda fig, *a, **k: saved.append(fig))
    plot_spread(spread, "unused.png")
    (fig,) = saved
    (legend,) = fig.legends
    assert all(ax.get_legend() is None for ax in fig.axes)
    labels = [t.get_text().split(": ")[0] for t in legend.get_texts()]
    named = [name for label in labels for name in label.split(" = ")]
    every = ["paper", *(b.name for b in spread.branches)]
    assert sorted(n for n in named if not n.startswith("t_u")) == sorted(every)
    assert "compliant = compliant-mass" in labels  # one outcome on the flat triangle
    curves = [label for label in labels if not label.startswith("t_u")]
    whole, after = fig.axes
    assert len(whole.get_lines()) == len(labels) and len(after.get_lines()) == len(curves)
    branches = {b.name: b for b in [spread.paper, *spread.branches]}
    for label in curves:  # the branches named together: one curve to roundoff
        (t0, e0), *others = [branches[n].energy_curve for n in label.split(" = ")]
        for t1, e1 in others:
            assert np.allclose(t1, t0, rtol=1e-9) and np.allclose(e1, e0, rtol=1e-9, atol=0)
