"""Figures of a fidelity study, drawn from its JSON document alone (so `harness report`
can redraw them): α* against dt with the fitted power laws, and the fraction of leading
impacts matched against α for every engine and dt."""

from __future__ import annotations

from typing import Any

import numpy as np

MARKERS = "osDPXph*d8"  # no up/down triangles: they mark the grid edges


def _plt():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def alpha_star_figure(doc: dict[str, Any]):
    """log-log α* against dt, one colour per engine: a filled marker at α* where the grid
    brackets it, with a bar down to the first failing α (the threshold lies on the bar)
    and a dotted line on down to the smallest α passed at all (a dash: the transition
    band, where passing depends on the exact α);
    an open downward triangle at the smallest α where the engine passes at every scale
    (α* at most that), an open upward one at the largest α where it fails at every scale
    (α* above it); the fitted α* = A dt^k dashed, k ± its standard error in the legend.
    Engines are drawn slightly apart in dt (DODGE decades) so that equal values stay
    visible."""
    plt = _plt()
    fig, ax = plt.subplots(figsize=(7.5, 5.5), layout="constrained")
    fits = {f["engine"]: f for f in doc["fits"]}
    n = len(doc["engines"])
    for i, engine in enumerate(doc["engines"]):
        stars = [s for s in doc["alpha_star"] if s["engine"] == engine and s["dt"] is not None]
        style = {
            "color": f"C{i % 10}",
            "marker": MARKERS[i % len(MARKERS)],
            "shift": 10 ** (DODGE * (i - (n - 1) / 2)),
        }
        _draw_engine(ax, stars, fits.get(engine), engine, style)
    refs = doc["reference"]
    for a in (refs[0]["alpha"], refs[-1]["alpha"]):
        ax.axhline(a, color="0.6", lw=0.8, ls=":")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("timestep dt [s] (a = m = g = 1; engines drawn slightly apart)")
    ax.set_ylabel("α* [rad]: smallest inclination the engine follows")
    crit = doc["criteria"]
    ax.set_title(
        f"fidelity limit on '{doc['scene']}': ≥ {crit['match_fraction']:.0%} of "
        f"{crit['leading']} leading impacts matched\n(bar: down to the first failing α; "
        "dotted to a dash: passes again down to there;\n▽ passes at every α, △ fails at "
        "every α; horizontal dotted lines: the α range tried)",
        fontsize=9,
    )
    ax.grid(True, which="major", alpha=0.3)
    ax.legend(fontsize=7, loc="best")
    return fig


DODGE = 0.025  # decades of dt between neighbouring engines' markers


def _draw_engine(ax, stars, fit, engine, style) -> None:
    color, marker, shift = style["color"], style["marker"], style["shift"]
    exact = [s for s in stars if s["bound"] == "bracket"]
    label = engine
    if fit is not None and fit["k"] is not None:
        err = f" ± {fit['k_stderr']:.2f}" if fit["k_stderr"] is not None else ""
        label += f": k = {fit['k']:.2f}{err}"
        d = np.array(sorted(fit["dts_used"]))
        y = 10 ** (fit["log10_A"] + fit["k"] * np.log10(d))
        ax.plot(d * shift, y, "--", color=color, lw=1)
    if not exact:
        label += " (no bracketed α*)"
    ax.plot([], [], marker=marker, ls="none", color=color, label=label)
    for s in exact:
        x = s["dt"] * shift
        ax.plot([x, x], [s["alpha_first_fail"], s["alpha_star"]], color=color, lw=1.5)
        ax.plot(x, s["alpha_star"], marker=marker, color=color)
    for s in stars:  # the transition band: passes again down to the smallest α passed
        low = s["alpha_lowest_pass"]
        top = s["alpha_first_fail"] if s["bound"] == "bracket" else None
        if low is not None and top is not None and low < top:
            x = s["dt"] * shift
            ax.plot([x, x], [low, top], color=color, lw=0.8, ls=":")
            ax.plot(x, low, marker="_", color=color, ms=10)
    for s in stars:
        if s["bound"] == "at most":
            ax.plot(s["dt"] * shift, s["alpha_star"], "v", color=color, mfc="none", ms=9)
        elif s["bound"] == "above grid":
            ax.plot(s["dt"] * shift, s["alpha_first_fail"], "^", color=color, mfc="none", ms=9)


def matched_figure(doc: dict[str, Any]):
    """Fraction of the leading impacts matched against α, one panel per dt, one line
    per engine, the pass threshold dashed; skipped runs are gaps."""
    plt = _plt()
    dts = sorted({r["dt"] for r in doc["runs"]}, key=lambda d: -(d if d is not None else 1e300))
    n = max(len(dts), 1)
    fig, axes = plt.subplots(
        1, n, figsize=(4.2 * n, 4.2), layout="constrained", sharey=True, squeeze=False
    )
    threshold = doc["criteria"]["match_fraction"]
    for ax, dt in zip(axes[0], dts, strict=False):
        for i, engine in enumerate(doc["engines"]):
            rows = sorted(
                (r for r in doc["runs"] if r["engine"] == engine and r["dt"] == dt),
                key=lambda r: r["alpha"],
            )
            if not rows:
                continue
            x = [r["alpha"] for r in rows]
            y = [
                r["match_fraction"] if r.get("match_fraction") is not None else np.nan for r in rows
            ]
            ax.plot(x, y, marker=MARKERS[i % len(MARKERS)], ms=4, color=f"C{i % 10}", label=engine)
        ax.axhline(threshold, color="k", ls="--", lw=0.8)
        ax.set_xscale("log")
        ax.set_ylim(-0.05, 1.05)
        ax.set_xlabel("inclination α [rad]")
        ax.set_title("event-driven" if dt is None else f"dt = {dt:g} s", fontsize=9)
        ax.grid(True, which="both", alpha=0.3)
    axes[0][0].set_ylabel(f"fraction of {doc['criteria']['leading']} leading impacts matched")
    handles, labels = axes[0][0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="outside lower center", ncol=min(len(labels), 6), fontsize=7)
    fig.suptitle(
        f"leading impacts matched on '{doc['scene']}' (dashed: pass threshold)", fontsize=9
    )
    return fig


def save_figure(fig, path, dpi: int = 120) -> str:
    """Write a figure as PNG (to a path or a binary file object) and close it."""
    plt = _plt()
    fig.savefig(path, dpi=dpi, format="png")
    plt.close(fig)
    return str(path)
