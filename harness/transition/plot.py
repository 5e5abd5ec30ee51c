"""The figure of `harness transition`, drawn from its JSON document alone: energy above
the rest against the time to the singularity at each impact, log-log, coloured by the
kind of contact that took it, with the regimes shaded."""

from __future__ import annotations

from typing import Any

import numpy as np

COLOURS = {"rim": "C0", "bump": "C3"}
SHADES = {"rim_only": "C0", "mixed": "C4", "bumps_only": "C3"}
# t_f is the singularity when the run reached it, else its last impact (regimes.end_time)
XLABELS = {
    "t_singularity": "time to the singularity t_f - t [s]",
    "last_impact": "time to the last impact t_f - t [s] (the run ends there, short of t_f)",
    "last_time": "time to the run's end t_f - t [s]",
}
LABELS = {"rim_only": "rim only", "mixed": "mixed", "bumps_only": "bumps only"}


def transition_figure(doc: dict[str, Any]):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7.5, 5.0), layout="constrained")
    pts = doc["impacts"]
    ttg = np.asarray(pts["time_to_singularity"], dtype=float)
    E = np.asarray(pts["energy"], dtype=float)
    kind = np.asarray(pts["kind"])
    for k, colour in COLOURS.items():
        sel = (kind == k) & (ttg > 0) & (E > 0)
        if sel.any():
            ax.loglog(ttg[sel], E[sel], ".", ms=2, color=colour, label=f"{k} impact")
    shown = ttg[(ttg > 0) & (E > 0)]
    floor = 0.5 * float(shown.min()) if len(shown) else 1e-12  # the plot's left edge
    for r in doc["regimes"]:
        hi = r["time_to_singularity_at_start"]
        lo = max(doc["t_f"] - r["t_end"], floor)
        if hi <= lo:
            continue
        c = "" if r["c"] is None else f", c = {r['c']:.2f}"
        ax.axvspan(lo, hi, color=SHADES[r["regime"]], alpha=0.12)
        ax.plot([], [], color=SHADES[r["regime"]], alpha=0.3, lw=8, label=LABELS[r["regime"]] + c)
    ax.set_xlim(left=floor)
    ax.set_xlabel(XLABELS.get(doc.get("t_f_source"), XLABELS["t_singularity"]))
    ax.set_ylabel("energy above the rest on the bumps [J]")
    tk = doc["takeover"]
    ax.set_title(
        f"{doc['scene']} ({doc['engine']}): Delta/a = {tk['delta_over_a']:.3g}, "
        f"first bump at tilt {tk['first_bump_tilt'] or float('nan'):.3g}",
        fontsize=10,
    )
    ax.legend(fontsize=8, loc="best")
    return fig


def save_figure(fig, path) -> None:
    import matplotlib.pyplot as plt

    fig.savefig(path, dpi=120, format="png")
    plt.close(fig)
