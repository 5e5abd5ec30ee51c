"""The paper's figures of the energy's decay to the singularity (§3.6, §4, §5), from the
linearised model's runs and chatter analysis: energy_precession, rod_clin,
triangle_c_vs_clin."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from reference.linear.chatter import analyze_chatter, c_lin, rod_betas
from reference.linear.model import LinearModel
from reference.linear.selfsimilar import selfsimilar_solutions
from reference.linear.simulate import run_linear, run_linear_exponent

from .plotting import (
    ENERGY,
    GAMMA,
    TIME_TO_GO,
    pyplot,
    save,
)


def fig_energy_precession(out: Path, progress) -> dict:
    plt = pyplot()
    cases = [(20, 0.6), (20, 0.7), (25, 0.5), (25, 0.6), (30, 0.5), (30, 0.6)]
    fig, axes = plt.subplots(3, 2, figsize=(10, 10))
    cs = []
    from reference.linear import kernel as K
    from reference.linear.exponent_estimates import exponent_of_run

    for ax, (n, g) in zip(axes.flat, cases, strict=True):
        progress(f"  energy_precession n={n} gamma={g}")
        m = LinearModel.polygon(n, 0.5, g)
        s = [x for x in selfsimilar_solutions(m) if x.feasible][0]
        p0 = s.p0 * (1 + 1e-3 * np.array([1.0, -0.5, 0.0]))
        run = run_linear(m, s.q0, p0, max_impacts=200_000, energy_floor=1e-24)
        ex = exponent_of_run(run)
        lttg = K.log2_time_to_go(np.ascontiguousarray(run.log2_dt), ex["log2_time_remaining"])
        imp = run.impact_rows
        ttg = 2.0 ** lttg[imp]
        th = m.theta
        ke = 0.5 * np.sum(run.p_pre[imp] ** 2 * th, axis=1)
        pe = m.mass * m.gravity * run.q_pre[imp, 2]
        ax.loglog(ttg, ke + pe, "k-", lw=1, label="E")
        ax.loglog(ttg, ke, "-", lw=0.6, color="tab:red", label="kinetic")
        ax.loglog(ttg, pe, "-", lw=0.6, color="tab:blue", label="potential")
        ref = (ke[0] + pe[0]) * (ttg / ttg[0]) ** 2
        ax.loglog(ttg, ref, ":", color="gray", label="slope 2")
        ax.set_title(f"n = {n}, γ = {g}, ρ = 0.5: c = {ex['c']:.3f} ± {ex['c_stderr']:.1g}")
        ax.set_xlabel(TIME_TO_GO)
        ax.set_ylabel(ENERGY)
        cs.append((n, g, ex["c"], ex["c_decades"]))
    axes.flat[0].legend(fontsize=7)
    fig.suptitle("Perturbed self-similar motion drifts into precession; c ± its standard error")
    path = save(fig, out / "energy_precession.png", dpi=110)
    worst = max(abs(c - 2) for _, _, c, _ in cs)
    return {
        "path": str(path),
        "paper": "perturbed self-similar motion drifts into precession (growing "
        "oscillations of kinetic and potential energy) but keeps c ≈ 2",
        "ours": "c (regression / decades): "
        + "; ".join(f"n={n} γ={g}: {c:.3f}/{d:.3f}" for n, g, c, d in cs),
        "agree": bool(worst < 0.05),
        "headline": f"c of perturbed self-similar motion: {min(c for _, _, c, _ in cs):.3f} … "
        f"{max(c for _, _, c, _ in cs):.3f} over {len(cs)} runs (paper: 2)",
    }


def fig_rod_clin(out: Path, progress) -> dict:
    plt = pyplot()
    progress("  rod_clin")
    psis = np.linspace(0.005, 0.995, 199)
    gammas = np.linspace(0.005, 0.995, 199)
    C = np.full((len(psis), len(gammas)), np.nan)
    for i, psi in enumerate(psis):
        rho = math.sqrt((1 - psi) / (1 + psi))
        for j, g in enumerate(gammas):
            b = rod_betas(rho, float(g))
            if b is not None and 0 < b[1] < b[0] < 1:
                C[i, j] = c_lin(*b)
    fig, ax = plt.subplots(figsize=(6.5, 5))
    im = ax.pcolormesh(gammas, psis, np.log10(C), shading="auto", cmap="viridis", vmin=-2, vmax=1)
    fig.colorbar(im, ax=ax, label="log10 c_lin  [–]")
    cs = ax.contour(gammas, psis, C, levels=[0.5, 1, 2], colors="w", linewidths=0.8)
    ax.clabel(cs, fontsize=7)
    ax.plot(gammas, 2 * np.sqrt(gammas) / (1 + gammas), "r-", lw=1, label="CC boundary (no g)")
    ax.plot(
        gammas,
        (gammas ** (1 / 3) + gammas ** (2 / 3)) / (1 + gammas),
        "r--",
        lw=1,
        label="Or's condition (with g)",
    )
    ax.set_xlabel(GAMMA)
    ax.set_ylabel("ψ = (1 − ρ²)/(1 + ρ²)  [–]")
    ax.set_title("Falling rod (n = 2) without gravity: energy exponent c_lin")
    ax.legend(fontsize=7, loc="lower right")
    path = save(fig, out / "rod_clin.png")
    # checks: on Or's boundary c_lin = 2; near the CC boundary large; small at γ, ρ → 0
    g = 0.3
    psi_or = (g ** (1 / 3) + g ** (2 / 3)) / (1 + g)
    on_or = c_lin(*rod_betas(math.sqrt((1 - psi_or) / (1 + psi_or)), g))
    psi_cc = 2 * math.sqrt(g) / (1 + g) + 1e-6
    near_cc = c_lin(*rod_betas(math.sqrt((1 - psi_cc) / (1 + psi_cc)), g))
    small = c_lin(*rod_betas(0.01, 0.01))
    ours = (
        f"c_lin = {on_or:.6f} on Or's boundary (γ = 0.3), {near_cc:.1f} at 1e-6 above the "
        f"CC boundary, {small:.4f} at γ = ρ = 0.01"
    )
    return {
        "path": str(path),
        "paper": "c_lin → ∞ at the CC boundary, → 0 as γ → 0 or ρ → 0, = 2 on Or's boundary",
        "ours": ours,
        "agree": bool(abs(on_or - 2) < 1e-6 and near_cc > 10 and small < 0.05),
        "headline": f"c_lin = {on_or:.6f} on Or's boundary (paper: 2), {near_cc:.0f} just "
        f"above the CC boundary (paper: → ∞), {small:.2g} at γ = ρ = 0.01 (paper: → 0)",
    }


def fig_triangle_c_vs_clin(out: Path, progress, samples: int = 20) -> dict:
    plt = pyplot()
    rhos = [0.1, 0.15, 0.2, 0.25]
    gammas = np.linspace(0.02, 0.6, 30)
    rng = np.random.default_rng(0)
    fig, ax = plt.subplots(figsize=(7, 5))
    rows, long_rows = [], []
    for rho, col in zip(rhos, ["tab:blue", "tab:orange", "tab:green", "tab:red"], strict=True):
        progress(f"  triangle_c_vs_clin rho={rho}")
        gs, cm, cl = [], [], []
        for g in gammas:
            doc = analyze_chatter(3, rho, float(g))
            cs = []
            for _ in range(samples):
                chi = rng.uniform(-0.5, 0.5, 4)
                p = [0.1 * chi[0], 0.1 * chi[1], -1.0]
                q = [0.001 * chi[2], 0.001 * chi[3], 1.0]
                r = run_linear_exponent(3, rho, float(g), q, p)
                if r["c"] is not None:
                    cs.append(r["c"])
            if cs:
                gs.append(float(g))
                cm.append(float(np.mean(cs)))
                cl.append(doc["c_lin"] if doc["cc"] and not doc["pcc"] else math.nan)
                if doc["cc"] and not doc["pcc"] and doc["c_lin"] is not None:
                    rows.append((rho, float(g), float(np.mean(cs)), doc["c_lin"], len(cs)))
        ax.plot(gs, cm, "o", color=col, ms=3, label=f"ρ = {rho}: mean simulated c")
        ax.plot(gs, cl, "--", color=col, lw=1)
        # the asymptote: one run followed down 290 decades of energy
        ga, ca = [], []
        for g in gs[:: max(1, len(gs) // 6)]:
            doc = analyze_chatter(3, rho, g)
            if not (doc["cc"] and not doc["pcc"]):
                continue
            r = run_linear_exponent(
                3, rho, g, [2e-4, -1e-4, 1.0], [0.03, 0.02, -1.0], energy_floor=1e-290,
                max_impacts=200_000,
            )  # fmt: skip
            if r["c"] is not None:
                ga.append(g)
                ca.append(r["c"])
                long_rows.append((rho, g, r["c"], doc["c_lin"]))
        ax.plot(ga, ca, "x", color=col, ms=6)
    ax.plot([], [], "k--", label="c_lin (CC, not PCC)")
    ax.plot([], [], "kx", label="one run down 290 decades (asymptote)")
    ax.axhline(2, color="gray", lw=0.5)
    ax.set_yscale("log")
    ax.set_xlabel(GAMMA)
    ax.set_ylabel("energy exponent c  [–]")
    ax.set_title("Triangle (n = 3): simulated exponent c against c_lin")
    ax.legend(fontsize=7)
    path = save(fig, out / "triangle_c_vs_clin.png")
    rel = [abs(c - cl) / cl for _, _, c, cl, _ in rows]
    rel_long = [abs(c - cl) / cl for _, _, c, cl in long_rows]
    ours = (
        f"{len(rows)} (ρ, γ) points in the CC-not-PCC region with a fitted c (24 decades, "
        f"{samples} samples): |c − c_lin|/c_lin median {np.median(rel):.2f}, max "
        f"{np.max(rel):.2f}; c < 2 at {sum(c < 2 for _, _, c, _, _ in rows)} of them; "
        f"followed down 290 decades ({len(long_rows)} points): median "
        f"{np.median(rel_long):.2f}, max {np.max(rel_long):.2f} (c > c_lin towards the CC "
        "boundary, c < c_lin towards the PCC boundary)"
        if rows and long_rows
        else "no CC-not-PCC point produced an exponent"
    )
    return {
        "path": str(path),
        "paper": "in the CC-not-PCC region the simulated c is close to c_lin and mostly below 2",
        "ours": ours,
        "agree": bool(rows) and float(np.median(rel)) < 0.1,
        "headline": (
            f"CC-not-PCC region: median |c − c_lin|/c_lin = {np.median(rel):.2f} over "
            f"{len(rows)} (ρ, γ) points, c < 2 at {sum(c < 2 for _, _, c, _, _ in rows)} "
            "(paper: c close to c_lin, mostly below 2)"
            if rows
            else "no CC-not-PCC point produced an exponent"
        ),
        "points": [
            {"rho": r, "gamma": g, "c_mean": c, "c_lin": cl, "n": k} for r, g, c, cl, k in rows
        ],
        "asymptotic_points": [
            {"rho": r, "gamma": g, "c": c, "c_lin": cl} for r, g, c, cl in long_rows
        ],
    }
