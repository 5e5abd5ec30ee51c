"""Contact geometry of a scene, for arrays of states: the one vectorised form used by the
scene validation, the engine adapters, the metrics and the recordings.

State rows (13): position x (3), quaternion q = (w, x, y, z) body → world (4),
velocity v (3), angular velocity ω in the world frame (3).

Contacts (the model of Baranyai & Várkonyi, section 2):
- `flat`: contact k is vertex k, body-frame position a(cos 2πk/n, sin 2πk/n, 0); with
  r_k = R p_k its gap is z + (r_k)_z (the z row of R from the small quaternion
  components directly, so tilts of 1e-12 keep their digits) and its normal
  velocity v_z + (ω × r_k)_z;
- `three_point`: contact k is the ground bump b_k = b(cos 2πk/3, sin 2πk/3, 0); the
  body's face (the plane through the centre of mass with normal e3 = R ẑ) touches it:
  gap (x − b_k)·e3, normal velocity v·e3 − (ω × (x − b_k))·e3.

The compiled event loop evaluates the same contacts one at a time in
`reference.core.contacts`; tests check the two against each other.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from .quaternion import body_axis, from_rotation_vector

if TYPE_CHECKING:  # geometry depends on no other module of the package
    from .scene import Body, Ground, InitialState, Scene


def contact_points(body: Body, ground: Ground) -> np.ndarray:
    """(k, 3): body-frame vertices (flat ground) or world bump positions (three_point)."""
    if ground.kind == "flat":
        ang = 2.0 * np.pi * np.arange(body.n) / body.n
        r = body.radius
    else:
        ang = 2.0 * np.pi * np.arange(3) / 3
        r = ground.bump_radius
    pts = r * np.stack([np.cos(ang), np.sin(ang), np.zeros(len(ang))], axis=1)
    pts.setflags(write=False)
    return pts


def initial_state(initial: InitialState) -> np.ndarray:
    """The 13-component state of an InitialState (attitude from its rotation vector)."""
    y = np.zeros(13)
    y[0:3] = initial.position
    y[3:7] = from_rotation_vector(initial.rotation_vector)
    y[7:10] = initial.velocity
    y[10:13] = initial.angular_velocity
    return y


def contact_kinematics(
    states: np.ndarray, points: np.ndarray, flat: bool
) -> tuple[np.ndarray, np.ndarray]:
    """Gap and normal velocity (N, k) of every contact for states (N, 13)."""
    states = np.asarray(states, dtype=float).reshape(-1, 13)
    x, v, w = states[:, 0:3], states[:, 7:10], states[:, 10:13]
    if flat:
        qw, qx, qy, qz = states[:, 3:7].T
        px, py = points[:, 0], points[:, 1]
        lx = (1 - 2 * (qy * qy + qz * qz))[:, None] * px + (2 * (qx * qy - qw * qz))[:, None] * py
        ly = (2 * (qx * qy + qw * qz))[:, None] * px + (1 - 2 * (qx * qx + qz * qz))[:, None] * py
        lz = (2 * (qx * qz - qw * qy))[:, None] * px + (2 * (qy * qz + qw * qx))[:, None] * py
        gap = x[:, 2:3] + lz
        vn = v[:, 2:3] + w[:, 0:1] * ly - w[:, 1:2] * lx
        return gap, vn
    e3 = body_axis(states[:, 3:7])
    d = x[:, None, :] - points[None, :, :]
    gap = np.einsum("nkj,nj->nk", d, e3)
    wxd = np.cross(w[:, None, :], d)
    vn = np.einsum("nj,nj->n", v, e3)[:, None] - np.einsum("nkj,nj->nk", wxd, e3)
    return gap, vn


def scene_contact_kinematics(scene: Scene, states: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """`contact_kinematics` with the scene's contact points and ground."""
    return contact_kinematics(
        states, contact_points(scene.body, scene.ground), scene.ground.kind == "flat"
    )


def energies(scene: Scene, states: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Kinetic and potential energy (N,) of states (N, 13):
    ½ m|v|² + ½ (I1 |ω⊥|² + I3 ω3²) and m g z."""
    states = np.asarray(states, dtype=float).reshape(-1, 13)
    v, w = states[:, 7:10], states[:, 10:13]
    i1, _, i3 = scene.body.inertia_diag
    e3 = body_axis(states[:, 3:7])
    w3 = np.einsum("nj,nj->n", w, e3)
    wperp2 = np.einsum("nj,nj->n", w, w) - w3 * w3
    ke = 0.5 * scene.body.mass * np.einsum("nj,nj->n", v, v) + 0.5 * (i1 * wperp2 + i3 * w3 * w3)
    pe = scene.body.mass * scene.gravity * states[:, 2]
    return ke, pe


def resting_energy(scene: Scene, states: np.ndarray) -> np.ndarray:
    """(N,) the lowest energy the invariants allow, the level the motion ends at:
    flat ground: ½ m |v_h|² + L_z²/(2 I3) (horizontal momentum and the vertical angular
    momentum are kept by frictionless contacts along e_z; lying flat, L_z = I3 ω_z);
    three_point: ½ I3 ω3² (the spin about the body axis is kept)."""
    states = np.asarray(states, dtype=float).reshape(-1, 13)
    v, w = states[:, 7:10], states[:, 10:13]
    i1, _, i3 = scene.body.inertia_diag
    e3 = body_axis(states[:, 3:7])
    w3 = np.einsum("nj,nj->n", w, e3)
    if scene.ground.kind == "flat":
        lz = i1 * w[:, 2] + (i3 - i1) * w3 * e3[:, 2]
        return 0.5 * scene.body.mass * (v[:, 0] ** 2 + v[:, 1] ** 2) + lz * lz / (2.0 * i3)
    return 0.5 * i3 * w3 * w3


def excess_energy(scene: Scene, states: np.ndarray) -> np.ndarray:
    """(N,) energy above `resting_energy`: the E of the paper's E ≈ a (t_f − t)^c, which
    goes to zero at the end of the motion."""
    ke, pe = energies(scene, states)
    return ke + pe - resting_energy(scene, states)
