"""Plain-text tables for the analyses' terminal output (no dependency on the harness)."""

from __future__ import annotations


def table(rows: list[list[str]], header: list[str], align: str | None = None) -> str:
    """Columns separated by two spaces; `align` has one letter per column, "l" (left)
    or "r" (right, the default for every column)."""
    widths = [max(len(str(x)) for x in col) for col in zip(header, *rows, strict=False)]
    align = align or "r" * len(widths)
    fmt = "  ".join(
        f"{{:{'<' if a == 'l' else '>'}{w}}}" for a, w in zip(align, widths, strict=True)
    )
    out = [fmt.format(*header), fmt.format(*["-" * w for w in widths])]
    out += [fmt.format(*[str(x) for x in r]) for r in rows]
    return "\n".join(line.rstrip() for line in out)


# Legends of the analyses' tables (printed after them and in `harness analyze --help`).
SELFSIMILAR_LEGEND = """\
columns:
  beta             factor per impact: p scales by beta and q by beta^2 from one vertex to the
                   next (0 < beta < 1: the motion runs into the singularity)
  kind             trivial: tau0 = 0, q0 = 0, p0 an eigenvector of R^-1 U0 for eigenvalue beta;
                   blank: nontrivial, a root of N(beta) with tau0 > 0
  feasible         yes: every condition of the paper's section 3.2 holds; marginal: a trivial
                   solution on their border (tau0 = 0); no: see failed checks
  stable           the fixed point of the reduced map C-bar is asymptotically stable
  spectral radius  largest |eigenvalue| of C-bar's Jacobian there (< 1: stable; -: not computed)
  tau0             duration of the smooth phase between two impacts, with |p0| = 1
  failed checks    approaching (vertex 0 moves down), tau_positive, non_penetration (no contact
                   below the ground before tau0), beta_in_0_1, held_vertex_released (gamma = 0:
                   the held vertex n-1 is not pushed into the ground)"""

_CHATTER_OUTPUT = """\
output:
  eigenvalues of R^-1 U0  the map of the velocities p over one impact at vertex 0 and the
                          rotation to the next vertex, without gravity
  CC                      complete chatter: the dominant eigenvalue is real and positive
  PCC                     partial complete chatter: U0 U1 has only real eigenvalues
  rod (n = 2)             psi = (1 - rho^2)/(1 + rho^2) against the thresholds of complete
                          chatter without gravity and with gravity"""
_CHATTER_FACTORS = """\
  beta_p, beta_q          factors per impact: p_i = beta_p^i R^i p0, q_i = beta_q^i R^i q0
  c_lin                   energy exponent of E ~ (t_f - t)^c_lin:
                          2 log beta_p / log(beta_q/beta_p)"""
_CHATTER_TABLE = f"""\
table (gravity-free self-similar chatter, one row per pair of eigenvalues):
{_CHATTER_FACTORS}
  feasible                no contact below the ground, the next vertex reached approaching
  spectral radius         largest |eigenvalue| of the reduced map's Jacobian (< 1: stable)"""
# With the table of pairs, with the one line of beta_p, beta_q, c_lin (the rod), or with
# neither (no self-similar chatter); `harness analyze chatter --help` shows the first.
CHATTER_LEGEND = f"{_CHATTER_OUTPUT}\n{_CHATTER_TABLE}"
CHATTER_LEGEND_NO_TABLE = f"{_CHATTER_OUTPUT}\n{_CHATTER_FACTORS}"
CHATTER_LEGEND_OUTPUT_ONLY = _CHATTER_OUTPUT
