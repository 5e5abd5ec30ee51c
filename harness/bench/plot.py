"""The work-precision figure of `harness bench` (and of `harness report`)."""

from __future__ import annotations

import os
from typing import Any

from .settings import ERROR_FLOOR, METRIC_LABELS, METRICS

# ----------------------------------------------------------------------------- output


def plot_work_precision(doc: dict[str, Any], path: str | os.PathLike) -> str:
    """The work-precision figure (`work_precision_figure`) as a PNG file."""
    import matplotlib.pyplot as plt

    fig = work_precision_figure(doc)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return str(path)


def work_precision_figure(doc: dict[str, Any]):
    """Log-log: one panel per error metric, error against median wall time, one curve
    per simulator, points labelled with their setting; drawn from the bench document's
    rows alone (so `harness report` can redraw it)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = doc["results"]
    engines = list(dict.fromkeys(r["engine"] for r in rows))
    fig, axes = plt.subplots(1, len(METRICS), figsize=(6 * len(METRICS), 5.2))
    markers = "osD^v<>ph"
    for ax, metric in zip(axes, METRICS, strict=True):
        for k, engine in enumerate(engines):
            sel = [r for r in rows if r["engine"] == engine and r.get(metric) is not None]
            # in setting order (coarse to fine), as work-precision curves are drawn
            if not sel:
                continue
            x = [r["wall_time_s"] for r in sel]
            y = [max(r[metric], ERROR_FLOOR) for r in sel]
            ax.loglog(x, y, marker=markers[k % len(markers)], label=engine)
            for r, xi, yi in zip(sel, x, y, strict=True):
                tag = (
                    f"{r['dt']:g}"
                    if r["dt"] is not None
                    else (f"{r['contact_rtol']:g}" if r["contact_rtol"] is not None else "")
                )
                if tag:
                    ax.annotate(
                        tag, (xi, yi), fontsize=6, xytext=(3, 3), textcoords="offset points"
                    )
        ax.set_xlabel("wall time per run [s] (median)")
        ax.set_ylabel(METRIC_LABELS[metric], fontsize=8)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    load = doc.get("load", {}).get("before", [None])[0]
    fig.suptitle(
        f"work-precision on scene '{doc['scene']}' (t = 0 .. {doc['t_end']:.4g}, errors vs "
        f"reference at its tightest setting; below {ERROR_FLOOR:g} drawn at {ERROR_FLOOR:g}; "
        f"load {load:.2f})"
        if load is not None
        else f"work-precision on scene '{doc['scene']}'",
        fontsize=9,
    )
    fig.tight_layout()
    return fig
