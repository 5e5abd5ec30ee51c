"""Contact geometry of a scene, for arrays of states: the one vectorised form used by the
scene validation, the engine adapters, the metrics and the recordings.

State rows (13): position x (3), quaternion q = (w, x, y, z) body → world (4),
velocity v (3), angular velocity ω in the world frame (3).

Contacts (the model of Baranyai & Várkonyi, section 2; reference.contact_kinds):
- a rim vertex on the plane: body-frame position p_k = a(cos 2πk/n, sin 2πk/n, 0); with
  r_k = R p_k its gap is z + (r_k)_z (the z row of R from the small quaternion
  components directly, so tilts of 1e-12 keep their digits) and its normal
  velocity v_z + (ω × r_k)_z;
- a floor point on the face: the fixed point b_k (`three_point`: b(cos 2πk/3,
  sin 2πk/3, 0)); the body's face (the plane through the centre of mass with normal
  e3 = R ẑ) touches it: gap (x − b_k)·e3, normal velocity v·e3 − (ω × (x − b_k))·e3.

The formulas are the compiled core's (reference.core.contacts, reference.core.inertia),
applied row by row (reference.core.arrays).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from .compiled import function
from .core import layout as L
from .quaternion import from_rotation_vector

if TYPE_CHECKING:  # at run time geometry imports only compiled, core.layout and quaternion
    from .contact_kinds import GroundContacts
    from .scene import Body, Ground, InitialState, Scene


def contact_points(body: Body, ground: Ground) -> np.ndarray:
    """(k, 3): the ground's contact points (`Ground.contacts`): body-frame rim vertices,
    then world floor points; read-only, shared between calls with the same geometry."""
    return ground.contacts(body).points


def initial_state(initial: InitialState) -> np.ndarray:
    """The 13-component state of an InitialState (attitude from its rotation vector)."""
    y = np.zeros(L.STATE_SIZE)
    y[L.POSITION] = initial.position
    y[L.QUATERNION] = from_rotation_vector(initial.rotation_vector)
    y[L.VELOCITY] = initial.velocity
    y[L.ANGULAR_VELOCITY] = initial.angular_velocity
    return y


def _states(states: np.ndarray) -> np.ndarray:
    return np.ascontiguousarray(np.asarray(states, dtype=float).reshape(-1, L.STATE_SIZE))


def contact_kinematics(
    states: np.ndarray, contacts: GroundContacts
) -> tuple[np.ndarray, np.ndarray]:
    """Gap and normal velocity (N, k) of every contact of a ground for states (N, 13)."""
    S = _states(states)
    pts = contacts.core_points
    gap, vn = np.empty((len(S), len(pts))), np.empty((len(S), len(pts)))
    function("contact_kinematics_rows")(S, pts, gap, vn)
    return gap, vn


def scene_contact_kinematics(scene: Scene, states: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """`contact_kinematics` with the scene's ground's contacts."""
    return contact_kinematics(states, scene.contacts)


def _energy_rows(scene: Scene, states: np.ndarray) -> np.ndarray:
    """(N, 3): kinetic, potential and excess energy of each state."""
    S = _states(states)
    i1, _, i3 = scene.body.inertia_diag
    out = np.empty((len(S), 3))
    keeps = scene.contacts.invariants
    function("energy_rows")(S, keeps, scene.body.mass, i1, i3, scene.gravity, out)
    return out


def energies(scene: Scene, states: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Kinetic and potential energy (N,) of states (N, 13):
    ½ m|v|² + ½ (I1 |ω⊥|² + I3 ω3²) and m g z."""
    e = _energy_rows(scene, states)
    return e[:, 0], e[:, 1]


def excess_energy(scene: Scene, states: np.ndarray) -> np.ndarray:
    """(N,) energy above the level the motion ends at (`inertia.excess_energy`, by the
    ground's `GroundContacts.invariants`): rim vertices on the plane
    E − ½ m |v_h|² − L_z²/(2 I3); floor points on the face E − ½ m |v_h|² − ½ I3 ω3²
    (ω3 is kept and the flat disk slides freely on the bumps), the energy of the tilt and
    the height: the E of the paper's E ≈ a (t_f − t)^c, which goes to zero at the end of
    the motion."""
    return _energy_rows(scene, states)[:, 2]


def resting_energy(scene: Scene, states: np.ndarray) -> np.ndarray:
    """(N,) the lowest energy the invariants allow (see `excess_energy`)."""
    e = _energy_rows(scene, states)
    return e[:, 0] + e[:, 1] - e[:, 2]


def free_acceleration(scene: Scene, states: np.ndarray) -> np.ndarray:
    """(N, 6): (v̇, ω̇) without contact forces: (0, 0, −g) and −I⁻¹(ω × Iω)."""
    S = _states(states)
    i1, _, i3 = scene.body.inertia_diag
    out = np.empty((len(S), 6))
    function("free_acceleration_rows")(S, i1, i3, scene.gravity, out)
    return out


def length_scale(scene: Scene, states: np.ndarray) -> np.ndarray:
    """(N,) the local length unit |z| + a sin α of each state."""
    S = _states(states)
    out = np.empty(len(S))
    function("length_scale_rows")(S, scene.body.radius, out)
    return out
