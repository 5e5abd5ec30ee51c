"""PNGs of an exponent sweep (the paper's figures numsim and numsimsec, section 4.3).

- `exponent-map.png`: mean c over (γ, ρ), blank where no run has a c, with the CC and
  PCC boundaries; the colour scale is centred on c = 2 (self-similar motion).
- `simultaneous.png`: fraction of runs ending in a simultaneous (undecidable) impact.
- `sections.png`: c against γ for four values of ρ: every run's c (dots), the mean
  (line), and c_lin of eq. clin (dashed).
- `compare-<engine>-vs-<base>.png` (in the study directory): an engine's map beside
  the base simulator's (linear, else reference) and their sections overlaid.
"""

from __future__ import annotations

import functools
from pathlib import Path

import numpy as np
import pandas as pd

from ..outputs import atomic_write
from .grid import SweepConfig
from .stats import (
    as_grid,
    boundary_grid,
    c_lin_curve,
    chatter_regions,
    grid_stats,
    section_rhos,
)

C_MAX = 4.0


def _plt():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _edges(v: np.ndarray) -> np.ndarray:
    if len(v) == 1:
        return np.array([v[0] - 0.5, v[0] + 0.5]) if v[0] == 0 else v[0] * np.array([0.9, 1.1])
    mid = 0.5 * (v[1:] + v[:-1])
    return np.concatenate([[v[0] - (mid[0] - v[0])], mid, [v[-1] + (v[-1] - mid[-1])]])


class Boundaries:
    """CC / PCC regions over a map's extent, computed once per figure set."""

    def __init__(self, config: SweepConfig, k: int = 61):
        g, r = config.gamma_values, config.rho_values
        ge, re = _edges(g), _edges(r)
        lo_g, hi_g = max(0.0, ge[0]), min(1.0, ge[-1])
        lo_r, hi_r = max(0.0, re[0]), re[-1]
        self.g, self.r, self.cc, self.pcc = _regions(config.n, lo_g, hi_g, lo_r, hi_r, k)

    def draw(self, ax) -> list:
        handles = []
        for field, color, name in ((self.cc, "k", "CC"), (self.pcc, "m", "PCC")):
            if field.any() and not field.all():
                ax.contour(self.g, self.r, field.astype(float), levels=[0.5], colors=color)
                handles.append(_line(color, f"{name} boundary"))
        return handles


@functools.lru_cache(maxsize=8)
def _regions(n, lo_g, hi_g, lo_r, hi_r, k):
    g, r = boundary_grid(lo_g, hi_g, lo_r, hi_r, k)
    return (g, r) + chatter_regions(n, g, r)


def _line(color, label, **kw):
    from matplotlib.lines import Line2D

    return Line2D([], [], color=color, label=label, **kw)


def _heatmap(ax, stats, config, column, cmap, norm, annotate_fmt):
    g, r = config.gamma_values, config.rho_values
    a = as_grid(stats, column, config)
    cmap = _plt().get_cmap(cmap).with_extremes(bad="0.85")
    if norm is None:
        from matplotlib.colors import Normalize

        norm = Normalize(0.0, 1.0)
    mesh = ax.pcolormesh(_edges(g), _edges(r), np.ma.masked_invalid(a), cmap=cmap, norm=norm)
    if len(g) * len(r) <= 900:
        fs = 7 if max(len(g), len(r)) <= 12 else 4.5
        for i in range(len(r)):
            for j in range(len(g)):
                if np.isfinite(a[i, j]):
                    ax.text(
                        g[j], r[i], annotate_fmt(a[i, j]), ha="center", va="center", fontsize=fs
                    )
    ax.set_xlabel("restitution γ")
    ax.set_ylabel("gyration ρ")
    return mesh


def _c_norm():
    from matplotlib.colors import TwoSlopeNorm

    return TwoSlopeNorm(vmin=0.0, vcenter=2.0, vmax=C_MAX)


def plot_exponent_map(ax, stats, config, bounds: Boundaries | None, title: str):
    mesh = _heatmap(ax, stats, config, "mean_c", "RdBu_r", _c_norm(), lambda x: f"{x:.2f}")
    handles = bounds.draw(ax) if bounds is not None else []
    if handles:
        ax.legend(handles=handles, loc="upper right", fontsize=7)
    ax.set_title(title, fontsize=9)
    return mesh


def plot_sections(axes, df_by_engine: dict, configs: dict, n: int, colors=None):
    """c against γ at four ρ of the first engine's grid, one axes each; every engine's
    runs (dots) and means (line) at its nearest ρ, and c_lin (dashed)."""
    first = next(iter(configs.values()))
    idx = section_rhos(first.rho_values)
    colors = colors or ["C0", "C1", "C2", "C3"]
    for ax, i in zip(axes, idx, strict=False):
        rho = float(first.rho_values[i])
        gg = np.linspace(0.0, 1.0, 201)
        ax.plot(gg, c_lin_curve(n, rho, gg), "k--", lw=1.2, label="c_lin (eq. clin)")
        for (eng, df), col in zip(df_by_engine.items(), colors, strict=False):
            cfg = configs[eng]
            j = int(np.argmin(np.abs(cfg.rho_values - rho)))
            sub = df[(df["i_gyration"] == j) & df["c"].notna()]
            jitter = 0.004 * (np.arange(len(sub)) % 5 - 2)
            ax.plot(
                sub["restitution"] + jitter,
                sub["c"].clip(upper=2 * C_MAX),
                ".",
                color=col,
                ms=2,
                alpha=0.35,
            )
            # means on the engine's whole γ grid, NaN (a gap in the line) where no c
            m = sub.groupby("i_restitution")["c"].mean().reindex(range(len(cfg.gamma_values)))
            ax.plot(
                cfg.gamma_values, m.to_numpy(), "o-", color=col, ms=3, lw=1, label=f"{eng} mean c"
            )
        ax.axhline(2.0, color="0.6", lw=0.8, zorder=0)
        ax.set_ylim(0, C_MAX)
        ax.set_xlim(-0.02, 1.02)
        ax.set_title(f"ρ = {rho:.3g}", fontsize=9)
        ax.set_xlabel("restitution γ")
        ax.set_ylabel("c")
    if len(axes):
        axes[0].legend(fontsize=6, loc="upper left")
    for ax in axes[len(idx) :]:
        ax.set_visible(False)


def sweep_label(config: SweepConfig) -> str:
    """'linear, n = 3, 100 runs per point, seed 0' (the figures' subtitle)."""
    return f"{config.engine}, n = {config.n}, {config.samples} runs per point, seed {config.seed}"


def exponent_map_figure(
    stats: pd.DataFrame, config: SweepConfig, bounds: Boundaries | None, label: str
):
    """The exponent map (mean c per grid point, CC/PCC boundaries) as a figure, from
    the per-point statistics alone (`grid_stats`), so `harness report` can redraw it
    from a sweep's JSON summary."""
    plt = _plt()
    fig, ax = plt.subplots(figsize=(8, 6.5), layout="constrained")
    mesh = plot_exponent_map(ax, stats, config, bounds, f"mean energy exponent c ({label})")
    fig.colorbar(mesh, ax=ax, label="mean c (grey: no run with a c)")
    return fig


def _save(fig, path, dpi: int) -> None:
    """Write the figure atomically (a sweep's PNGs are redrawn on every run, so an old
    one is replaced) and free it."""
    try:
        with atomic_write(path, force=True) as tmp:
            fig.savefig(tmp, dpi=dpi)
    finally:
        _plt().close(fig)


def make_sweep_figures(
    sweep_dir: Path, df: pd.DataFrame, config: SweepConfig, boundary_points: int = 61
) -> dict:
    """The three PNGs of one engine's sweep; returns {name: path}."""
    plt = _plt()
    sweep_dir = Path(sweep_dir)
    stats = grid_stats(df, config)
    bounds = Boundaries(config, boundary_points)
    label = sweep_label(config)
    paths = {}

    fig = exponent_map_figure(stats, config, bounds, label)
    paths["exponent_map"] = str(sweep_dir / "exponent-map.png")
    _save(fig, paths["exponent_map"], dpi=130)

    fig, ax = plt.subplots(figsize=(8, 6.5), layout="constrained")
    mesh = _heatmap(ax, stats, config, "frac_simultaneous", "viridis", None, lambda x: f"{x:.2f}")
    handles = bounds.draw(ax)
    if handles:
        ax.legend(handles=handles, loc="upper right", fontsize=7)
    ax.set_title(f"fraction of runs ending in a simultaneous impact ({label})", fontsize=9)
    fig.colorbar(mesh, ax=ax, label="fraction")
    paths["simultaneous"] = str(sweep_dir / "simultaneous.png")
    _save(fig, paths["simultaneous"], dpi=130)

    fig, axes = plt.subplots(2, 2, figsize=(10, 7.5), layout="constrained")
    plot_sections(list(axes.ravel()), {config.engine: df}, {config.engine: config}, config.n)
    fig.suptitle(f"sections of the exponent map: runs (dots), means, c_lin ({label})", fontsize=9)
    paths["sections"] = str(sweep_dir / "sections.png")
    _save(fig, paths["sections"], dpi=130)
    return paths


def make_compare_figure(
    root: Path,
    base: tuple[str, pd.DataFrame, SweepConfig],
    other: tuple[str, pd.DataFrame, SweepConfig],
    boundary_points: int = 61,
) -> str:
    """`other`'s map beside `base`'s and their sections overlaid (same n)."""
    plt = _plt()
    fig = plt.figure(figsize=(14, 9.5), layout="constrained")
    gs = fig.add_gridspec(2, 4, height_ratios=[1.3, 1])
    mesh = None
    eg = np.concatenate([_edges(c.gamma_values) for c in (base[2], other[2])])
    er = np.concatenate([_edges(c.rho_values) for c in (base[2], other[2])])
    for k, (eng, df, cfg) in enumerate((base, other)):
        ax = fig.add_subplot(gs[0, 2 * k : 2 * k + 2])
        ax.set_xlim(eg.min(), eg.max())
        ax.set_ylim(er.min(), er.max())
        title = f"{eng}: mean c, {cfg.samples} runs per point"
        if cfg.dt:
            title += f", dt = {cfg.dt:g}"
        mesh = plot_exponent_map(
            ax, grid_stats(df, cfg), cfg, Boundaries(cfg, boundary_points), title
        )
    fig.colorbar(mesh, ax=fig.axes, label="mean c", shrink=0.6)
    axes = [fig.add_subplot(gs[1, j]) for j in range(4)]
    plot_sections(
        axes,
        {base[0]: base[1], other[0]: other[1]},
        {base[0]: base[2], other[0]: other[2]},
        base[2].n,
    )
    path = Path(root) / f"compare-{other[0]}-vs-{base[0]}.png"
    fig.suptitle(f"energy exponent: {other[0]} against {base[0]} (n = {base[2].n})")
    _save(fig, path, dpi=110)
    return str(path)
