"""The paper's log-log plot: energy against time to the singularity, and its exponent.

Near the singularity E ≈ a (t_f − t)^c (paper, section on energy exponents; c = 2 for
self-similar motion).  The exponent is the slope of a plain least-squares line of
log E on log(t_f − t) over the samples with t < t_f and E > 0.

Time to go keeps the low part of double-double times (Trajectory.t_lo, ImpactEvent.t_lo):
t_f − t = (t_f,hi − t_hi) + (t_f,lo − t_lo); the first difference is exact when the two
times are close (Sterbenz), so digits survive down to t_f − t ≈ 1e-16 t_f and below.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from reference.trajectory import Trajectory


@dataclass(frozen=True)
class SingularityTime:
    """t_f = hi + lo, and where it came from (for the recording's legend)."""

    hi: float
    lo: float
    source: str


@dataclass(frozen=True)
class ExponentFit:
    """log E ≈ c log(t_f − t) + log a, over `n_samples` samples; `method` names the fit used."""

    c: float
    log_a: float
    n_samples: int
    method: str


def singularity_time(reference: Trajectory) -> SingularityTime | None:
    """The reference's t_singularity when it has one, else its last impact time, else None."""
    if reference.t_singularity is not None and np.isfinite(reference.t_singularity):
        return SingularityTime(float(reference.t_singularity), 0.0, "t_singularity of reference")
    if reference.impacts:
        last = max(reference.impacts, key=lambda e: (e.t, e.t_lo))
        return SingularityTime(float(last.t), float(last.t_lo), "last impact of reference")
    return None


def time_to_go(traj: Trajectory, t_f: SingularityTime) -> np.ndarray:
    """t_f − t per sample: (t_f,hi − t) + (t_f,lo − t_lo), t_lo = 0 where not kept."""
    t_lo = np.zeros(traj.n_samples) if traj.t_lo is None else np.asarray(traj.t_lo, dtype=float)
    return (t_f.hi - np.asarray(traj.t, dtype=float)) + (t_f.lo - t_lo)


def loglog_mask(time_to_go: np.ndarray, energy: np.ndarray) -> np.ndarray:
    """Samples that have a logarithm on both axes: t < t_f and E > 0, both finite."""
    with np.errstate(invalid="ignore"):
        return np.isfinite(time_to_go) & np.isfinite(energy) & (time_to_go > 0) & (energy > 0)


def fit_exponent(time_to_go: np.ndarray, energy: np.ndarray) -> ExponentFit | None:
    """Least-squares slope c of log E on log(t_f − t) over the loggable samples.

    Uses reference.linear.exponent.fit_energy_exponent when that module exists (its `c`),
    otherwise numpy's degree-1 polyfit.  The intercept log a is the least-squares one for
    that slope: mean(log E − c log(t_f − t)).  None with fewer than two distinct times."""
    keep = loglog_mask(time_to_go, energy)
    tau, E = np.asarray(time_to_go)[keep], np.asarray(energy)[keep]
    if len(np.unique(tau)) < 2:
        return None
    x, y = np.log(tau), np.log(E)
    try:
        from reference.linear.exponent import fit_energy_exponent
    except ImportError:
        c = float(np.polyfit(x, y, 1)[0])
        method = "numpy.polyfit of log E on log(t_f - t)"
    else:
        c = float(fit_energy_exponent(tau, E)["c"])
        method = "reference.linear.exponent.fit_energy_exponent"
    return ExponentFit(c=c, log_a=float(np.mean(y - c * x)), n_samples=int(len(x)), method=method)
