"""DART adapter: the model's geometry and state conventions, the single-impact
restitution contract of both profiles (the tuned one over its faithful range, the
default one's rebound cut-off), and a short run against the reference."""

from __future__ import annotations

import numpy as np
import pytest

from tests.conftest import require_extra

require_extra("dartpy", "dart")

from engines import dart as dk  # noqa: E402
from harness.restitution.study import Grid, run_study  # noqa: E402
from reference import quaternion as qt  # noqa: E402
from reference.geometry import contact_points  # noqa: E402
from reference.scenes import as_scene  # noqa: E402
from reference.simulate import simulate  # noqa: E402
from tests.conftest import make_scene  # noqa: E402

SPINNING = np.concatenate(
    [[0.1, -0.2, 0.9], qt.from_rotation_vector([0.3, -0.5, 1.1]), [0.2, 0.1, -0.3]]
    + [[0.7, -0.4, 1.3]]
)


@pytest.mark.parametrize("profile", ["tuned", "default"])
def test_state_set_in_dart_reads_back_in_world_axes(profile):
    scene = make_scene()
    settings = dk.contact_settings(scene, 1e-4, profile)
    model = dk.build_model(scene, 1e-4, settings)
    dk.set_state(model, SPINNING)
    y = dk.read_state(model)
    assert np.allclose(y[:3], SPINNING[:3], atol=1e-12)
    assert abs(abs(np.dot(y[3:7], SPINNING[3:7])) - 1.0) < 1e-12
    assert np.allclose(y[7:], SPINNING[7:], atol=1e-12)


def test_vertex_spheres_sit_at_the_reference_vertices():
    """Sphere k's centre (scene units) is vertex k of the reference's geometry, so its
    distance to the ground's top face (z = −r) is the reference's gap."""
    scene = make_scene(n=7)
    settings = dk.contact_settings(scene, 1e-4, "tuned")
    model = dk.build_model(scene, 1e-4, settings)
    dk.set_state(model, SPINNING)
    q, x = SPINNING[3:7], SPINNING[:3]
    expected = x + qt.rotate(q, contact_points(scene.body, scene.ground)[:7])
    for k in range(7):
        node = model.body.getShapeNode(k)
        centre = np.asarray(node.getWorldTransform().translation()) / model.scale
        assert node.getName() == f"vertex{k}"
        assert np.allclose(centre, expected[k], atol=1e-12)


def test_tuned_units_put_the_cutoff_far_below_the_scenes_speeds():
    scene = as_scene("pentagon-bounce")
    s = dk.contact_settings(scene, 1e-4, "tuned")
    bound = dk.speed_bound(scene, 1e-4)
    clamp = dk.MAX_BOUNCING_VELOCITY / s.length_scale
    assert clamp == pytest.approx(3.0 * bound)  # no rebound reaches the clamp
    assert s.cutoff == pytest.approx(1e-3 * clamp)  # DART's own ratio: 0.1 / 100
    assert s.body_restitution * s.ground_restitution == pytest.approx(scene.restitution)
    d = dk.contact_settings(scene, 1e-4, "default")
    assert d.cutoff == dk.BOUNCING_VELOCITY_THRESHOLD
    assert d.body_restitution * d.ground_restitution == pytest.approx(scene.restitution)


def test_tuned_dart_bounces_at_gamma_over_its_faithful_range():
    grid = Grid(gammas=(0.3, 0.8), speeds=(0.1, 1.0), dts=(1e-4,), geometries=("vertex",))
    rows = run_study(["dart"], grid)["engines"][0]["rows"]
    assert len(rows) == 12
    for row in rows:
        assert row["outcome"] == "ok"
        assert abs(row["e_error"]) <= 0.01
        assert not row["energy_gained"]


def test_default_dart_rebound_below_the_cutoff_is_zero():
    """γ = 0.5: u⁻ = 1 rebounds at 0.5 (above DART's 0.1), u⁻ = 0.1 would rebound at
    0.05, which DART sets to zero."""
    grid = Grid(
        gammas=(0.5,), speeds=(0.1, 1.0), dts=(1e-4,), geometries=("vertex",), phases=(0.5,)
    )
    rows = run_study(["dart-default"], grid)["engines"][0]["rows"]
    by_speed = {r["speed"]: r for r in rows}
    assert abs(by_speed[1.0]["e_error"]) <= 0.01
    assert by_speed[0.1]["e_eff"] is None or by_speed[0.1]["e_eff"] < 0.01


def test_tuned_dart_follows_the_reference_for_the_first_impacts():
    scene = as_scene("pentagon-bounce")
    ref = simulate(scene, t_end=0.4)
    run = dk.simulate_dart(scene, 1e-4, t_end=0.4)
    assert run.status.value == "t_end" and run.engine == "dart"
    assert [e.contact for e in run.impacts] == [e.contact for e in ref.impacts]
    for e, r in zip(run.impacts, ref.impacts, strict=True):
        assert abs(e.t - r.t) < 1e-4
        assert e.v_normal_post == pytest.approx(r.v_normal_post, rel=1e-3)
    assert run.stats["wall_time_s"] > 0 and run.stats["steps"] == 4000
