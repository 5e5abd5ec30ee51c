"""One sweep task: run a simulator from a task's initial state and estimate the exponent c
of E ≈ a (t_f − t)^c (paper eq. scalinglaw, section 4.3).

- `linear`: reference.linear.simulate.run_linear_exponent, which runs the linearised
  model to the singularity and fits c with its own estimator.
- every other simulator: a Scene (the n-gon, a = m = 1, on flat ground, from (q0, p0) via
  reference.scene.initial_from_linear), harness.simulators.run_simulator, and
  `trajectory_exponent`: the regression of log E before each impact on log(t_f − t).

`run_chunk` is what workers execute: plain data in, a list of row dicts out.  A run
that raises becomes a row with status `failed` and the error text; it never takes the
chunk down.
"""

from __future__ import annotations

import math
import time
import traceback

import numpy as np

from .grid import Chunk, SweepConfig, initial_state

LOG10 = math.log(10.0)


def _error_text(exc: BaseException, limit: int = 2000) -> str:
    tb = traceback.format_exception(type(exc), exc, exc.__traceback__, limit=-3)
    text = "".join(tb).strip()
    return text[-limit:]


def pre_impact_samples(traj) -> np.ndarray:
    """Index of the last sample strictly before each impact (−1 if none), comparing
    times as (t, t_lo) pairs so that impacts closer together than an ulp of t stay
    ordered.  Energy is constant in flight, so for exact simulators the energy of that
    sample is the energy just before the impact."""
    n_s = traj.n_samples
    t_s = np.asarray(traj.t, dtype=float)
    lo_s = np.zeros(n_s) if traj.t_lo is None else np.asarray(traj.t_lo, dtype=float)
    t_i = np.array([e.t for e in traj.impacts])
    lo_i = np.array([e.t_lo for e in traj.impacts])
    hi = np.concatenate([t_s, t_i])
    lo = np.concatenate([lo_s, lo_i])
    is_sample = np.concatenate([np.ones(n_s, dtype=bool), np.zeros(len(t_i), dtype=bool)])
    # order by time; at an exact tie the impact comes first (the sample is not before it)
    order = np.lexsort((is_sample, lo, hi))
    samples_before = np.cumsum(is_sample[order]) - is_sample[order]
    rank = np.empty(len(order), dtype=np.int64)
    rank[order] = np.arange(len(order))
    return samples_before[rank[n_s:]] - 1


def excess_energy_at(traj, scene):
    """energy_at(indices) for `trajectory_exponent`: the energy above the floor that the
    invariants allow (reference.geometry.excess_energy; on flat ground
    E − ½ m |v_h|² − L_z²/(2 I3)).  The motion ends with that floor, not zero: the
    horizontal momentum and L_z are conserved, and L_z ≠ 0 for a tilted spinning body,
    so fitting the total energy would flatten the tail of the power law."""
    from reference.geometry import excess_energy

    def energy_at(idx: np.ndarray) -> np.ndarray:
        idx = np.asarray(idx, dtype=int)
        states = np.concatenate(
            [
                traj.position[idx],
                traj.quaternion[idx],
                traj.velocity[idx],
                traj.angular_velocity[idx],
            ],
            axis=1,
        )
        return excess_energy(scene, states)

    return energy_at


def trajectory_exponent(
    traj,
    skip_start: float = 3.0,
    skip_end: float = 2.0,
    min_decades: float = 6.0,
    resolution: float | None = None,
    energy_at=None,
) -> dict:
    """c from a Trajectory: the regression of log E_i on log(t_f − t_i) over the impacts
    (reference.linear.exponent.fit_energy_exponent), E_i the energy just before impact
    i (of the sample `pre_impact_samples` finds; `energy_at(indices)` gives the energy
    of samples, default traj.energy).

    Time-to-go is summed from the intervals between impacts, smallest first
    (reference.linear.exponent.time_to_go), each interval from the (t, t_lo) parts, so
    it keeps its relative precision however close to t_f.  Only the leading impacts
    whose intervals are resolved are used (every interval ≥ `resolution` × t; default
    1e-28 with t_lo, 1e-13 without): the rest are below the simulator's time
    resolution.  The remainder from the last used impact K to t_f is
    traj.t_singularity − t_K when that difference is resolved (≥ 1e-12 t_f); else,
    when the run has a singularity, the geometric extrapolation of the last decades of
    energy (reference.linear.exponent.extrapolate_time_to_go, as the linear model
    does); without a singularity t_f is the last impact time (remainder 0).

    As the linear estimator, the window leaves out the first `skip_start` decades of
    energy below the initial energy and the last `skip_end` above the lowest energy
    among the used impacts; c is None unless it spans `min_decades` decades with at
    least 8 impacts.  Returns c, c_stderr, t_f, fit_decades, n_used (impacts used) and
    remainder_from ("t_singularity", "extrapolated" or "last_impact")."""
    from reference.linear.exponent import (
        LOG2_10,
        extrapolate_time_to_go,
        fit_energy_exponent,
        time_to_go,
    )

    out = {
        "c": None,
        "c_stderr": None,
        "t_f": None,
        "fit_decades": 0.0,
        "n_used": 0,
        "remainder_from": None,
    }
    imps = traj.impacts
    N = len(imps)
    if N < 8 or traj.n_samples < 2:
        return out
    if energy_at is None:
        energy = np.asarray(traj.energy, dtype=float)

        def energy_at(idx):
            return energy[idx]

    t_i = np.array([e.t for e in imps])
    lo_i = np.array([e.t_lo for e in imps])
    has_lo = traj.t_lo is not None or bool(np.any(lo_i != 0))
    tol = resolution if resolution is not None else (1e-28 if has_lo else 1e-13)
    idx = pre_impact_samples(traj)
    E0 = float(energy_at(np.array([0]))[0])
    if not E0 > 0:
        return out
    E_pre = np.full(N, np.nan)
    E_pre[idx >= 0] = energy_at(idx[idx >= 0])
    # interval before impact i (the first from t = 0)
    tau = np.empty(N)
    tau[0] = t_i[0] + lo_i[0]
    tau[1:] = np.diff(t_i) + np.diff(lo_i)
    bad = np.flatnonzero(~(tau[1:] > tol * np.maximum(np.abs(t_i[1:]), 1.0)))
    K = int(bad[0]) if len(bad) else N - 1  # last impact whose interval is resolved
    t_sing = traj.t_singularity
    rem = None
    if t_sing is not None:
        r = (float(t_sing) - t_i[K]) - lo_i[K]
        if r >= 1e-12 * max(abs(float(t_sing)), 1.0):
            rem, how = r, "t_singularity"
        else:
            last = E_pre[K + 1] if K + 1 < N else energy_at(np.array([traj.n_samples - 1]))[0]
            E_after = np.append(E_pre[1 : K + 1], last)
            with np.errstate(divide="ignore", invalid="ignore"):
                lrem = extrapolate_time_to_go(np.log2(tau[: K + 1]), np.log2(E_after))
            if lrem is not None:
                rem, how = 2.0**lrem, "extrapolated"
    else:
        rem, how = 0.0, "last_impact"
    if rem is None:
        return out
    ttg = time_to_go(tau[: K + 1], rem)  # t_f − t_i for impacts 0..K
    out.update(t_f=float(t_i[K] + lo_i[K] + rem), n_used=K + 1, remainder_from=how)
    E_used = E_pre[: K + 1]
    pos = E_used[E_used > 0]
    if len(pos) < 2:
        return out
    top = math.log10(E0) - skip_start
    bottom = math.log10(pos.min()) + skip_end
    span = top - bottom
    out["fit_decades"] = float(max(span, 0.0))
    with np.errstate(divide="ignore", invalid="ignore"):
        L = np.log2(E_used) / LOG2_10
    sel = (ttg > 0) & np.isfinite(L) & (L <= top) & (L >= bottom)
    if sel.sum() < 8 or span < min_decades:
        return out
    fit = fit_energy_exponent(ttg[sel], E_used[sel])
    out["c"], out["c_stderr"] = fit["c"], fit["c_stderr"]
    return out


def polygon_scene(config: SweepConfig, rho: float, gamma: float, q0, p0):
    """The n-gon (a = m = 1) on flat ground from linear coordinates (q0, p0)."""
    from reference.scene import Body, Ground, RunSettings, Scene, initial_from_linear

    return Scene(
        name=f"sweep-n{config.n}-rho{rho:.6g}-gamma{gamma:.6g}",
        body=Body(n=config.n, radius=1.0, mass=1.0, gyration=rho),
        ground=Ground(kind="flat"),
        initial=initial_from_linear(q0, p0),
        restitution=gamma,
        gravity=config.gravity,
        run=RunSettings(t_end=config.t_end, max_impacts=config.max_impacts),
    )


def run_linear_sample(config: SweepConfig, rho: float, gamma: float, q0, p0) -> dict:
    from reference.linear.simulate import run_linear_exponent

    r = run_linear_exponent(
        config.n, rho, gamma, q0, p0, g=config.gravity, max_impacts=config.max_impacts
    )
    return {
        "status": str(r["status"]),
        "c": r.get("c"),
        "c_stderr": r.get("c_stderr"),
        "t_singularity": r.get("t_singularity"),
        "n_impacts": int(r.get("n_impacts") or 0),
        "fit_decades": r.get("fit_decades"),
        "c_decades": r.get("c_decades"),
        "c_period": r.get("c_period"),
        "message": str(r.get("message") or ""),
        "error": str(r.get("message") or "") if r["status"] == "failed" else None,
    }


def fixed_step_t_end(config: SweepConfig, rho: float, gamma: float, q0, p0) -> float:
    """Run length for a fixed-step engine, which does not stop at the singularity:
    1.5 t_lin + 0.5, t_lin the time at which the linear model from the same initial
    state stops (singularity or undecidable impact; milliseconds to compute).  The
    events-driven reference stops by itself and runs to config.t_end at most."""
    from reference.linear.model import LinearModel
    from reference.linear.simulate import run_linear

    model = LinearModel.polygon(config.n, rho, gamma, gravity=config.gravity)
    run = run_linear(model, q0, p0, max_impacts=config.max_impacts, record_states=False)
    return 1.5 * run.t_final + 0.5


def run_trajectory_sample(config: SweepConfig, rho: float, gamma: float, q0, p0) -> dict:
    from ..simulators import is_fixed_step, run_simulator

    t_end = config.t_end
    if is_fixed_step(config.engine):
        t_end = min(t_end, fixed_step_t_end(config, rho, gamma, q0, p0))
    scene = polygon_scene(config, rho, gamma, q0, p0)
    traj = run_simulator(config.engine, scene, dt=config.dt, t_end=t_end)
    status = traj.status.value
    out = {
        "status": status,
        "c": None,
        "c_stderr": None,
        "t_singularity": traj.t_singularity,
        "n_impacts": len(traj.impacts),
        "fit_decades": None,
        "c_decades": None,
        "c_period": None,
        "message": traj.message,
        "error": traj.message if status == "failed" else None,
    }
    if status in ("simultaneous_impact", "failed"):
        return out  # as in the paper: no exponent for undecidable runs
    fit = trajectory_exponent(
        traj, min_decades=config.min_decades, energy_at=excess_energy_at(traj, scene)
    )
    out.update(c=fit["c"], c_stderr=fit["c_stderr"], fit_decades=fit["fit_decades"])
    return out


def warm_up(config: SweepConfig) -> None:
    """Import and compile the simulator in this process before a local pool forks, so
    that workers inherit the compiled code (the linear kernel is numba-compiled: tens of
    seconds per process when its on-disk cache is stale)."""
    if config.engine == "linear":
        q0, p0 = initial_state(config.seed, 0, 0, 0)
        try:
            run_linear_sample(config, 0.3, 0.5, q0, p0)
        except Exception:  # best effort: the tasks themselves record any error
            pass


def sample_runner(engine: str):
    """The function (config, rho, gamma, q0, p0) -> result dict for an engine."""
    return run_linear_sample if engine == "linear" else run_trajectory_sample


def run_chunk(chunk: Chunk) -> list[dict]:
    """Run every sample of a chunk; one row (dict, the store's schema) per sample."""
    cfg = chunk.config
    rho, gamma = chunk.rho, chunk.gamma
    runner = sample_runner(cfg.engine)
    rows = []
    for s in chunk.samples:
        q0, p0 = initial_state(cfg.seed, chunk.i_gamma, chunk.i_rho, s)
        t0, c0 = time.perf_counter(), time.thread_time()
        try:
            res = runner(cfg, rho, gamma, q0, p0)
        except Exception as exc:  # recorded, never dropped
            res = failed_result(_error_text(exc))
        res["wall_time_s"] = time.perf_counter() - t0
        res["cpu_time_s"] = time.thread_time() - c0
        rows.append(make_row(chunk, s, q0, p0, res))
    return rows


def failed_result(error: str) -> dict:
    return {
        "status": "failed",
        "c": None,
        "c_stderr": None,
        "t_singularity": None,
        "n_impacts": 0,
        "fit_decades": None,
        "c_decades": None,
        "c_period": None,
        "message": error.splitlines()[-1] if error else "",
        "error": error,
    }


def _num(x):
    if x is None:
        return None
    x = float(x)
    return x if math.isfinite(x) else None


def make_row(chunk: Chunk, sample: int, q0, p0, res: dict) -> dict:
    cfg = chunk.config
    return {
        "engine": cfg.engine,
        "n": cfg.n,
        "seed": cfg.seed,
        "i_restitution": chunk.i_gamma,
        "i_gyration": chunk.i_rho,
        "sample": int(sample),
        "gyration": chunk.rho,
        "restitution": chunk.gamma,
        "status": res["status"],
        "c": _num(res["c"]),
        "c_stderr": _num(res["c_stderr"]),
        "t_singularity": _num(res["t_singularity"]),
        "n_impacts": int(res["n_impacts"]),
        "fit_decades": _num(res.get("fit_decades")),
        "c_decades": _num(res.get("c_decades")),
        "c_period": _num(res.get("c_period")),
        "message": res.get("message") or "",
        "error": res.get("error"),
        "q0": [float(x) for x in q0],
        "p0": [float(x) for x in p0],
        "dt": cfg.dt,
        "wall_time_s": float(res.get("wall_time_s", 0.0)),
        "cpu_time_s": float(res.get("cpu_time_s", 0.0)),
    }


def failed_rows(chunk: Chunk, error: str) -> list[dict]:
    """Rows for a chunk whose worker died (the runs could not even report)."""
    rows = []
    for s in chunk.samples:
        q0, p0 = initial_state(chunk.config.seed, chunk.i_gamma, chunk.i_rho, s)
        rows.append(make_row(chunk, s, q0, p0, failed_result(error)))
    return rows
