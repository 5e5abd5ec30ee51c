"""The figure of `harness branches`: the energy above the resting level, one curve per
branch: against time over the whole run (left), and against the time since the first
undecidable state t_u on logarithmic axes (right), where the branches part."""

from __future__ import annotations

import os

import numpy as np

# every law its colour, line style and marker in every panel
LAWS_STYLE = {
    "moreau": {"color": "C0", "ls": "-", "marker": "o"},
    "sequential": {"color": "C1", "ls": "--", "marker": "s"},
    "compliant": {"color": "C2", "ls": "-.", "marker": "^"},
    "compliant-mass": {"color": "C3", "ls": ":", "marker": "v"},
}
LINESTYLES = ("-", "--", "-.", ":")


def same_curves(spread) -> list[tuple[list[str], object]]:
    """The branches grouped by energy curves that are the same to roundoff, in their
    order: ([names], branch) with the first branch of each group (compliant and
    compliant-mass, or the sequential law and the order it picks, are often the same
    run: drawn once, named together)."""
    groups: list[tuple[list[str], object]] = []
    for b in [spread.paper, *spread.branches]:
        for names, first in groups:
            if first.name != "paper" and _same_curve(b.energy_curve, first.energy_curve):
                names.append(b.name)
                break
        else:
            groups.append(([b.name], b))
    return groups


def _same_curve(a, b, rtol: float = 1e-9) -> bool:
    """Two (t, E) curves with the same samples: times equal to `rtol` of the last time,
    each energy to `rtol` of itself (the tails, many decades down, compared as closely
    as the start)."""
    (t0, e0), (t1, e1) = a, b
    if t0.shape != t1.shape or e0.shape != e1.shape or not len(t0):
        return False
    t_scale = rtol * max(float(np.max(np.abs(t0))), 1e-300)
    e_scale = rtol * np.maximum(np.abs(e0), np.abs(e1))
    return bool(np.all(np.abs(t0 - t1) <= t_scale) and np.all(np.abs(e0 - e1) <= e_scale))


def plot_spread(spread, path: str | os.PathLike) -> str:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (whole, after) = plt.subplots(1, 2, figsize=(13, 5.6))
    t_u = spread.undecidable["t"] if spread.undecidable is not None else None
    for i, (names, b) in enumerate(same_curves(spread)):
        t, e = b.energy_curve
        label = " = ".join(names) + f": {b.status}"
        style = (
            {"lw": 2.5, "color": "k", "zorder": 5}
            if b.name == "paper"
            else {"lw": 1.4, "color": f"C{i - 1}", "ls": LINESTYLES[(i - 1) % len(LINESTYLES)]}
        )
        keep = e > 0
        whole.semilogy(t[keep], e[keep], label=label, **style)
        if t_u is not None:
            late = keep & (t > t_u)
            after.loglog(t[late] - t_u, e[late], drawstyle="steps-post", **style)
    if t_u is not None:
        whole.axvline(t_u, color="grey", ls="--", lw=1, label="t_u: first undecidable state")
    whole.set_xlabel("t [s]")
    whole.set_ylabel("energy above the resting level [J]")
    whole.set_title("whole run")
    after.set_xlabel("t - t_u [s]")
    after.set_title("after t_u" if t_u is not None else "no undecidable state")
    handles, labels = whole.get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=min(3, len(labels)), fontsize=8,
               frameon=False)  # fmt: skip
    fig.suptitle(f"{spread.scene}: branches at the first undecidable state")
    rows = -(-len(labels) // 3)
    fig.tight_layout(rect=(0, 0.035 * rows + 0.02, 1, 1))
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return str(path)


def plot_engines(studies, path: str | os.PathLike) -> str:
    """Distance to each law against dt: one panel per landing (rows) and engine
    (columns), one curve per law (the sequential law: its nearest order), each law its
    own colour, line and marker in every panel, one legend for the figure."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.lines import Line2D

    from .engines import LAWS

    engines = sorted({r.engine for st in studies for r in st.runs})
    cols = max(1, len(engines))
    fig, axes = plt.subplots(len(studies), cols, squeeze=False,
                             figsize=(3.2 * cols, 2.6 * len(studies) + 0.6))  # fmt: skip
    drawn = set()
    for row, st in zip(axes, studies, strict=True):
        for ax, engine in zip(row, engines, strict=False):
            for law in LAWS:
                pts = law_curve(st, engine, law)
                if pts:
                    x, y = zip(*pts, strict=True)
                    ax.loglog(x, np.maximum(y, 1e-16), ms=4, **LAWS_STYLE[law])
                    drawn.add(law)
            ax.set_title(f"{st.scene}\n{engine}", fontsize=8)
            ax.tick_params(labelsize=7)
    for ax in axes[-1]:
        ax.set_xlabel("dt [s]", fontsize=8)
    for row in axes:
        row[0].set_ylabel("distance after the impact", fontsize=8)
    laws = [law for law in LAWS if law in drawn]
    if laws:  # event-driven engines have no dt to plot against
        handles = [Line2D([], [], ms=4, **LAWS_STYLE[law]) for law in laws]
        fig.legend(handles, laws, loc="upper center", ncol=len(laws), fontsize=8,
                   frameon=False, title="distance to the nearest outcome of each law",
                   title_fontsize=8)  # fmt: skip
    top = 1 - 0.6 / fig.get_figheight()
    fig.tight_layout(rect=(0, 0, 1, top))
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
