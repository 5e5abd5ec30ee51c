"""The figure of `harness branches`: the energy above the resting level against time,
one curve per branch, the first undecidable state marked."""

from __future__ import annotations

import os


def plot_spread(spread, path: str | os.PathLike) -> str:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(8, 5))
    for b in [spread.paper, *spread.branches]:
        t, e = b.energy_curve
        keep = e > 0
        style = {"lw": 2.5, "color": "k", "zorder": 5} if b.name == "paper" else {"lw": 1.2}
        ax.semilogy(t[keep], e[keep], label=f"{b.name}: {b.status}", **style)
    if spread.undecidable is not None:
        ax.axvline(spread.undecidable["t"], color="grey", ls="--", lw=1, label="t_u")
    ax.set_xlabel("t")
    ax.set_ylabel("energy above the resting level")
    ax.set_title(f"{spread.scene}: branches at the first undecidable state")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return str(path)
