"""Oracle: free flight in closed form (paper §2.2, eqs. acc1free–acc2free).

The centre of mass follows a parabola, x(s) = x0 + v0 s − ½ g s² e_z.  The body is
axisymmetric (I1 = I2 = A, I3 = C), so torque-free rotation is regular precession: the
angular momentum L is constant, the symmetry axis e3 turns about L at Ω = |L|/A, and the
body turns about e3 at λ = (1/C − 1/A)(L·e3) relative to that:

    R(s) = Rot(L/A · s) · R0 · Rot(ẑ, λ s),     ω(s) = L/A + λ e3(s).

Derivatives used by the event search: ω̇ = λ (L/A) × e3, |ω| is constant,
|ω̇| ≤ |λ| Ω, |ω̈| ≤ |λ| Ω².
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from . import quaternion as qt
from .body import BodyModel, Q, W, cross3


@dataclass(frozen=True)
class FlightConstants:
    """What stays fixed along one free flight: the start state and its invariants."""

    y0: np.ndarray
    L_over_A: np.ndarray  # L / A, world frame (rad/s)
    lam: float  # spin rate about e3 relative to the precessing frame
    omega_abs: float  # |ω|, constant in torque-free axisymmetric motion
    Omega: float  # |L| / A, precession rate
    gravity: float

    @property
    def wdot_bound(self) -> float:
        return abs(self.lam) * self.Omega

    @property
    def wddot_bound(self) -> float:
        return abs(self.lam) * self.Omega * self.Omega


def flight_constants(model: BodyModel, y0: np.ndarray) -> FlightConstants:
    q, w = y0[Q], y0[W]
    e3 = qt.body_axis(q)
    w3 = float(w @ e3)
    L = model.i1 * (w - w3 * e3) + model.i3 * w3 * e3  # I_w ω
    L3 = model.i3 * w3
    L_over_A = L / model.i1
    lam = (1.0 / model.i3 - 1.0 / model.i1) * L3
    return FlightConstants(
        y0=np.array(y0, dtype=float),
        L_over_A=L_over_A,
        lam=lam,
        omega_abs=float(np.linalg.norm(w)),
        Omega=float(np.linalg.norm(L_over_A)),
        gravity=model.gravity,
    )


def free_flight(fc: FlightConstants, s: float) -> np.ndarray:
    """State after a free flight of duration s from fc.y0 (closed form): the parabola
    x0 + v0 s − ½ g s² e_z, v0 − g s e_z, q = Rot(L/A · s) q0 Rot(ẑ, λ s) and
    ω = L/A + λ e3 (components as Python floats, see quaternion.py)."""
    x0, x1, x2, *q0, v0, v1, v2 = fc.y0[:10].tolist()
    g = fc.gravity
    L = fc.L_over_A.tolist()
    q_prec = qt.exp_components(L[0] * s, L[1] * s, L[2] * s)
    half = 0.5 * fc.lam * s
    q_spin = (math.cos(half), 0.0, 0.0, math.sin(half))
    q = qt.unit(qt.product(qt.product(q_prec, q0), q_spin))
    e0, e1, e2 = qt.axis(q)
    lam = fc.lam
    return np.array(
        [
            x0 + v0 * s,
            x1 + v1 * s,
            x2 + v2 * s - 0.5 * g * s * s,
            *q,
            v0,
            v1,
            v2 - g * s,
            L[0] + lam * e0,
            L[1] + lam * e1,
            L[2] + lam * e2,
        ]
    )


def flight_acceleration(fc: FlightConstants, y: np.ndarray) -> np.ndarray:
    """[v̇; ω̇] in flight: (0, 0, −g) and ω̇ = λ (L/A) × e3."""
    e3 = qt.axis(qt.components(y[Q]))
    lam = fc.lam
    wdot = cross3(fc.L_over_A.tolist(), e3)
    return np.array([0.0, 0.0, -fc.gravity, lam * wdot[0], lam * wdot[1], lam * wdot[2]])
