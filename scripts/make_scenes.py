"""Construct the built-in scenes whose initial states need a computation:

- grazing-contact: a vertex whose gap has a double root (touches with zero normal
  velocity, pulled up by centripetal acceleration) at t = T_GRAZE; built by taking the
  grazing state and running the closed-form flight backwards by T_GRAZE.
- near-simultaneous: a square falling without rotation, tilted so that vertex 1 is
  DT_APART·|v| higher than vertex 0: the two hit DT_APART ≈ 1e-12 s apart.
- bumpy-transition, bumpy-rolling: the transition study's rolling polygon over three
  bumps (harness.transition.scene, in the paper's units), its rolling rate computed from
  the tilt; the first followed to the end, the second a short one engines run in seconds.

Run: python scripts/make_scenes.py
(rewrites reference/scenes/{grazing-contact,near-simultaneous,bumpy-*}.toml)
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from scipy.optimize import brentq

from reference import quaternion as qt
from reference.core.contacts import vertex_lever
from reference.core.flight import flight_constants, free_flight
from reference.geometry import scene_contact_kinematics
from reference.scene import Body, Ground, InitialState, Scene

OUT = Path(__file__).resolve().parent.parent / "reference" / "scenes"
T_GRAZE = 0.1
DT_APART = 1e-12


def _toml(name, desc, gamma, n, rho, y, t_end):
    rv = qt.to_rotation_vector(y[3:7])
    f = lambda v: "[" + ", ".join(repr(float(x)) for x in v) + "]"  # noqa: E731
    return f'''name = "{name}"
description = "{desc}"
gravity = 1.0
restitution = {gamma}

[body]
n = {n}
radius = 1.0
mass = 1.0
gyration = {rho}

[ground]
kind = "flat"

[initial]
position = {f(y[0:3])}
rotation_vector = {f(rv)}
velocity = {f(y[7:10])}
angular_velocity = {f(y[10:13])}

[run]
t_end = {t_end}
max_impacts = 1000
'''


def _scene(n, rho, y):
    return Scene(
        name="tmp",
        body=Body(n=n, gyration=rho),
        ground=Ground(),
        initial=InitialState(
            tuple(y[0:3]), tuple(qt.to_rotation_vector(y[3:7])), tuple(y[7:10]), tuple(y[10:13])
        ),
    )


def grazing() -> str:
    n, rho, w, tilt = 3, 0.5, -5.0, 0.1
    scene = _scene(n, rho, np.r_[0, 0, 1, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0])
    y = np.zeros(13)
    # vertex 0 at body (1, 0, 0); tilt about y so it is the lowest point
    y[3:7] = qt.from_rotation_vector([0.02, tilt, 0.0])  # asymmetric: no mirror hits
    # horizontal spin: centripetal (ω×(ω×r))_z = −|ω|² r_z > 0 lifts the low vertex 0;
    # v_z cancels (ω × r)_z so vertex 0 touches with zero normal velocity
    y[10:13] = [0.5, w, 0.0]
    rx, ry, rz = vertex_lever(y, 1.0, 0.0)
    y[2] = -rz  # vertex 0 exactly on the ground
    y[9] = -(y[10] * ry - y[11] * rx)
    g, vn = scene_contact_kinematics(scene, y)
    assert abs(g[0, 0]) < 1e-15 and abs(vn[0, 0]) < 1e-14, (g, vn)
    i1, _, i3 = scene.body.inertia_diag
    back = np.empty(13)
    free_flight(y, flight_constants(y, i1, i3), scene.gravity, -T_GRAZE, back)
    assert np.all(scene_contact_kinematics(scene, back)[0] > 0)
    return _toml(
        "grazing-contact",
        f"triangle whose vertex v0 grazes the ground (double root) at t = {T_GRAZE}",
        0.5,
        n,
        rho,
        back,
        0.3,
    )


def near_simultaneous() -> str:
    n, rho, v, h0 = 4, 0.5, -1.0, 0.05
    scene = _scene(n, rho, np.r_[0, 0, 1, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0])
    phiy = 0.02

    def gaps(y):
        return scene_contact_kinematics(scene, y)[0][0]

    def state(phix):
        y = np.zeros(13)
        y[3:7] = qt.from_rotation_vector([phix, phiy, 0.0])
        y[2] = h0 - gaps(y)[0]
        y[9] = v
        return y

    def diff(phix):
        g = gaps(state(phix))
        return (g[1] - g[0]) - DT_APART * abs(v)

    phix = brentq(diff, -0.03, -0.01, xtol=1e-17, rtol=1e-15)
    y = state(phix)
    g = gaps(y)
    assert abs((g[1] - g[0]) - DT_APART) < 1e-15 and g[0] == min(g)
    return _toml(
        "near-simultaneous",
        "square falling without spin; vertices v0 and v1 hit about 1e-12 s apart",
        0.5,
        n,
        rho,
        y,
        0.5,
    )


def bumpy(name: str, description: str, **study) -> str:
    """A scene of the transition study as TOML (linear coordinates of its rolling start)."""
    from harness.transition.scene import transition_scene

    s = transition_scene(name=name, **study)
    g, b, i = s.ground, s.body, s.initial
    f = lambda v: "[" + ", ".join(repr(float(x)) for x in v) + "]"  # noqa: E731
    return f'''name = "{name}"
description = "{description}"
gravity = {s.gravity!r}
restitution = {s.restitution!r}

[body]
n = {b.n}
radius = {b.radius!r}
mass = {b.mass!r}
gyration = {b.gyration!r}

[ground]
kind = "bumpy"
bump_radius = {g.bump_radius!r}
bump_height = {g.bump_height!r}

[initial]
q = {f(i.q)}
p = {f(i.p)}

[run]
t_end = {s.run.t_end!r}
max_impacts = {s.run.max_impacts}
'''


BUMPY_SCENES = {
    "bumpy-transition": (
        "100-gon (ρ = 0.5, γ = 0.5) rolling at tilt 0.02 over 3 bumps of height Δ = 1e-4 m "
        "at d = 0.1 m, g = 9.81: rim, mixed, bumps to the end",
        dict(delta=1e-4, tilt=0.02, n=100, t_end=1.0, max_impacts=1_000_000),
    ),
    "bumpy-rolling": (
        "20-gon (ρ = 0.5, γ = 0) rolling at tilt 0.01 over 3 bumps of height Δ = 1e-4 m "
        "at d = 0.1 m: rim impacts, then the first bump impacts (short: for engines)",
        dict(delta=1e-4, tilt=0.01, n=20, restitution=0.0, t_end=0.04, max_impacts=100_000),
    ),
}


if __name__ == "__main__":
    (OUT / "grazing-contact.toml").write_text(grazing())
    (OUT / "near-simultaneous.toml").write_text(near_simultaneous())
    for name, (description, study) in BUMPY_SCENES.items():
        (OUT / f"{name}.toml").write_text(bumpy(name, description, **study))
    print("wrote", OUT / "grazing-contact.toml", OUT / "near-simultaneous.toml", *BUMPY_SCENES)
