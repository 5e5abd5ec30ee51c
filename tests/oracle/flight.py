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
from .body import BodyModel, Q, V, W, X, cross


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
    """State after a free flight of duration s from fc.y0 (closed form)."""
    y0 = fc.y0
    y = np.empty(13)
    g = fc.gravity
    y[X] = y0[X] + y0[V] * s
    y[2] -= 0.5 * g * s * s
    y[V] = y0[V]
    y[9] -= g * s
    q_prec = qt.from_rotation_vector(fc.L_over_A * s)
    half = 0.5 * fc.lam * s
    q_spin = np.array([math.cos(half), 0.0, 0.0, math.sin(half)])
    q = qt.multiply(qt.multiply(q_prec, y0[Q]), q_spin)
    y[Q] = qt.normalize(q)
    y[W] = fc.L_over_A + fc.lam * qt.body_axis(y[Q])
    return y


def flight_acceleration(fc: FlightConstants, y: np.ndarray) -> np.ndarray:
    """[v̇; ω̇] in flight: (0, 0, −g) and ω̇ = λ (L/A) × e3."""
    e3 = qt.body_axis(y[Q])
    wdot = fc.lam * cross(fc.L_over_A, e3)
    return np.array([0.0, 0.0, -fc.gravity, *wdot])
