"""The paper's figures of self-similar motions (§3), from reference.linear.selfsimilar:
beta_vs_rho, feasibility_border, beta_vs_gamma, boundaries."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from .plotting import (
    GAMMA,
    RHO,
    legend,
    pyplot,
    save,
    scatter_betas,
    solutions,
)


def fig_beta_vs_rho(out: Path, progress) -> dict:
    plt = pyplot()
    rhos = np.linspace(0.02, 1.0, 50)
    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    facts = {}
    for ax, n in zip(axes, (3, 25), strict=True):
        progress(f"  beta_vs_rho n={n}")
        sols = [solutions(n, float(r), 0.0, stability=False) for r in rhos]
        scatter_betas(ax, rhos, sols, RHO)
        ax.set_title(f"n = {n}, γ = 0")
        legend(ax)
        small = [s for s in sols[0] if s.trivial]
        facts[n] = {
            "trivial_at_small_rho": len(small),
            "rho_without_nontrivial": [
                float(r)
                for r, ss in zip(rhos, sols, strict=True)
                if not any(not s.trivial for s in ss)
            ],
            "feasible_rhos": [
                float(r) for r, ss in zip(rhos, sols, strict=True) if any(s.feasible for s in ss)
            ],
        }
    fig.suptitle("Self-similar motions of the plastic polygon (γ = 0): β against ρ")
    path = save(fig, out / "beta_vs_rho.png")
    f3, f25 = facts[3], facts[25]
    ours = (
        f"trivial solutions at small ρ: {f3['trivial_at_small_rho']} (n=3), "
        f"{f25['trivial_at_small_rho']} (n=25); n=25 has a feasible nontrivial solution "
        f"for ρ ≥ {min(f25['feasible_rhos']):.2f}; n=3 has no nontrivial β in (0,1) for "
        f"{len(f3['rho_without_nontrivial'])} of {len(rhos)} ρ values "
        f"(feasible only for ρ ≥ {min(f3['feasible_rhos'], default=math.nan):.2f})"
    )
    agree = f3["trivial_at_small_rho"] == 1 and f25["trivial_at_small_rho"] == 2
    return {
        "path": str(path),
        "paper": "one trivial β > 0 for n = 3, two for n > 3 at small ρ; at least one "
        "positive nontrivial root for all parameters; nontrivial solutions feasible for "
        "large enough ρ when n > 3",
        "ours": ours,
        "agree": bool(agree and not f3["rho_without_nontrivial"]),
        "headline": f"trivial β at small ρ: {f3['trivial_at_small_rho']} for n = 3, "
        f"{f25['trivial_at_small_rho']} for n = 25 (paper: 1, 2); n = 3 has no nontrivial β in "
        f"(0, 1) at {len(f3['rho_without_nontrivial'])} of {len(rhos)} ρ",
        "note": "disagree only in part: for n = 3, γ = 0 the nontrivial roots of N(β) "
        "lie outside (0, 1) over most of the ρ range"
        if f3["rho_without_nontrivial"]
        else "",
    }


def _smallest_feasible_rho(n: int, rhos) -> float:
    """The first ρ of `rhos` at which the n-gon (γ = 0) has a feasible self-similar
    motion (nan if none): the ρ after it are not needed."""
    for r in rhos:
        if any(s.feasible for s in solutions(n, float(r), 0.0, stability=False)):
            return float(r)
    return math.nan


def fig_feasibility_border(out: Path, progress) -> dict:
    plt = pyplot()
    ns = [3, 4, 5, 6, 7, 8, 10, 12, 15, 20, 25, 30, 40, 50]
    rhos = np.linspace(0.01, 1.0, 100)
    border = []
    for n in ns:
        progress(f"  feasibility_border n={n}")
        border.append(_smallest_feasible_rho(n, rhos))
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.plot(ns, border, "o-")
    ax.axhline(0.5, color="k", lw=0.8, ls=":", label="homogeneous disk ρ ≈ 1/2")
    ax.set_xlabel("n, number of vertices  [–]")
    ax.set_ylabel("smallest feasible ρ  [–]")
    ax.set_title("Feasible self-similar motion (γ = 0) above the curve (ρ step 0.01)")
    ax.legend(fontsize=8)
    path = save(fig, out / "feasibility_border.png")
    ok = all(b < 0.5 for n, b in zip(ns, border, strict=True) if n > 3)
    return {
        "path": str(path),
        "paper": "for ρ ≈ 1/2 the nontrivial self-similar solution is feasible for all n > 3",
        "ours": "smallest feasible ρ: "
        + ", ".join(f"n={n}: {b:.2f}" for n, b in zip(ns, border, strict=True)),
        "agree": bool(ok),
        "headline": "smallest feasible ρ (γ = 0) for n > 3: at most "
        f"{max(b for n, b in zip(ns, border, strict=True) if n > 3):.2f} (paper: below 1/2)",
    }


def fig_beta_vs_gamma(out: Path, progress) -> dict:
    plt = pyplot()
    gammas = np.linspace(0.0, 0.98, 50)
    fig, axes = plt.subplots(2, 2, figsize=(10, 7))
    multi = []
    for ax, (n, rho) in zip(axes.flat, [(3, 0.25), (3, 0.5), (25, 0.25), (25, 0.5)], strict=True):
        progress(f"  beta_vs_gamma n={n} rho={rho}")
        sols = [solutions(n, rho, float(g), stability=False) for g in gammas]
        scatter_betas(ax, gammas, sols, GAMMA)
        ax.set_title(f"n = {n}, ρ = {rho}")
        multi += [(n, rho, float(g)) for g, ss in zip(gammas, sols, strict=True) if len(ss) > 1]
    legend(axes.flat[0])
    fig.suptitle("Self-similar motions with restitution: β against γ")
    path = save(fig, out / "beta_vs_gamma.png")
    return {
        "path": str(path),
        "paper": "trivial solutions for small ρ and γ, feasible or infeasible nontrivial "
        "ones; in some cases several self-similar motions with different β",
        "ours": f"{len(multi)} of {4 * len(gammas)} (n, ρ, γ) points have more than one "
        "self-similar β (trivial or not)",
        "agree": bool(multi),
        "headline": f"{len(multi)} of {4 * len(gammas)} (n, ρ, γ) points have more than one "
        "self-similar β (paper: several in some cases)",
    }


def fig_boundaries(out: Path, progress) -> dict:
    plt = pyplot()
    ns = [3, 4, 6, 10, 25]
    gammas = np.linspace(0.0, 0.95, 20)
    rhos = np.linspace(0.05, 1.0, 20)
    fig, ax = plt.subplots(figsize=(7, 5.5))
    colors = plt.cm.viridis(np.linspace(0, 0.9, len(ns)))
    rho05_stable, g0_unstable = [], []
    for n, col in zip(ns, colors, strict=True):
        progress(f"  boundaries n={n}")
        feas = np.zeros((len(rhos), len(gammas)))
        stab = np.zeros_like(feas)
        triv = np.zeros_like(feas)
        for i, r in enumerate(rhos):
            for j, g in enumerate(gammas):
                sols = solutions(n, float(r), float(g))
                fs = [s for s in sols if s.feasible]
                feas[i, j] = bool(fs)
                stab[i, j] = bool(fs) and all(s.stable for s in fs)
                triv[i, j] = any(s.trivial for s in sols)
                if fs and g == 0 and not stab[i, j] and r <= 1 / math.sqrt(2):
                    g0_unstable.append((n, float(r)))
        for field, ls in ((feas, "-."), (stab, "--"), (triv, "-")):
            if 0 < field.mean() < 1:
                ax.contour(gammas, rhos, field, levels=[0.5], colors=[col], linestyles=ls)
        ax.plot([], [], color=col, label=f"n = {n}")
        for g in np.linspace(0.05, 0.95, 19):
            fs = [s for s in solutions(n, 0.5, float(g)) if s.feasible]
            rho05_stable += [(n, float(g)) for s in fs if s.stable]
    ax.plot([], [], "k-.", label="feasible above")
    ax.plot([], [], "k--", label="stable (feasible) left of")
    ax.plot([], [], "k-", label="trivial below")
    ax.set_xlabel(GAMMA)
    ax.set_ylabel(RHO)
    ax.set_title("Self-similar motion: existence, feasibility and stability over (γ, ρ)")
    ax.legend(fontsize=7, loc="upper right")
    path = save(fig, out / "boundaries.png")
    return {
        "path": str(path),
        "paper": "γ = 0: feasible self-similar motion is always stable; ρ = 0.5: unstable "
        "for all n and γ > 0",
        "ours": f"ρ = 0.5, γ ∈ [0.05, 0.95], n ∈ {ns}: {len(rho05_stable)} stable feasible "
        f"solutions; γ = 0, ρ ≤ 1/√2: feasible but unstable at {g0_unstable or 'none'} "
        "(outside: n = 3 for ρ ≥ 0.71, n = 4 for ρ ≥ 0.78, n = 5 for ρ ≥ 1.34)",
        "agree": bool(not rho05_stable and not g0_unstable),
        "headline": f"stable feasible solutions at ρ = 0.5, γ > 0: {len(rho05_stable)}; "
        f"unstable feasible ones at γ = 0, ρ ≤ 1/√2: {len(g0_unstable)} (paper: none, none)",
    }
