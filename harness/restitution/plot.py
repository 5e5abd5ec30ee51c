"""One figure per engine: e_eff/γ − 1 against the impact speed, a panel per geometry, a
colour per dt and a marker per γ, the faithful band |e_eff/γ − 1| ≤ 1 % shaded.  The line
goes through the worst onset phase of each cell (as the table), a bar spans all phases."""

from __future__ import annotations

import math

MARKERS = ("o", "s", "^", "D", "v", "P", "X", "*")


def restitution_figure(engine_doc: dict, grid: dict, faithful: float):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    geos = grid["geometry"]
    fig, axes = plt.subplots(
        1, len(geos), figsize=(4.2 * len(geos) + 1.5, 4.4), sharey=True, layout="constrained"
    )
    axes = list(axes) if len(geos) > 1 else [axes]
    rows = engine_doc["rows"]
    dts = sorted({r["dt"] for r in rows}, key=lambda d: -(d if d is not None else math.inf))
    band = 100.0 * faithful
    for ax, geo in zip(axes, geos, strict=True):
        ax.axhspan(-band, band, color="0.85", zorder=0)
        ax.axhline(0.0, color="0.4", lw=0.8)
        for i, dt in enumerate(dts):
            for j, gamma in enumerate(grid["gamma"]):
                pts = _points(rows, geo, dt, gamma)
                if pts:
                    x, y, lo, hi = (list(c) for c in zip(*pts, strict=True))
                    style = {"color": f"C{i}", "marker": MARKERS[j % len(MARKERS)], "ms": 5}
                    ax.plot(x, y, lw=1, **style)
                    ax.vlines(x, lo, hi, color=f"C{i}", lw=2, alpha=0.5)
        ax.set_xscale("log")
        ax.set_yscale("symlog", linthresh=band, linscale=1.0)
        ax.set_title(geo)
        ax.set_xlabel("impact speed u⁻ [√(g a)]")
        ax.grid(True, which="major", lw=0.4, alpha=0.6)
    axes[0].set_ylabel("e_eff/γ − 1 [%]")
    _legend(fig, axes[-1], dts, grid["gamma"])
    fig.suptitle(f"{engine_doc['engine']}: restitution against γ (grey: within ±{band:g} %)")
    return fig


def _points(rows, geo, dt, gamma) -> list[tuple[float, float, float, float]]:
    """(speed, worst, lowest, highest) of e_eff/γ − 1 [%] over the phases of each cell
    that bounced in every phase."""
    from .study import worst_row

    out = []
    cell = [r for r in rows if r["geometry"] == geo and r["dt"] == dt and r["gamma"] == gamma]
    for v in sorted({r["speed"] for r in cell}):
        at = [r for r in cell if r["speed"] == v]
        worst = worst_row(at)
        if worst is None or worst["outcome"] != "ok" or worst["e_error"] is None:
            continue
        errs = [100.0 * r["e_error"] for r in at]
        out.append((v, 100.0 * worst["e_error"], min(errs), max(errs)))
    return out


def _legend(fig, ax, dts, gammas) -> None:
    from matplotlib.lines import Line2D

    handles = [
        Line2D(
            [], [], color=f"C{i}", lw=2, label="exact (event-driven)" if d is None else f"dt {d:g}"
        )
        for i, d in enumerate(dts)
    ]
    handles += [
        Line2D([], [], color="0.3", lw=0, marker=MARKERS[j % len(MARKERS)], label=f"γ = {g:g}")
        for j, g in enumerate(gammas)
    ]
    ax.legend(handles=handles, loc="center left", bbox_to_anchor=(1.02, 0.5), fontsize=8)
