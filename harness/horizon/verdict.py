"""The horizon verdict of one engine run (`compare`'s `horizon` object; docs/output.md,
docs/fidelity.md "Horizon").

Level (a), fixed-step engines only: the matched counts of the grid model at the run's
dt (grid.py), an ensemble of `runs` random grid phases; `matched_quantiles` are their
10 %, 50 % and 90 % quantiles, and the run is `within` when its own matched count is at
least the 10 % quantile: a fixed-step engine at that dt cannot be asked for more.

Level (b), every simulator but the reference: the run's own error, measured on this run
as the separation (state.separation) of its state from the reference's in the flight
after its first matched impact (`own_error`), then the reference perturbed at that
level from just after that impact (ensemble.perturbed_ensemble): `own_error_quantiles`
are the matched counts this error alone allows; `own_error_predicted` the count the
growth of the scene's ensemble at LYAPUNOV_LEVEL predicts for that level
(lyapunov.profile_horizon: each member's impact-time offsets scaled to it, against the
windows; it treats the error as if made at the start).  A
run matching far less than (b) diverges for another reason than its error at the first
impact; a run whose (b) is far below (a) makes a larger error than its timestep forces.

`lyapunov_per_impact` is the scene's λ (lyapunov.py), the same for every run.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from reference import Trajectory
from reference.scene import Scene

from ..metrics import ImpactMatch, energy_guard
from .ensemble import (
    Member,
    grid_ensemble,
    matched_counts,
    perturbed_ensemble,
    rematched,
)
from .grid import GRID_MODEL
from .lyapunov import LYAPUNOV_LEVEL, lyapunov_per_impact, profile_horizon
from .settings import DEFAULT_RUNS, DEFAULT_SEED
from .state import flown, post_impact_states, separation

QUANTILES = (10.0, 50.0, 90.0)
DIRECTIONS = (
    "uniform on the unit sphere of the 12 dimensionless state components (position/a, "
    "attitude rad, velocity/U, angular velocity a/U; U = max(sqrt(g a), a/t_end))"
)


def quantiles(counts: np.ndarray) -> list[float] | None:
    """10 %, 50 %, 90 % quantiles of matched counts (numpy's linear interpolation)."""
    if len(counts) == 0:
        return None
    return [float(q) for q in np.percentile(counts, QUANTILES)]


@dataclass(frozen=True)
class SceneHorizon:
    """What every run of a comparison shares: the perturbed ensemble at LYAPUNOV_LEVEL
    from the initial state and its growth rate λ per impact."""

    members: list[Member]
    lyapunov: float | None
    runs: int
    seed: int


def scene_horizon(
    scene: Scene,
    reference: Trajectory,
    runs: int = DEFAULT_RUNS,
    seed: int = DEFAULT_SEED,
    progress: Callable[[], None] | None = None,
) -> SceneHorizon:
    """The shared part (SceneHorizon): `runs` members from the initial state perturbed
    at LYAPUNOV_LEVEL (event-driven windows; `rematched` judges them at a run's dt)."""
    members = perturbed_ensemble(scene, reference, LYAPUNOV_LEVEL, runs, seed, None, None, progress)
    return SceneHorizon(members, lyapunov_per_impact(scene, reference, members), runs, seed)


@dataclass(frozen=True)
class Horizon:
    """The `horizon` object of one run (module docstring)."""

    matched: int
    matched_quantiles: list[float] | None
    own_error: float | None
    own_error_impact: int | None
    own_error_quantiles: list[float] | None
    own_error_predicted: float | None
    lyapunov_per_impact: float | None
    runs: int
    seed: int
    dt: float | None

    @property
    def within(self) -> bool | None:
        """Matched count ≥ the 10 % quantile of level (a); None without level (a)."""
        if self.matched_quantiles is None:
            return None
        return self.matched >= self.matched_quantiles[0]

    def to_dict(self) -> dict[str, Any]:
        return {
            "matched_quantiles": self.matched_quantiles,
            "within": self.within,
            "own_error": self.own_error,
            "own_error_quantiles": self.own_error_quantiles,
            "lyapunov_per_impact": self.lyapunov_per_impact,
            "own_error_predicted": self.own_error_predicted,
            "own_error_impact": self.own_error_impact,
            "runs": self.runs,
            "seed": self.seed,
            "lyapunov_level": LYAPUNOV_LEVEL,
            "grid_model": GRID_MODEL if self.dt is not None else None,
            "directions": DIRECTIONS,
        }


def own_error(
    scene: Scene, reference: Trajectory, run: Trajectory, match: ImpactMatch
) -> tuple[float | None, int | None]:
    """The run's separation from the reference in the flight after its first matched
    impact that allows the measurement, and that reference impact's index.  Both states
    are compared the same time s after their own impacts (the impact section: a shift in
    time is not an error), s about halfway to the earlier of the two next impacts: the
    run's sample nearest there, at least ENERGY_GUARD_STEPS steps after its impact (an
    engine's impact is over by then, a soft contact's too), the reference's post-impact
    state carried s by its closed-form flight."""
    if run.n_samples == 0:
        return None, None
    guard = energy_guard(run)
    t_ref, t_run = reference.impact_times(), run.impact_times()
    post = post_impact_states(reference)
    rows = np.concatenate([run.position, run.quaternion, run.velocity, run.angular_velocity], 1)
    for i, j in match.pairs:
        next_ref = t_ref[i + 1] - t_ref[i] if i + 1 < len(t_ref) else math.inf
        next_run = t_run[j + 1] - t_run[j] if j + 1 < len(t_run) else math.inf
        flight = min(next_ref, next_run, float(run.t[-1] - t_run[j]))
        k = int(np.argmin(np.abs(run.t - (t_run[j] + 0.5 * flight))))
        s = float(run.t[k] - t_run[j])
        if guard <= s and s < next_ref and s < next_run and s > 0:
            y_ref = flown(scene, post[i], s)
            return float(separation(scene, rows[k], y_ref)), int(i)
    return None, None


def engine_horizon(
    scene: Scene,
    reference: Trajectory,
    run: Trajectory,
    match: ImpactMatch,
    shared: SceneHorizon,
    progress: Callable[[], None] | None = None,
) -> Horizon:
    """Levels (a) and (b) of one run (module docstring)."""
    g, dt = scene.gravity, run.dt
    band = None
    if dt is not None:
        grid = grid_ensemble(scene, reference, dt, shared.runs, shared.seed, progress)
        band = quantiles(matched_counts(grid))
    err, at = own_error(scene, reference, run, match)
    own_q = predicted = None
    if err is not None and err > 0:
        own = perturbed_ensemble(scene, reference, err, shared.runs, shared.seed, at, dt, progress)
        own_q = quantiles(matched_counts(own))
        base = rematched(shared.members, reference, g, dt)
        predicted = profile_horizon(reference, base, g, LYAPUNOV_LEVEL, err)
    return Horizon(
        match.n_matched, band, err, at, own_q, predicted, shared.lyapunov, shared.runs,
        shared.seed, dt,
    )  # fmt: skip


def planned_members(runs: int, fixed_step: list[bool]) -> int:
    """Members the horizons of these runs take (for a progress bar)."""
    return runs * (1 + sum(2 if f else 1 for f in fixed_step))
