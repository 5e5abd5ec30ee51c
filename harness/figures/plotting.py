"""What the paper's figures share: axis labels, the headless pyplot, the atomic save, the
self-similar solutions and their β scatter (harness.figures)."""

from __future__ import annotations

from pathlib import Path

from reference.linear.model import LinearModel
from reference.linear.selfsimilar import selfsimilar_solutions

from ..outputs import atomic_write

# Axis labels.  The models are dimensionless with a = m = g = 1: lengths in a, times in
# √(a/g), energies in m g a; ratios carry [–].
RHO = "ρ = radius of gyration / a  [–]"
GAMMA = "γ, coefficient of restitution  [–]"
BETA = "β, ratio of successive impact intervals  [–]"
TIME_TO_GO = "t_f − t  [√(a/g)]"
ENERGY = "E before each impact  [m g a]"


def pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def save(fig, path: Path, dpi: int = 120) -> Path:
    """Write the figure (tight layout) to path, atomically, and free it.  Whether an
    existing file may be replaced is decided before the figures are computed
    (`figure_paths`, checked by the CLI with --force)."""
    fig.tight_layout()
    try:
        with atomic_write(path, force=True) as tmp:
            fig.savefig(tmp, dpi=dpi)
    finally:
        pyplot().close(fig)
    return path


def solutions(n: int, rho: float, gamma: float, stability: bool = True):
    """The self-similar motions of the n-gon (reference.linear.selfsimilar); `stability`:
    with the eigenvalues of each one's reduced map (the figures that read only existence
    and feasibility go without)."""
    return selfsimilar_solutions(LinearModel.polygon(n, rho, gamma), with_stability=stability)


# The β scatter's marker of each kind of solution: format and style (scatter_betas).
MARKERS = {
    "trivial": ("*", {"color": "tab:orange", "ms": 5}),
    "feasible": ("o", {"color": "tab:blue", "ms": 3}),
    "infeasible": ("o", {"mfc": "none", "color": "tab:gray", "ms": 3}),
}


def _kind(s) -> str:
    return "trivial" if s.trivial else "feasible" if s.feasible else "infeasible"


def scatter_betas(ax, xs, sols_list, xlabel):
    """Each solution's β over its x, one line of markers per kind (MARKERS)."""
    points = {kind: ([], []) for kind in MARKERS}
    for x, sols in zip(xs, sols_list, strict=True):
        for s in sols:
            px, py = points[_kind(s)]
            px.append(x)
            py.append(s.beta)
    for kind, (fmt, style) in MARKERS.items():
        if points[kind][0]:
            ax.plot(*points[kind], fmt, **style)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(BETA)
    ax.set_ylim(0, 1.02)


def legend(ax):
    ax.plot([], [], "*", color="tab:orange", label="trivial")
    ax.plot([], [], "o", color="tab:blue", label="feasible")
    ax.plot([], [], "o", mfc="none", color="tab:gray", label="infeasible")
    ax.legend(loc="lower right", fontsize=8)
