"""Mass properties of the axisymmetric body (inertia m(ρa)² diag(1, 1, 2) in the body
frame): inverse inertia in the world frame, the response of (v, ω) to a normal impulse,
the torque-free angular acceleration, and energies (paper §2.2–2.3)."""

from .jit import hot
from .layout import VX, VY, VZ, WX, WY, WZ, Z
from .records import KEEPS_PLANE_MOMENTA, KEEPS_SPIN, Response
from .rotation import body_axis


@hot
def inverse_inertia(e3x, e3y, e3z, i1, i3, cx, cy, cz):
    """I⁻¹ c in the world frame: c/i1 + (1/i3 − 1/i1)(e3·c) e3."""
    f = (1.0 / i3 - 1.0 / i1) * (e3x * cx + e3y * cy + e3z * cz)
    return cx / i1 + f * e3x, cy / i1 + f * e3y, cz / i1 + f * e3z


@hot
def impulse_response(y, f, mass, i1, i3):
    """M⁻¹Jᵀ and w = J M⁻¹ Jᵀ for the contact with frame f, J = [nᵀ, (r × n)ᵀ]: a normal
    impulse ζ changes v by ζ n/m, ω by ζ I⁻¹(r × n), the normal velocity by ζ w
    (the denominator of the paper's eq. F)."""
    return response_on_axis(f, body_axis(y), mass, i1, i3)


@hot
def response_on_axis(f, e3, mass, i1, i3):
    """`impulse_response` with e3 = R ẑ, the body's axis at the state, given."""
    cx = f.ry * f.nz - f.rz * f.ny
    cy = f.rz * f.nx - f.rx * f.nz
    cz = f.rx * f.ny - f.ry * f.nx
    e3x, e3y, e3z = e3
    ix, iy, iz = inverse_inertia(e3x, e3y, e3z, i1, i3, cx, cy, cz)
    w = (f.nx * f.nx + f.ny * f.ny + f.nz * f.nz) / mass + cx * ix + cy * iy + cz * iz
    return Response(f.nx / mass, f.ny / mass, f.nz / mass, ix, iy, iz, w)


@hot
def response_rate(f, resp):
    """J_f M⁻¹ J_gᵀ: the change of contact f's normal velocity per unit impulse at the
    contact of `resp` (an entry of the contact system's matrix A)."""
    cx = f.ry * f.nz - f.rz * f.ny
    cy = f.rz * f.nx - f.rx * f.nz
    cz = f.rx * f.ny - f.ry * f.nx
    return (
        f.nx * resp.dvx
        + f.ny * resp.dvy
        + f.nz * resp.dvz
        + cx * resp.dwx
        + cy * resp.dwy
        + cz * resp.dwz
    )


@hot
def apply_impulse(y, resp, zeta):
    """In place: (v, ω) += ζ M⁻¹Jᵀ."""
    y[VX] += resp.dvx * zeta
    y[VY] += resp.dvy * zeta
    y[VZ] += resp.dvz * zeta
    y[WX] += resp.dwx * zeta
    y[WY] += resp.dwy * zeta
    y[WZ] += resp.dwz * zeta


@hot
def free_angular_acceleration(y, i1, i3):
    """ω̇ without contact forces, −I⁻¹(ω × Iω) (paper eq. acc2free)."""
    e3x, e3y, e3z = body_axis(y)
    wx, wy, wz = y[WX], y[WY], y[WZ]
    w3 = wx * e3x + wy * e3y + wz * e3z
    Lx = i1 * wx + (i3 - i1) * w3 * e3x
    Ly = i1 * wy + (i3 - i1) * w3 * e3y
    Lz = i1 * wz + (i3 - i1) * w3 * e3z
    gx, gy, gz = wy * Lz - wz * Ly, wz * Lx - wx * Lz, wx * Ly - wy * Lx
    ix, iy, iz = inverse_inertia(e3x, e3y, e3z, i1, i3, gx, gy, gz)
    return -ix, -iy, -iz


@hot
def free_acceleration(y, i1, i3, gravity):
    """(v̇, ω̇) of the free body: (0, 0, −g) and −I⁻¹(ω × Iω)."""
    ax, ay, az = free_angular_acceleration(y, i1, i3)
    return 0.0, 0.0, -gravity, ax, ay, az


@hot
def kinetic_energy(y, mass, i1, i3):
    """½ m|v|² + ½ (I1 |ω⊥|² + I3 ω3²)."""
    e3x, e3y, e3z = body_axis(y)
    w3 = y[WX] * e3x + y[WY] * e3y + y[WZ] * e3z
    ww = y[WX] ** 2 + y[WY] ** 2 + y[WZ] ** 2
    return 0.5 * mass * (y[VX] ** 2 + y[VY] ** 2 + y[VZ] ** 2) + 0.5 * (
        i1 * (ww - w3 * w3) + i3 * w3 * w3
    )


@hot
def potential_energy(y, mass, gravity):
    """m g z."""
    return mass * gravity * y[Z]


@hot
def excess_energy(y, invariants, mass, i1, i3, gravity):
    """Energy above the level the motion ends at (the body flat on the ground;
    `invariants`: records.KEEPS_* bits):

    - vertical contact forces (rim vertices on the plane) keep the horizontal momentum
      and L_z: E − ½ m |v_h|² − L_z²/(2 I3);
    - forces along e3 (floor points on the face) keep the spin ω3, and the body flat on
      the floor points slides on them freely (its face is level and frictionless), so
      the motion ends flat with whatever horizontal velocity it has then: the level is
      ½ m |v_h|² + ½ I3 ω3² and the excess is the energy of the tilt and the height,
      ½ m v_z² + ½ I1 |ω − ω3 e3|² + m g z (the paper's three-bump model, §4: its q and
      p are the tilt, the height and their rates), summed without cancellation;
    - neither: E."""
    e3x, e3y, e3z = body_axis(y)
    w3 = y[WX] * e3x + y[WY] * e3y + y[WZ] * e3z
    if invariants & KEEPS_SPIN:
        px, py, pz = y[WX] - w3 * e3x, y[WY] - w3 * e3y, y[WZ] - w3 * e3z
        tilting = 0.5 * i1 * (px * px + py * py + pz * pz)
        return 0.5 * mass * y[VZ] * y[VZ] + tilting + potential_energy(y, mass, gravity)
    e = kinetic_energy(y, mass, i1, i3) + potential_energy(y, mass, gravity)
    if invariants & KEEPS_PLANE_MOMENTA:
        lz = i1 * y[WZ] + (i3 - i1) * w3 * e3z
        e = e - 0.5 * mass * (y[VX] ** 2 + y[VY] ** 2) - lz * lz / (2.0 * i3)
    return e
