"""The work-precision figure of `harness bench` (and of `harness report`).

Three log-log panels (one per error metric), error against median wall time, one curve
per simulator in setting order (coarse to fine).  Points are labelled with their
setting (dt, or the reference's contact_rtol) where the label does not overlap another;
a run that does not follow the reference (harness.metrics.follows) is drawn hollow.
The truth's own row (error 0 against itself) is left out, and the y axis runs from a
decade below the smallest error drawn."""

from __future__ import annotations

import math
import os
from typing import Any

from .settings import ERROR_FLOOR, METRIC_LABELS, METRICS, TRUTH

MARKERS = "osD^v<>ph"
FONT = 10
TAG_FONT = 8
# A label's box in pixels (four characters at TAG_FONT): one that would overlap a label
# already placed is left out.
TAG_BOX_PX = (34, 14)


def plot_work_precision(doc: dict[str, Any], path: str | os.PathLike) -> str:
    """The work-precision figure (`work_precision_figure`) as a PNG file."""
    import matplotlib.pyplot as plt

    fig = work_precision_figure(doc)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return str(path)


def work_precision_figure(doc: dict[str, Any]):
    """The figure (module docstring), drawn from the bench document's rows alone (so
    `harness report` can redraw it)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = [r for r in doc["results"] if not _is_truth(r)]
    engines = list(dict.fromkeys(r["engine"] for r in rows))
    with plt.rc_context({"font.size": FONT}):
        fig, axes = plt.subplots(1, len(METRICS), figsize=(15, 5.4))
        for ax, metric in zip(axes, METRICS, strict=True):
            _panel(ax, rows, engines, metric)
        handles, labels = axes[0].get_legend_handles_labels()
        fig.legend(handles, labels, loc="lower center", ncol=min(len(labels), 8), frameon=False)
        fig.suptitle(_title(doc), fontsize=FONT + 1)
        fig.tight_layout(rect=(0, 0.07, 1, 1))
    return fig


def _is_truth(row: dict[str, Any]) -> bool:
    return row["engine"] == "reference" and row.get("contact_rtol") == TRUTH[0]


def _panel(ax, rows: list[dict[str, Any]], engines: list[str], metric: str) -> None:
    tags: list[tuple[str, float, float]] = []
    for k, engine in enumerate(engines):
        sel = [r for r in rows if r["engine"] == engine and r.get(metric) is not None]
        if not sel:
            continue
        x = [r["wall_time_s"] for r in sel]
        y = [max(r[metric], ERROR_FLOOR) for r in sel]
        (line,) = ax.loglog(x, y, marker=MARKERS[k % len(MARKERS)], label=engine, ms=6)
        hollow = [i for i, r in enumerate(sel) if not r.get("follows_reference", True)]
        if hollow:
            ax.plot(
                [x[i] for i in hollow],
                [y[i] for i in hollow],
                ls="none",
                marker=MARKERS[k % len(MARKERS)],
                ms=8,
                mfc="white",
                mec=line.get_color(),
            )
        tags += [(_tag(r), xi, yi) for r, xi, yi in zip(sel, x, y, strict=True) if _tag(r)]
    ys = [max(r[metric], ERROR_FLOOR) for r in rows if r.get(metric) is not None]
    if ys:
        ax.set_ylim(bottom=10 ** math.floor(math.log10(min(ys)) - 0.5))
    ax.set_xlabel("wall time per run [s] (median)")
    ax.set_ylabel(METRIC_LABELS[metric], fontsize=FONT - 1)
    ax.grid(True, which="both", alpha=0.3)
    _place_tags(ax, tags)


def _tag(row: dict[str, Any]) -> str:
    value = row["dt"] if row["dt"] is not None else row.get("contact_rtol")
    if value is None:
        return ""
    mantissa, _, exp = f"{value:.0e}".partition("e")
    return f"{mantissa}e{int(exp)}"


def _place_tags(ax, tags: list[tuple[str, float, float]]) -> None:
    """Label points, skipping a label whose box (TAG_BOX_PX) would overlap one already
    placed (positions in display pixels at the axes' final limits)."""
    ax.autoscale_view()
    placed: list[tuple[float, float]] = []
    for text, x, y in tags:
        px, py = ax.transData.transform((x, y))
        w, h = TAG_BOX_PX
        if any(abs(px - qx) < w and abs(py - qy) < h for qx, qy in placed):
            continue
        placed.append((px, py))
        ax.annotate(text, (x, y), fontsize=TAG_FONT, xytext=(4, 4), textcoords="offset points")


def _title(doc: dict[str, Any]) -> str:
    load = doc.get("load", {}).get("before", [None])[0]
    head = f"work-precision on scene '{doc['scene']}'"
    if load is None:
        return head
    return (
        f"{head}, t = 0 .. {doc['t_end']:.4g}: errors against the reference at its tightest "
        f"setting (hollow: does not follow it); load {load:.2f}"
    )
