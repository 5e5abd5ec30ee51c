"""Engines on the bumpy ground: the model MuJoCo builds (vertex spheres over the
plane, bump spheres under the face, and no other pair colliding) and its run against the
oracle on the short rolling scene."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from engines.base import contact_kinematics
from engines.mujoco import set_state, simulate_mujoco
from engines.mujoco_model import contact_geom_pairs, load_model
from harness.transition.scene import transition_scene
from reference import quaternion as qt
from tests.conftest import require_extra
from tests.oracle.simulate import simulate as oracle_simulate

N = 20


@pytest.fixture(scope="module")
def short_scene():
    """The 20-gon rolling at tilt 0.01 over bumps of 1e-4 m (Δ/a = 2e-3): rim impacts,
    then the first bump impact near t = 0.028 s."""
    return transition_scene(delta=1e-4, tilt=0.01, n=N, restitution=0.0, t_end=0.04)


def _contacts_at(scene, y):
    """(geom1, geom2) names of the contacts MuJoCo finds at state y."""
    model = load_model(scene, 1e-4)
    data = mujoco.MjData(model)
    set_state(model, data, y)
    mujoco.mj_forward(model, data)
    names = set()
    for c in data.contact[: data.ncon]:
        pair = sorted(mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_GEOM, g) for g in c.geom)
        names.add(tuple(pair))
    return names


def _state(z, rotation_vector=(0.0, 0.0, 0.0), xy=(0.0, 0.0)):
    y = np.zeros(13)
    y[0:3] = (*xy, z)
    y[3:7] = qt.from_rotation_vector(np.array(rotation_vector))
    return y


def test_mujoco_bumpy_model_numbers_vertices_then_bumps(short_scene):
    pairs = contact_geom_pairs(short_scene)
    assert pairs[:N] == [(f"vertex{k}", "ground") for k in range(N)]
    assert pairs[N:] == [(f"bump{j}", "face") for j in range(3)]


def test_mujoco_bumpy_model_collides_the_face_only_with_bumps(short_scene):
    """Lying flat 1e-6 a into the bumps: only bump–face contacts, though the face
    cylinder's bottom edge lies within the plane's margin of nothing and the vertices
    sit Δ above the plane."""
    a = short_scene.body.radius
    delta = short_scene.ground.bump_height * a
    found = _contacts_at(short_scene, _state(delta - 1e-6 * a))
    assert found == {("bump0", "face"), ("bump1", "face"), ("bump2", "face")}


def test_mujoco_bumpy_model_collides_vertices_only_with_the_plane(short_scene):
    """Vertex 0's sphere centred on bump 0's sphere (the body shifted and tilted 0.3 so
    that it lies there, Δ above the plane): no vertex–bump contact."""
    a = short_scene.body.radius
    b = short_scene.ground.bump_radius * a
    delta = short_scene.ground.bump_height * a
    tilt = 0.3
    y = _state(a * np.sin(tilt) + delta, (0.0, tilt, 0.0), xy=(b - a * np.cos(tilt), 0.0))
    found = _contacts_at(short_scene, y)
    assert not any("vertex0" in pair and "bump0" in pair for pair in found), found


def test_mujoco_bumpy_model_never_collides_the_face_with_the_plane(short_scene):
    """Flat and sunk 3 sphere radii into the floor (the face cylinder's bottom below the
    plane): every vertex meets the plane and every bump the face, the face not the plane."""
    r = 1e-3 * short_scene.body.radius
    found = _contacts_at(short_scene, _state(-3 * r))
    expected = {("ground", f"vertex{k}") for k in range(N)}
    expected |= {(f"bump{j}", "face") for j in range(3)}
    assert found == expected


def test_mujoco_on_the_short_bumpy_scene_follows_the_oracle(short_scene):
    """At dt = 1e-5 the leading 40 impacts hit the same contacts as the exact oracle's
    (rim vertices, then the first bumps), the first bump impact within 1e-4 s (measured:
    47 leading impacts agree, the first bump 2.4e-5 s apart)."""
    exact = oracle_simulate(short_scene)
    engine = simulate_mujoco(short_scene, dt=1e-5)
    first_bump = [next(e.t for e in tr.impacts if e.contact >= N) for tr in (exact, engine)]
    lead = 40
    assert [e.contact for e in engine.impacts[:lead]] == [e.contact for e in exact.impacts[:lead]]
    assert any(e.contact >= N for e in exact.impacts[:lead])
    assert abs(first_bump[0] - first_bump[1]) < 1e-4


# ------------------------------------------------------------------ PyBullet and Drake
def _tilted_over_the_corner(scene, lift):
    """Tilted 0.3 about the axis (1, 1, 0)/√2, its lowest vertex `lift` above the plane:
    a square face of side 2a reaches 0.43 a sin 0.3 further down than any vertex."""
    y = _state(0.0, 0.3 * np.array([1.0, 1.0, 0.0]) / np.sqrt(2.0))
    gaps = contact_kinematics(scene, y[None])[0][0]
    y[2] = lift - gaps[:N].min()
    return y


def test_drake_bumpy_model_never_collides_the_face_with_the_half_space(short_scene):
    """The face box's corner 0.006 a into the half space, the vertices 1e-4 a above it
    and the bumps far below the face: Drake reports no contact (the filter excludes
    the face–half space pair)."""
    require_extra("pydrake", "drake")
    from engines import drake as dk

    y = _tilted_over_the_corner(short_scene, 1e-4 * short_scene.body.radius)
    model = dk.build_model(short_scene, dk.contact_settings(short_scene, 1e-4, "sap"))
    context = model.diagram.CreateDefaultContext()
    pc = model.plant.GetMyMutableContextFromRoot(context)
    model.plant.SetPositionsAndVelocities(pc, dk.to_drake_state(y))
    query = model.plant.get_geometry_query_input_port().Eval(pc)
    assert query.ComputePointPairPenetration() == []


def test_drake_bumpy_model_reports_the_reference_gaps_of_both_kinds(short_scene):
    """Centre at the bumps' height, tilted 4.5e-3: vertices on the low side below the
    plane, bumps on the low side above the face; every pair Drake reports is a scene
    contact of either kind at depth −gap (1e-12)."""
    require_extra("pydrake", "drake")
    from engines import drake as dk

    y = _state(short_scene.ground.bump_height, (0.004, -0.002, 0.0))
    gaps = contact_kinematics(short_scene, y[None])[0][0]
    model = dk.build_model(short_scene, dk.contact_settings(short_scene, 1e-4, "sap"))
    context = model.diagram.CreateDefaultContext()
    pc = model.plant.GetMyMutableContextFromRoot(context)
    model.plant.SetPositionsAndVelocities(pc, dk.to_drake_state(y))
    query = model.plant.get_geometry_query_input_port().Eval(pc)
    depth = {}
    for pair in query.ComputePointPairPenetration():
        k = model.contact_of.get(pair.id_A, model.contact_of.get(pair.id_B))
        assert k is not None, "a pair that is no scene contact"
        depth[k] = pair.depth
    assert set(depth) == set(np.flatnonzero(gaps < 0))
    assert any(k >= N for k in depth) and any(k < N for k in depth)
    for k, d in depth.items():
        assert abs(d + gaps[k]) < 1e-12


def test_pybullet_bumpy_model_reports_the_reference_gaps_of_the_bumps(short_scene):
    """Bullet's distance from the face to each bump sphere is the reference's bump gap
    to r(1 − cos α) = 5e-10 m, as on three_point ground (the face an implicit cylinder:
    the importer's convex hull put it 1e-3 m low)."""
    from engines.pybullet import build_world, pb

    h = build_world(short_scene, 1e-5)
    try:
        y = _state(0.0, (0.004, -0.002, 0.0))
        y[2] = 2e-4 * short_scene.body.radius + short_scene.ground.bump_height
        pos, q = [float(v) for v in y[0:3]], [float(y[4]), float(y[5]), float(y[6]), float(y[3])]
        pb.resetBasePositionAndOrientation(h.body, pos, q, physicsClientId=h.client)
        gaps = contact_kinematics(short_scene, y[None])[0][0]
        for j, gid in enumerate(h.ground[1:]):
            d = min(
                cp[8] for cp in pb.getClosestPoints(h.body, gid, 0.01, physicsClientId=h.client)
            )
            assert d == pytest.approx(gaps[N + j], abs=2e-8 * short_scene.body.radius)
    finally:
        pb.disconnect(h.client)


def test_pybullet_on_the_short_bumpy_scene_follows_the_reference(short_scene):
    """At dt = 1e-5 every one of the reference's 40 impacts (34 rim, then the first
    bumps) is reproduced: same contact, times within 3 dt + 1 % (measured: 40/40)."""
    from harness.compare import compare

    result = compare(short_scene, ["pybullet"], dts=[1e-5])
    row = result.to_dict()["engines"][0]
    assert row["impacts"] == 40 and row["impacts_matched"] == 40
