"""Aggregates of a sweep's rows, and the theory drawn over the map.

- `grid_stats`: per grid point (γ, ρ), the mean of c over the runs that have one (the
  paper's figure shows the mean of the 100 runs, blank where none has a c), its spread,
  and the runs by status.
- `chatter_regions`: where the triangle (or n-gon) has the CC and PCC properties
  (reference.linear.chatter.cc_property / pcc_property, paper eqs. CCtriangle and
  PCCtriangle), on a grid fine enough to draw their boundaries.
- `c_lin_curve`: c_lin = 2 log β_p / log(β_q/β_p) (eq. clin) against γ at fixed ρ, from
  reference.linear.chatter.analyze_chatter, NaN where it does not exist.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from reference.trajectory import Status

from .grid import SweepConfig

STATUSES = tuple(s.value for s in Status)  # every status a run can end with


def grid_stats(df: pd.DataFrame, config: SweepConfig) -> pd.DataFrame:
    """One row per grid point of the config (also points without results yet):
    i_restitution, i_gyration, restitution, gyration, runs, n_c, mean_c, std_c,
    median_c, one count column per status, frac_simultaneous (of the runs done)."""
    gam, rho = config.gamma_values, config.rho_values
    ig, ir = np.meshgrid(np.arange(len(gam)), np.arange(len(rho)), indexing="ij")
    out = pd.DataFrame(
        {
            "i_restitution": ig.ravel(),
            "i_gyration": ir.ravel(),
            "restitution": gam[ig.ravel()],
            "gyration": rho[ir.ravel()],
        }
    )
    key = ["i_restitution", "i_gyration"]
    if len(df):
        g = df.groupby(key)
        agg = pd.DataFrame(
            {
                "runs": g.size(),
                "n_c": g["c"].count(),
                "mean_c": g["c"].mean(),
                "std_c": g["c"].std(ddof=0),
                "median_c": g["c"].median(),
            }
        )
        counts = df.groupby(key + ["status"]).size().unstack("status", fill_value=0)
        agg = agg.join(counts)
        out = out.merge(agg.reset_index(), on=key, how="left")
    else:
        for col in ("runs", "n_c", "mean_c", "std_c", "median_c"):
            out[col] = np.nan
    for s in STATUSES:
        if s not in out:
            out[s] = 0
    for col in ("runs", "n_c") + STATUSES:
        out[col] = out[col].fillna(0).astype(int)
    with np.errstate(invalid="ignore", divide="ignore"):
        out["frac_simultaneous"] = np.where(
            out["runs"] > 0, out["simultaneous_impact"] / out["runs"].clip(lower=1), np.nan
        )
    return out


def as_grid(stats: pd.DataFrame, column: str, config: SweepConfig) -> np.ndarray:
    """stats[column] as an array [i_gyration, i_restitution] (rows ρ, columns γ)."""
    a = np.full((config.gyration[2], config.restitution[2]), np.nan)
    a[stats["i_gyration"].to_numpy(), stats["i_restitution"].to_numpy()] = stats[column].to_numpy(
        dtype=float
    )
    return a


def chatter_regions(n: int, gammas: np.ndarray, rhos: np.ndarray):
    """(cc, pcc) boolean arrays [i_rho, i_gamma]: the CC and PCC properties of the
    gravity-free n-gon (ρ must be > 0)."""
    from reference.linear import chatter
    from reference.linear.model import LinearModel

    models = [LinearModel.polygon(n, float(r), float(g)) for r in rhos for g in gammas]
    # the eigenvalues of all the cells in one call each (cc_property and pcc_property,
    # one model at a time, are the same predicates on the same matrices)
    lam_cc = np.linalg.eigvals(np.array([chatter.cc_matrix(m) for m in models]))
    lam_pcc = np.linalg.eigvals(np.array([chatter.pcc_matrix(m) for m in models]))
    shape = (len(rhos), len(gammas))
    cc = np.array([chatter.cc_of_eigenvalues(lam) for lam in lam_cc]).reshape(shape)
    pcc = np.array([chatter.pcc_of_eigenvalues(lam) for lam in lam_pcc]).reshape(shape)
    return cc, pcc


def boundary_grid(lo_g: float, hi_g: float, lo_r: float, hi_r: float, k: int = 61):
    """Sample points for `chatter_regions` over a map's extent: ρ > 0, and extra
    resolution in γ near 0, where the PCC region is a thin strip for the triangle."""
    g_fine = np.linspace(lo_g, lo_g + 0.15 * (hi_g - lo_g), k // 2)
    g = np.unique(np.concatenate([g_fine, np.linspace(lo_g, hi_g, k)]))
    r = np.linspace(max(lo_r, 1e-3), hi_r, k)
    return g, r


def c_lin_curve(n: int, rho: float, gammas: np.ndarray) -> np.ndarray:
    """c_lin(γ) at fixed ρ (NaN where analyze_chatter gives none)."""
    from reference.linear.chatter import analyze_chatter

    out = np.full(len(gammas), np.nan)
    if not rho > 0:
        return out
    for j, g in enumerate(gammas):
        v = analyze_chatter(n, float(rho), float(g)).get("c_lin")
        if v is not None:
            out[j] = v
    return out


def section_rhos(rhos: np.ndarray, targets=(0.1, 0.2, 0.3, 0.4)) -> list[int]:
    """Indices of up to four grid values of ρ > 0 for the sections: the nearest to
    `targets` (the triangle's CC region lies below ρ ≈ 0.45), then the smallest
    remaining ones until there are four (or none are left)."""
    cand = [i for i in np.argsort(rhos) if rhos[i] > 0]
    idx: list[int] = []
    for t in targets:
        if cand:
            i = int(min(cand, key=lambda j: abs(rhos[j] - t)))
            if i not in idx:
                idx.append(i)
    for i in cand:
        if len(idx) >= 4:
            break
        if int(i) not in idx:
            idx.append(int(i))
    return sorted(idx, key=lambda j: rhos[j])
