"""The figure of `harness branches`: the energy above the resting level, one curve per
branch: against time over the whole run (left), and against the time since the first
undecidable state t_u on logarithmic axes (right), where the branches part."""

from __future__ import annotations

import os

import numpy as np


def plot_spread(spread, path: str | os.PathLike) -> str:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (whole, after) = plt.subplots(1, 2, figsize=(13, 5))
    t_u = spread.undecidable["t"] if spread.undecidable is not None else None
    for b in [spread.paper, *spread.branches]:
        t, e = b.energy_curve
        style = {"lw": 2.5, "color": "k", "zorder": 5} if b.name == "paper" else {"lw": 1.2}
        keep = e > 0
        whole.semilogy(t[keep], e[keep], label=f"{b.name}: {b.status}", **style)
        if t_u is not None:
            late = keep & (t > t_u)
            after.loglog(t[late] - t_u, e[late], drawstyle="steps-post", label=b.name, **style)
    if t_u is not None:
        whole.axvline(t_u, color="grey", ls="--", lw=1, label="t_u")
    whole.set_xlabel("t")
    whole.set_ylabel("energy above the resting level")
    whole.set_title(f"{spread.scene}: branches at the first undecidable state")
    whole.legend(fontsize=8)
    after.set_xlabel("t - t_u")
    after.set_title("after t_u" if t_u is not None else "no undecidable state")
    if t_u is not None and np.isfinite(t_u):
        after.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return str(path)


def plot_engines(studies, path: str | os.PathLike) -> str:
    """Distance to each law against dt: one panel per landing (rows) and engine
    (columns), one curve per law (the sequential law: its nearest order)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from .engines import LAWS

    engines = sorted({r.engine for st in studies for r in st.runs})
    fig, axes = plt.subplots(len(studies), len(engines), squeeze=False,
                             figsize=(3.2 * len(engines), 2.6 * len(studies)))  # fmt: skip
    for row, st in zip(axes, studies, strict=True):
        for ax, engine in zip(row, engines, strict=True):
            for law in LAWS:
                pts = law_curve(st, engine, law)
                if pts:
                    x, y = zip(*pts, strict=True)
                    ax.loglog(x, np.maximum(y, 1e-16), marker="o", label=law)
            ax.set_title(f"{st.scene}\n{engine}", fontsize=8)
            ax.tick_params(labelsize=7)
    if axes[0][0].lines:  # event-driven engines have no dt to plot against
        axes[0][0].legend(fontsize=7)
    for ax in axes[-1]:
        ax.set_xlabel("dt", fontsize=8)
    for row in axes:
        row[0].set_ylabel("distance after the impact", fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return str(path)


def law_curve(study, engine: str, law: str) -> list[tuple[float, float]]:
    """(dt, distance to the nearest outcome of `law`) of one engine's runs, by dt."""
    names = [o.name for o in study.outcomes if o.law == law]
    pts = []
    for r in study.runs:
        d = [r.distances[n] for n in names if n in r.distances]
        if r.engine == engine and r.dt is not None and d:
            pts.append((r.dt, min(d)))
    return sorted(pts)
