"""Engines on the bumpy ground (issue 32): the model MuJoCo builds (vertex spheres over the
plane, bump spheres under the face, and no other pair colliding) and its run against the
oracle on the short rolling scene."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from engines.mujoco import set_state, simulate_mujoco
from engines.mujoco_model import contact_geom_pairs, load_model
from harness.transition.scene import transition_scene
from reference import quaternion as qt
from tests.oracle.simulate import simulate as oracle_simulate

N = 20


@pytest.fixture(scope="module")
def short_scene():
    """The 20-gon rolling at tilt 0.01 over bumps of 1e-4 m (Δ/a = 2e-3): rim impacts,
    then the first bump impact near t = 0.028 s."""
    return transition_scene(delta=1e-4, tilt=0.01, n=N, t_end=0.04)


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
