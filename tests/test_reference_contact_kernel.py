"""The compiled contact phase (reference.contact_kernel) against its Python specification
(reference.contact and the Python loop of reference.simulate)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import reference.simulate as sim
from harness.scenes import resolve_scene
from reference import contact_kernel as ck
from reference.body import BodyModel, Q, V, W, X
from reference.contact import constrained_rhs, project_positions, project_velocities
from reference.scene import Body, Ground, InitialState, RunSettings, Scene


def _state_touching(held: list[int], n: int = 5):
    """A spinning, tumbling n-gon with the vertices `held` exactly on the ground
    (two held vertices: the body is rotated so both are at the same height)."""
    scene = Scene(
        name="held",
        body=Body(n=n, gyration=0.45),
        ground=Ground(),
        initial=InitialState((0, 0, 1), (0, 0, 0), (0, 0, 0), (0, 0, 0)),
        restitution=0.5,
        gravity=1.0,
        run=RunSettings(t_end=1.0),
    )
    model = BodyModel.from_scene(scene)
    rng = np.random.default_rng(len(held))
    y = np.zeros(13)
    p = model.points
    if len(held) == 1:
        axis = np.array([0.3, -0.2, 0.0])
    else:  # tilt about the chord through the two held vertices
        c = p[held[1]] - p[held[0]]
        axis = 0.35 * c / np.linalg.norm(c)
    th = np.linalg.norm(axis)
    y[Q] = np.concatenate([[np.cos(th / 2)], np.sin(th / 2) * axis / th])
    gap = model.contacts(y)[0]
    y[2] = -gap[held].min()
    y[V] = rng.normal(0, 0.3, 3)
    y[W] = rng.normal(0, 0.8, 3)
    return model, project_velocities(model, project_positions(model, y, held), held)


@pytest.mark.parametrize("held", [[0], [1, 3]])
def test_held_rhs_equals_the_python_newton_euler_solve(held):
    model, y = _state_touching(held)
    ref = constrained_rhs(model, held, compiled=False)(0.0, y)
    dy, lam = np.empty(13), np.empty(2)
    ck.held_rhs(
        y, np.ascontiguousarray(model.points[held]), model.mass, model.i1, model.i3, 1.0, dy, lam
    )
    np.testing.assert_allclose(dy, ref, rtol=0, atol=1e-13)


@pytest.mark.parametrize("held", [[0], [1, 3]])
def test_projection_equals_the_python_projections(held):
    model, y = _state_touching(held)
    y_off = y.copy()
    y_off[X] += (1e-7, -2e-7, 3e-7)
    y_off[W] += (1e-6, 2e-6, -1e-6)
    y_off[V] += (0.0, 0.0, 5e-7)
    ref = project_velocities(model, project_positions(model, y_off, held), held)
    out = y_off.copy()
    ck.project_held(out, np.ascontiguousarray(model.points[held]), model.mass, model.i1, model.i3)
    np.testing.assert_allclose(out, ref, rtol=0, atol=1e-15)
    gap, _, _, vn, _ = model.contacts(out, held)
    assert np.max(np.abs(gap)) < 1e-15 and np.max(np.abs(vn)) < 1e-15


@pytest.mark.parametrize("held", [[0], [1, 3]])
def test_integration_is_scipys_dop853_step_for_step(held):
    """Same tableau, initial step, error norm and step control: the end state agrees to
    roundoff and the number of RHS evaluations is the same."""
    model, y = _state_touching(held)
    rtol, s = 1e-12, 0.05
    atol = np.full(13, 1e-13)
    sol = solve_ivp(
        constrained_rhs(model, held), (0.0, s), y, method="DOP853", rtol=rtol, atol=atol
    )
    empty = np.empty((0, 2))
    ok, y_end, nfev, _ = ck.integrate_held(
        y, s, np.ascontiguousarray(model.points[held]), model.mass, model.i1, model.i3, 1.0,
        rtol, atol, empty, np.empty((0, 13)), empty, 0, np.empty(0),
    )  # fmt: skip
    assert ok and nfev == sol.nfev
    np.testing.assert_allclose(y_end, sol.y[:, -1], rtol=0, atol=1e-13)


@pytest.mark.parametrize(
    "name,max_impacts,n_compare",
    [("triangle-chatter", None, 59), ("rod", None, 50), ("polygon25-rolling", 300, 300),
     ("pentagon-bounce", None, 100)],
)  # fmt: skip
def test_compiled_contact_phases_give_the_impacts_of_the_python_loop(
    name, max_impacts, n_compare, monkeypatch
):
    """Contact phases with lift-offs, landings and chatter endings: same contacts, same
    times to 1e-12 (pentagon-bounce is chaotic: its leading 100 impacts)."""
    scene = resolve_scene(name)
    if max_impacts:
        scene = scene.with_run(max_impacts=max_impacts)
    monkeypatch.setattr(sim, "USE_CONTACT_KERNEL", False)
    py = sim.simulate(scene)
    monkeypatch.setattr(sim, "USE_CONTACT_KERNEL", True)
    nb = sim.simulate(scene)
    assert nb.stats["compiled_contact_chunks"] > 0
    assert len(py.impacts) >= n_compare and len(nb.impacts) >= n_compare
    for a, b in zip(py.impacts[:n_compare], nb.impacts[:n_compare], strict=True):
        assert a.contact == b.contact
        assert abs((a.t - b.t) + (a.t_lo - b.t_lo)) <= 1e-12
    if name != "pentagon-bounce":
        assert nb.status == py.status and len(nb.impacts) == len(py.impacts)
        # the samples inside contact phases come from extra steps, not dense output
        np.testing.assert_allclose(nb.energy, py.energy, rtol=0, atol=1e-10)
