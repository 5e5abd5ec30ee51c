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
    """Distance to each outcome against dt, one panel per landing, one colour per
    outcome, one marker per engine."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, len(studies), figsize=(5.5 * len(studies), 4.5), squeeze=False)
    markers = "osD^v<>px"
    for ax, st in zip(axes[0], studies, strict=True):
        engines = sorted({r.engine for r in st.runs})
        for j, o in enumerate(st.outcomes):
            for m, engine in enumerate(engines):
                pts = [
                    (r.dt, r.distances[o.name]) for r in st.runs
                    if r.engine == engine and r.dt is not None and o.name in r.distances
                ]  # fmt: skip
                if pts:
                    x, y = zip(*sorted(pts), strict=True)
                    ax.loglog(x, np.maximum(y, 1e-16), marker=markers[m % len(markers)],
                              color=f"C{j}", label=f"{engine}: {o.name}")  # fmt: skip
        ax.set_xlabel("dt")
        ax.set_ylabel("distance after the impact")
        ax.set_title(st.scene)
        ax.legend(fontsize=6)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return str(path)
