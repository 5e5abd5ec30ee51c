"""Row-wise forms of the core's primitives, for arrays of states and quaternions: what
reference.quaternion and reference.geometry expose to the rest of the project (metrics,
engines, recordings).  Each loops over rows calling the scalar function, so every
formula stays in one place.  Inputs are C-contiguous float64 arrays; outputs are
written into the arrays given."""

from numba import njit

from .contacts import contact_frame, contact_kind, length_scale, normal_velocity
from .inertia import excess_energy, free_acceleration, kinetic_energy, potential_energy
from .rotation import (
    axis_of,
    qmul,
    quaternion_log,
    rotate_vector,
    rotation_vector_quaternion,
    tilt,
)


@njit(cache=True)
def quaternion_product_rows(a, b, out):
    for i in range(a.shape[0]):
        out[i, 0], out[i, 1], out[i, 2], out[i, 3] = qmul(
            a[i, 0], a[i, 1], a[i, 2], a[i, 3], b[i, 0], b[i, 1], b[i, 2], b[i, 3]
        )


@njit(cache=True)
def quaternion_exp_rows(phi, out):
    for i in range(phi.shape[0]):
        out[i, 0], out[i, 1], out[i, 2], out[i, 3] = rotation_vector_quaternion(
            phi[i, 0], phi[i, 1], phi[i, 2]
        )


@njit(cache=True)
def quaternion_log_rows(q, out):
    for i in range(q.shape[0]):
        out[i, 0], out[i, 1], out[i, 2] = quaternion_log(q[i, 0], q[i, 1], q[i, 2], q[i, 3])


@njit(cache=True)
def rotate_rows(q, v, out):
    for i in range(q.shape[0]):
        out[i, 0], out[i, 1], out[i, 2] = rotate_vector(
            q[i, 0], q[i, 1], q[i, 2], q[i, 3], v[i, 0], v[i, 1], v[i, 2]
        )


@njit(cache=True)
def tilt_rows(q, out):
    for i in range(q.shape[0]):
        out[i] = tilt(q[i, 0], q[i, 1], q[i, 2], q[i, 3])


@njit(cache=True)
def axis_rows(q, out):
    for i in range(q.shape[0]):
        out[i, 0], out[i, 1], out[i, 2] = axis_of(q[i, 0], q[i, 1], q[i, 2], q[i, 3])


@njit(cache=True)
def contact_kinematics_rows(states, pts, gap, vn):
    """gap[i, k] and vn[i, k]: gap and normal velocity of contact k at state i (the
    ground's contacts, each of its stored kind: `contacts.contact_kind`)."""
    for i in range(states.shape[0]):
        y = states[i]
        for k in range(pts.shape[0]):
            kind = contact_kind(pts, k)
            f = contact_frame(y, kind, pts, k)
            gap[i, k] = f.gap
            vn[i, k] = normal_velocity(y, f, kind)


@njit(cache=True)
def energy_rows(states, invariants, mass, i1, i3, gravity, out):
    """out[i] = (kinetic, potential, excess) energy of state i."""
    for i in range(states.shape[0]):
        y = states[i]
        out[i, 0] = kinetic_energy(y, mass, i1, i3)
        out[i, 1] = potential_energy(y, mass, gravity)
        out[i, 2] = excess_energy(y, invariants, mass, i1, i3, gravity)


@njit(cache=True)
def free_acceleration_rows(states, i1, i3, gravity, out):
    """out[i] = (v̇, ω̇) of state i without contact forces."""
    for i in range(states.shape[0]):
        a = free_acceleration(states[i], i1, i3, gravity)
        for c in range(6):
            out[i, c] = a[c]


@njit(cache=True)
def length_scale_rows(states, radius, out):
    for i in range(states.shape[0]):
        out[i] = length_scale(states[i], radius)
