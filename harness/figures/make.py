"""The catalogue of the paper's figures and the run that makes them all
(`harness figures`): which figure is which function, the verdict on each claim, the
summary printed."""

from __future__ import annotations

from pathlib import Path

from .decay import fig_energy_precession, fig_rod_clin, fig_triangle_c_vs_clin
from .selfsimilar import fig_beta_vs_gamma, fig_beta_vs_rho, fig_boundaries, fig_feasibility_border

FIGURES = {
    "beta_vs_rho": fig_beta_vs_rho,
    "feasibility_border": fig_feasibility_border,
    "beta_vs_gamma": fig_beta_vs_gamma,
    "boundaries": fig_boundaries,
    "energy_precession": fig_energy_precession,
    "rod_clin": fig_rod_clin,
    "triangle_c_vs_clin": fig_triangle_c_vs_clin,
}


def verdict(doc: dict) -> str:
    """'reproduced', 'partly' (agrees, with a stated exception) or 'NOT reproduced'."""
    if not doc["agree"]:
        return "partly" if doc.get("note") else "NOT reproduced"
    return "reproduced"


def format_figures(doc: dict, out_dir: Path) -> str:
    """A short human summary: each of the paper's claims, reproduced or not, with the
    number that decides it (the JSON document has every detail)."""
    import textwrap

    lines = [f"The paper's claims, recomputed ({len(doc)} figures as PNG in {out_dir}):", ""]
    for name, d in doc.items():
        head = f"{verdict(d):>14}  {name}: {d.get('headline') or d['ours']}"
        lines += textwrap.wrap(head, 100, subsequent_indent=" " * 16)
        if d.get("note"):
            lines += textwrap.wrap(
                d["note"], 100, initial_indent=" " * 16, subsequent_indent=" " * 16
            )
    lines += ["", "--json: the paper's statement, our numbers and the data behind each figure."]
    return "\n".join(lines)


def figure_paths(out_dir: Path, names=None) -> list[Path]:
    """The files `make_figures` writes into out_dir (each figure is saved as <name>.png);
    `names`: those figures only (None: all)."""
    return [Path(out_dir) / f"{name}.png" for name in names or FIGURES]


def make_figures(out_dir: Path, progress=print, names=None) -> dict:
    """Compute and save every figure (`names`: those only, in FIGURES's order); returns
    name → {path, paper, ours, agree}."""
    from ..progress import progress_bar

    out_dir = Path(out_dir)  # created with the first figure (harness.outputs)
    chosen = {name: fn for name, fn in FIGURES.items() if names is None or name in names}
    doc = {}
    with progress_bar(len(chosen), "figures", unit="figure") as bar:
        for name, fn in chosen.items():
            progress(f"figure {name}")
            bar.set_postfix_str(name, refresh=False)
            doc[name] = fn(out_dir, progress)
            bar.update()
    return doc
