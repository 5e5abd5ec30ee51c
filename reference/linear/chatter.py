"""Gravity-free chatter of the linearised n-gon: the rod (paper §4.1-4.2) and the
triangle's CC and PCC properties (§4.3).

Without gravity the velocities only change at impacts; an impact sequence 0, 1, 2, ...
in the rotated frame is the linear map p ↦ M p, M = R⁻¹U0.

- CC (complete chatter, eq. CCtriangle): the dominant eigenvalue of M (largest modulus)
  is real and positive.  For the rod (n = 2) the roll about its own axis (φx, ωx) is
  invisible to both contacts and M acts on it as −1; CC is then decided on the planar
  block (φy, h), which is the paper's planar rod.
- PCC (partial complete chatter, eq. PCCtriangle): U0 R U0 R⁻¹ = U0 U1 (two alternating
  contacts) has only real eigenvalues.
- Gravity-free self-similar chatter (eqs. pscaling-rod, qscaling-rod, appendix C):
  p_i = β_p^i R^i p0, q_i = β_q^i R^i q0 with β_p, β_q distinct eigenvalues of M;
  p0 = eigenvector of β_p, q0 = α s + δ p0 (s the eigenvector of β_q,
  δ = β_p τ0/(β_q − β_p), α = −δ f0ᵀp0/f0ᵀs).  Intervals scale by β_q/β_p and energies
  by β_p², so E ~ (t_f − t)^c_lin with c_lin = 2 log β_p / log(β_q/β_p) (eq. clin).
  Its stability: eigenvalues of the Jacobian (central differences) of the reduced
  gravity-free map (impact, flight to the next vertex, rotation back, p and q each
  normalised).
- Rod: β_p,q = (ψ(1+γ) ± √(ψ²(1+γ)² − 4γ))/2, ψ = (1 − ρ²)/(1 + ρ²), i.e. the roots of
  x² − ψ(1+γ)x + γ.  Complete chatter without gravity needs ψ > 2√γ/(1+γ) (eq. CCcond,
  real β's); with gravity ψ > (γ^⅓ + γ^⅔)/(1+γ) (eq. CCcondgravity), which is β_q < β_p²,
  i.e. c_lin < 2 (equality: β_p = γ^⅓, β_q = γ^⅔, c_lin = 2).
"""

from __future__ import annotations

import math

import numpy as np

from ..core.tolerances import TINY
from ._text import (
    CHATTER_LEGEND,
    CHATTER_LEGEND_NO_TABLE,
    CHATTER_LEGEND_OUTPUT_ONLY,
    table,
)
from .model import LinearModel


def chatter_matrix(model: LinearModel) -> np.ndarray:
    """M = R⁻¹U0: impact at vertex 0 followed by the rotation back (no gravity)."""
    return model.R.T @ model.U(0)


def _visible_block(model: LinearModel, A: np.ndarray) -> np.ndarray:
    """For the rod, the planar block (φy, h) of A; else A."""
    if model.rank < 3:
        return A[1:, 1:]
    return A


def cc_matrix(model: LinearModel) -> np.ndarray:
    """The matrix whose eigenvalues decide CC: R⁻¹U0 (its visible block for the rod)."""
    return _visible_block(model, chatter_matrix(model))


def cc_of_eigenvalues(lam: np.ndarray) -> bool:
    """CC from the eigenvalues of `cc_matrix`: the dominant one (largest modulus, ties
    included) real and positive (eq. CCtriangle)."""
    top = lam[np.argmax(np.abs(lam))]
    big = np.abs(lam) >= np.abs(top) * (1 - 1e-12)
    return bool(all(abs(z.imag) <= 1e-12 * abs(z) and z.real > 0 for z in lam[big]))


def cc_property(model: LinearModel) -> bool:
    """Dominant eigenvalue of R⁻¹U0 real and positive (eq. CCtriangle)."""
    return cc_of_eigenvalues(np.linalg.eigvals(cc_matrix(model)))


def pcc_matrix(model: LinearModel) -> np.ndarray:
    """U0 R U0 R⁻¹, the map of two alternating impacts (eq. PCCtriangle)."""
    return model.U(0) @ model.R @ model.U(0) @ model.R.T


def pcc_of_eigenvalues(lam: np.ndarray) -> bool:
    """PCC from the eigenvalues of `pcc_matrix`: none of them complex."""
    return bool(np.all(np.abs(lam.imag) <= 1e-12 * np.maximum(np.abs(lam), TINY)))


def pcc_property(model: LinearModel) -> bool:
    """U0 R U0 R⁻¹ has no complex eigenvalues (eq. PCCtriangle)."""
    return pcc_of_eigenvalues(np.linalg.eigvals(pcc_matrix(model)))


def rod_betas(rho: float, gamma: float) -> tuple[float, float] | None:
    """(β_p, β_q) of the rod (paper §4.1), None when complex (no complete chatter)."""
    psi = (1 - rho * rho) / (1 + rho * rho)
    d = psi * psi * (1 + gamma) ** 2 - 4 * gamma
    if d < 0:
        return None
    s = psi * (1 + gamma) + math.sqrt(d)
    return 0.5 * s, 2 * gamma / s


def c_lin(beta_p: float, beta_q: float) -> float:
    """c_lin = 2 log β_p / log(β_q/β_p) (eq. clin)."""
    return 2.0 * math.log(beta_p) / math.log(beta_q / beta_p)


def rod_conditions(rho: float, gamma: float) -> dict:
    """Complete-chatter conditions of the rod without (Goyal) and with (Or) gravity."""
    psi = (1 - rho * rho) / (1 + rho * rho)
    no_g = 2 * math.sqrt(gamma) / (1 + gamma)
    with_g = (gamma ** (1 / 3) + gamma ** (2 / 3)) / (1 + gamma)
    return {
        "psi": psi,
        "cc_without_gravity": bool(psi > no_g),
        "psi_threshold_without_gravity": no_g,
        "cc_with_gravity": bool(psi > with_g),
        "psi_threshold_with_gravity": with_g,
    }


def gravity_free_selfsimilar(model: LinearModel, beta_p: float, beta_q: float) -> dict | None:
    """Appendix C's self-similar chatter for the eigenvalue pair (β_p, β_q), τ0 = 1, with
    its feasibility: f0ᵀp0 < 0, gaps ≥ 0 over [0, τ0] (linear in time: ends checked),
    0 < β_q < β_p < 1 (intervals shrink).  None if an eigenvalue is not real."""
    M = chatter_matrix(model)
    lam, vec = np.linalg.eig(M)
    ip = int(np.argmin(np.abs(lam - beta_p)))
    iq = int(np.argmin(np.abs(lam - beta_q)))
    if ip == iq or abs(lam[ip].imag) > 1e-12 or abs(lam[iq].imag) > 1e-12:
        return None
    p0, s = np.real(vec[:, ip]), np.real(vec[:, iq])
    F = model.F
    if F[0] @ p0 > 0:
        p0 = -p0
    tau0 = 1.0
    delta = beta_p * tau0 / (beta_q - beta_p)
    fs = float(F[0] @ s)
    if fs == 0:
        return None
    alpha = -delta * float(F[0] @ p0) / fs
    q0 = alpha * s + delta * p0
    pa = model.U(0) @ p0
    gaps0 = F @ q0
    gaps1 = F @ (q0 + pa * tau0)
    tol = 1e-12 * float(np.max(np.abs(F) @ (np.abs(q0) + np.abs(pa))))
    ok = {
        "approaching": bool(F[0] @ p0 < 0),
        "non_penetration": bool(np.all(gaps0 >= -tol) and np.all(gaps1 >= -tol)),
        "shrinking": bool(0 < beta_q < beta_p < 1),
    }
    return {"p0": p0, "q0": q0, "tau0": tau0, "checks": ok, "feasible": all(ok.values())}


def gravity_free_map(model: LinearModel, p: np.ndarray, q: np.ndarray):
    """Reduced map of gravity-free chatter: impact at vertex 0, free flight at constant
    velocity until vertex 1 lands (τ = −f1ᵀq / f1ᵀU0p), rotation back by R⁻¹, and
    normalisation of p and q separately (without gravity (q, p, t) → (μq, νp, μt/ν) is
    a symmetry for any μ, ν)."""
    U0, Ri, f1 = model.U(0), model.R.T, model.F[1]
    pa = U0 @ p
    tau = -float(f1 @ q) / float(f1 @ pa)
    qb = Ri @ (q + pa * tau)
    pb = Ri @ pa
    return pb / np.linalg.norm(pb), qb / np.linalg.norm(qb)


def gravity_free_stability(model: LinearModel, p0: np.ndarray, q0: np.ndarray, h=1e-7):
    """Eigenvalues of the Jacobian (central differences) of `gravity_free_map` at the
    normalised self-similar chatter (p0, q0); the two normalisations contribute zeros."""
    p0 = p0 / np.linalg.norm(p0)
    q0 = q0 / np.linalg.norm(q0)
    x0 = np.r_[p0, q0]
    J = np.zeros((6, 6))
    for k in range(6):
        e = np.zeros(6)
        e[k] = h
        a = np.concatenate(gravity_free_map(model, (x0 + e)[:3], (x0 + e)[3:]))
        b = np.concatenate(gravity_free_map(model, (x0 - e)[:3], (x0 - e)[3:]))
        J[:, k] = (a - b) / (2 * h)
    if model.rank < 3:
        # the rod: the roll (φx, ωx) is invisible to the contacts; keep the planar block
        keep = [1, 2, 4, 5]
        J = J[np.ix_(keep, keep)]
    return np.linalg.eigvals(J)


def analyze_chatter(n: int, rho: float, gamma: float) -> dict:
    """The contract's `analyze chatter` document: eigenvalues of R⁻¹U0, CC, PCC, and
    β_p, β_q, c_lin where they exist (the rod's formulas for n = 2; for n ≥ 3 the
    dominant eigenvalue with each smaller positive one whose gravity-free self-similar
    motion is feasible)."""
    model = LinearModel.polygon(n, rho, gamma)
    M = chatter_matrix(model)
    lam = np.linalg.eigvals(M)
    lam = lam[np.argsort(-np.abs(lam))]
    doc: dict = {
        "n": n,
        "gyration": rho,
        "restitution": gamma,
        "eigenvalues": [[float(z.real), float(z.imag)] for z in lam],
        "cc": cc_property(model),
        "pcc": pcc_property(model),
        "beta_p": None,
        "beta_q": None,
        "c_lin": None,
    }
    if n == 2:
        doc["cc_subspace"] = "planar block (phi_y, h); the roll phi_x has eigenvalue -1"
        doc.update(rod_conditions(rho, gamma))
        b = rod_betas(rho, gamma)
        if b is not None:
            doc["beta_p"], doc["beta_q"] = b
            if 0 < b[1] < b[0] < 1:
                doc["c_lin"] = c_lin(*b)
        return doc
    real = sorted((z.real for z in lam if abs(z.imag) <= 1e-12 and 0 < z.real < 1), reverse=True)
    if doc["cc"] and real:
        bp = real[0]
        pairs = []
        for bq in real[1:]:
            ss = gravity_free_selfsimilar(model, bp, bq)
            if ss is not None:
                lam_j = gravity_free_stability(model, ss["p0"], ss["q0"])
                pairs.append(
                    {
                        "beta_p": bp,
                        "beta_q": bq,
                        "c_lin": c_lin(bp, bq),
                        "feasible": ss["feasible"],
                        "checks": ss["checks"],
                        "spectral_radius": float(np.max(np.abs(lam_j))),
                        "stable": bool(np.max(np.abs(lam_j)) < 1),
                    }
                )
        doc["pairs"] = pairs
        feas = [x for x in pairs if x["feasible"]]
        pick = feas[0] if feas else None
        if pick:
            doc["beta_p"], doc["beta_q"], doc["c_lin"] = (
                pick["beta_p"],
                pick["beta_q"],
                pick["c_lin"],
            )
    return doc


def format_chatter(doc: dict) -> str:
    """The eigenvalues, CC/PCC, the rod's thresholds and the self-similar pairs, then
    its legend (CHATTER_LEGEND, without the parts describing what is not printed)."""
    lines = [
        f"chatter (no gravity): n = {doc['n']}, ρ = {doc['gyration']}, γ = {doc['restitution']}",
        "eigenvalues of R^-1 U0: "
        + ", ".join(f"{re:.6g}{im:+.6g}i" if im else f"{re:.9g}" for re, im in doc["eigenvalues"]),
        f"CC  {'yes' if doc['cc'] else 'no'}    PCC  {'yes' if doc['pcc'] else 'no'}",
    ]
    if doc.get("psi") is not None:
        lines += [
            f"rod: psi = {doc['psi']:.6g}; complete chatter",
            f"  without gravity: {'yes' if doc['cc_without_gravity'] else 'no'} "
            f"(psi > {doc['psi_threshold_without_gravity']:.6g})",
            f"  with gravity:    {'yes' if doc['cc_with_gravity'] else 'no'} "
            f"(psi > {doc['psi_threshold_with_gravity']:.6g})",
        ]
    if doc.get("pairs"):
        rows = [
            [
                f"{x['beta_p']:.9g}",
                f"{x['beta_q']:.9g}",
                f"{x['c_lin']:.6g}",
                "yes" if x["feasible"] else "no",
                f"{x['spectral_radius']:.4g}",
            ]
            for x in doc["pairs"]
        ]
        lines.append(table(rows, ["beta_p", "beta_q", "c_lin", "feasible", "spectral radius"]))
    if doc["beta_p"] is not None:
        cl = doc["c_lin"]
        lines.append(
            f"beta_p = {doc['beta_p']:.9g}, beta_q = {doc['beta_q']:.9g}, c_lin = {cl:.6g}"
            if cl is not None
            else "c_lin = -"
        )
    if doc.get("pairs"):
        legend = CHATTER_LEGEND
    elif doc["beta_p"] is not None:
        legend = CHATTER_LEGEND_NO_TABLE
    else:
        legend = CHATTER_LEGEND_OUTPUT_ONLY
    lines += ["", legend]
    return "\n".join(lines)
