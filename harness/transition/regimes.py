"""Regimes of a run on the bumpy ground, from which contact kinds act.

A contact *acts* when it takes an impulse (an impact) or is held (a contact phase of
the reference).  With t_bump the first time a bump acts and t_rim the last time a rim
vertex acts, the run splits into

- `rim_only`   [start, t_bump): the polygon rolls on its rim, the paper's section 3;
- `mixed`      [t_bump, t_rim]: both kinds act, the transition;
- `bumps_only` (t_rim, end]: the disk bounces or rests on the bumps alone, the paper's
  section 4 (three-point ground).

A regime that does not occur is left out (no bump ever acts: only `rim_only`).  The end
is the singularity when the run reached it, else its last time.

Per regime: duration, time to the singularity at its start, impacts of each kind, tilt
and energy at its ends, and the local exponent c of E ≈ a (t_f − t)^c over its impacts
(the regression of reference.exponent, `fit_energy_exponent`, with E_i the energy
above the three-point rest just before impact i: reference.bumpy.bumpy_excess_energy),
given only where its impacts' energies span REGIME_MIN_DECADES decades or more (a
regression over an energy that barely changes measures no power law; `c_reason` says
why c is None).  A run that ends short of its singularity keeps an energy E_end at t_f
(its last impact): the law then describes E − E_end, so only impacts with E above
PLATEAU_FACTOR · E_end enter the fit (the plateau at E_end is not a power of t_f − t).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from reference.bumpy import BUMP, RIM, bumpy_excess_energy, contact_kind_names
from reference.exponent import (
    MIN_POINTS,
    fit_energy_exponent,
    pre_impact_samples,
    states_of,
    time_to_go,
)
from reference.scene import Scene
from reference.trajectory import Status, Trajectory

RIM_ONLY, MIXED, BUMPS_ONLY = "rim_only", "mixed", "bumps_only"
REGIMES = (RIM_ONLY, MIXED, BUMPS_ONLY)


@dataclass(frozen=True)
class Activity:
    """When each kind of contact acts: sorted times of rim and bump activity (impact
    times, and the start and end of every contact phase holding such a contact)."""

    rim: np.ndarray
    bump: np.ndarray

    @property
    def first_bump(self) -> float | None:
        return float(self.bump[0]) if len(self.bump) else None

    @property
    def last_rim(self) -> float | None:
        return float(self.rim[-1]) if len(self.rim) else None


def activity(traj: Trajectory, kinds: tuple[str, ...]) -> Activity:
    """Times at which rim vertices and bumps act in a run (module docstring)."""
    times: dict[str, list[float]] = {RIM: [], BUMP: []}
    for t, k in zip(traj.impact_column("t"), traj.impact_column("contact"), strict=True):
        times[kinds[int(k)]].append(float(t))
    for phase in traj.phases or ():
        if phase.kind != "contact":
            continue
        for k in phase.contacts:
            times[kinds[int(k)]] += [float(phase.t_start), float(phase.t_end)]
    return Activity(rim=np.sort(times[RIM]), bump=np.sort(times[BUMP]))


def end_time(traj: Trajectory) -> tuple[float, str]:
    """The run's end t_f for the study: its singularity when reached; else its last impact
    (an engine's run has no singularity: its impacts stop when the body comes to rest, and
    the last one is the nearest it has to t_f, as reference.exponent's `last_impact`); else
    its last time."""
    if traj.status == Status.SINGULARITY and traj.t_singularity is not None:
        return float(traj.t_singularity), "t_singularity"
    if len(traj.impacts):
        return float(traj.impact_column("t")[-1]), "last_impact"
    last = float(traj.t_final) if traj.t_final else float(traj.t[-1]) if traj.n_samples else 0.0
    return last, "last_time"


def regime_spans(act: Activity, t_start: float, t_stop: float) -> list[tuple[str, float, float]]:
    """(name, start, end) of the regimes that occur, in time order."""
    t_bump = act.first_bump
    if t_bump is None:
        return [(RIM_ONLY, t_start, t_stop)]
    t_rim = act.last_rim
    spans = []
    if t_bump > t_start:
        spans.append((RIM_ONLY, t_start, t_bump))
    if t_rim is not None and t_rim >= t_bump:
        spans.append((MIXED, t_bump, t_rim))
        if t_stop > t_rim:
            spans.append((BUMPS_ONLY, t_rim, t_stop))
    else:
        spans.append((BUMPS_ONLY, t_bump, t_stop))
    return spans


def tilt(states: np.ndarray) -> np.ndarray:
    """(N,) tilt α of the body's axis from the vertical, 2 asin √(q_x² + q_y²) (keeps the
    digits of tilts far below √ε)."""
    q = np.asarray(states, dtype=float).reshape(-1, 13)[:, 3:7]
    s = np.sqrt(q[:, 1] ** 2 + q[:, 2] ** 2)
    return 2.0 * np.arcsin(np.clip(s, 0.0, 1.0))


@dataclass(frozen=True)
class RunSeries:
    """What the regimes are measured on: sample times, tilts and energies, and per impact
    its time, kind, time to go and the energy just before it."""

    t: np.ndarray
    tilt: np.ndarray
    energy: np.ndarray
    impact_t: np.ndarray
    impact_kind: np.ndarray
    impact_ttg: np.ndarray
    impact_energy: np.ndarray
    t_f: float
    t_f_source: str

    @property
    def e_end(self) -> float:
        """The energy the run keeps at t_f: 0 at its singularity, else its last sample's."""
        if self.t_f_source == "t_singularity" or not len(self.energy):
            return 0.0
        return max(float(self.energy[-1]), 0.0)

    def at(self, values: np.ndarray, t: float) -> float | None:
        """A sample series interpolated at time t (None without samples)."""
        if not len(self.t):
            return None
        return float(np.interp(t, self.t, values))


def run_series(traj: Trajectory, scene: Scene) -> RunSeries:
    kinds = np.array(contact_kind_names(scene))
    S = states_of(traj)
    energy = bumpy_excess_energy(scene, S) if len(S) else np.zeros(0)
    t_f, source = end_time(traj)
    t_i = traj.impact_column("t")
    lo_i = traj.impact_column("t_lo")
    if len(t_i):
        dt = np.diff(t_i, prepend=0.0) + np.diff(lo_i, prepend=0.0)
        ttg = time_to_go(dt, remainder=(t_f - t_i[-1]) - lo_i[-1])
        before = pre_impact_samples(traj)
        e_i = np.where(before >= 0, energy[np.maximum(before, 0)], np.nan)
    else:
        ttg, e_i = np.zeros(0), np.zeros(0)
    return RunSeries(
        t=np.asarray(traj.t, dtype=float),
        tilt=tilt(S),
        energy=energy,
        impact_t=np.asarray(t_i, dtype=float),
        impact_kind=kinds[traj.impact_column("contact").astype(int)] if len(t_i) else kinds[:0],
        impact_ttg=ttg,
        impact_energy=e_i,
        t_f=t_f,
        t_f_source=source,
    )


# a regime's c needs its impacts' energies to span this many decades (and MIN_POINTS
# impacts, the estimator's own minimum)
REGIME_MIN_DECADES = 1.0
# impacts within this factor of the energy a run keeps at its end are on its plateau
PLATEAU_FACTOR = 10.0


def regime_exponent(ttg: np.ndarray, energy: np.ndarray, e_end: float) -> dict[str, Any]:
    """`fit_energy_exponent` over a regime's impacts above PLATEAU_FACTOR · e_end (the
    energy the run keeps at t_f; 0 at a singularity), with c None (and `reason`) unless
    they span REGIME_MIN_DECADES with MIN_POINTS points."""
    above = energy > PLATEAU_FACTOR * e_end
    fit = fit_energy_exponent(ttg[above], energy[above])
    if fit["n_points"] < MIN_POINTS:
        reason = f"{fit['n_points']} impacts (needs {MIN_POINTS})"
    elif not fit["log10_energy_span"] >= REGIME_MIN_DECADES:
        reason = (f"energy spans {fit['log10_energy_span']:.2g} decades "
                  f"(needs {REGIME_MIN_DECADES:g})")  # fmt: skip
    else:
        return {**fit, "reason": ""}
    return {**fit, "c": None, "c_stderr": None, "reason": reason}


# Which ends of its span a regime's impacts may lie on: the first bump impact opens the
# mixed regime, the last rim impact closes it.
CLOSED_ENDS = {RIM_ONLY: (True, False), MIXED: (True, True), BUMPS_ONLY: (False, True)}


def regime_summary(series: RunSeries, name: str, t0: float, t1: float) -> dict[str, Any]:
    """One regime's figures (module docstring)."""
    t = series.impact_t
    with_start, with_end = CLOSED_ENDS[name]
    sel = ((t >= t0) if with_start else (t > t0)) & ((t <= t1) if with_end else (t < t1))
    fit = regime_exponent(series.impact_ttg[sel], series.impact_energy[sel], series.e_end)
    kinds = series.impact_kind[sel]
    return {
        "regime": name,
        "t_start": t0,
        "t_end": t1,
        "duration": t1 - t0,
        "time_to_singularity_at_start": series.t_f - t0,
        "impacts": {RIM: int(np.sum(kinds == RIM)), BUMP: int(np.sum(kinds == BUMP))},
        "tilt_start": series.at(series.tilt, t0),
        "tilt_end": series.at(series.tilt, t1),
        "energy_start": series.at(series.energy, t0),
        "energy_end": series.at(series.energy, t1),
        "c": fit["c"],
        "c_stderr": fit["c_stderr"],
        "c_points": fit["n_points"],
        "c_log10_energy_span": fit["log10_energy_span"],
        "c_reason": fit["reason"],
    }


def classify(traj: Trajectory, scene: Scene) -> tuple[RunSeries, Activity, list[dict[str, Any]]]:
    """The run's series, its contact activity and its regimes' summaries."""
    series = run_series(traj, scene)
    act = activity(traj, contact_kind_names(scene))
    t_start = float(traj.t[0]) if traj.n_samples else 0.0
    spans = regime_spans(act, t_start, series.t_f)
    out = [regime_summary(series, name, t0, t1) for name, t0, t1 in spans]
    return series, act, out


def takeover(series: RunSeries, act: Activity, scene: Scene) -> dict[str, Any]:
    """When and at which tilt the bumps first act and the rim last acts, against Δ/a,
    the paper's Δ/d and the tilt at which the face first reaches a bump of height Δ at
    radius b when the low side of the rim passes it, Δ/(a − b) (the centre over the axis;
    the face lies a sin α − ρ sin α above the floor at distance ρ from the centre towards
    the lowest point)."""
    a = scene.body.radius
    bumps = np.asarray(scene.contacts.floor_points)
    delta = float(bumps[:, 2].max()) if len(bumps) else 0.0
    reach = max((h / (a - math.hypot(x, y)) for x, y, h in bumps.tolist()), default=math.inf)
    first, last = act.first_bump, act.last_rim
    first_tilt = series.at(series.tilt, first) if first is not None else None
    last_tilt = series.at(series.tilt, last) if last is not None else None

    def ratio(x):
        return None if x is None or delta == 0 else x / (delta / a)

    return {
        "delta": delta,
        "delta_over_a": delta / a,
        "delta_over_d": 0.5 * delta / a,
        "face_reach_tilt": reach,
        "first_bump_t": first,
        "first_bump_tilt": first_tilt,
        "first_bump_tilt_over_delta_a": ratio(first_tilt),
        "last_rim_t": last,
        "last_rim_tilt": last_tilt,
        "last_rim_tilt_over_delta_a": ratio(last_tilt),
        "time_from_first_bump_to_end": None if first is None else series.t_f - first,
    }
