"""One sweep task: run a simulator from a task's initial state and estimate the exponent c
of E ≈ a (t_f − t)^c (paper eq. scalinglaw, section 4.3).

- `linear`: reference.linear.simulate.run_linear_exponent, which runs the linearised
  model to the singularity and fits c with its own estimator.
- `reference`: the exact reference called directly, samples at its events only
  (`run_reference_sample`), then as below.
- every other simulator: a Scene (the n-gon, a = m = 1, on flat ground, from (q0, p0) via
  reference.scene.initial_from_linear), harness.simulators.run_simulator, and
  reference.exponent.trajectory_exponent on the energy above the resting level: the
  regression of log E before each impact on log(t_f − t), for runs that reach the
  singularity (fixed-step engines never report one, so they have no c).

`run_chunk` is what workers execute: plain data in, a list of row dicts out.  A run
that raises becomes a row with status `failed` and the error text; it never takes the
chunk down.
"""

from __future__ import annotations

import math
import time
import traceback

from .grid import Chunk, SweepConfig, initial_state

LOG10 = math.log(10.0)


def _error_text(exc: BaseException, limit: int = 2000) -> str:
    tb = traceback.format_exception(type(exc), exc, exc.__traceback__, limit=-3)
    text = "".join(tb).strip()
    return text[-limit:]


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
        impact_law=config.impact_law,
        simultaneity_window=config.simultaneity_window,
    )


def run_linear_sample(config: SweepConfig, rho: float, gamma: float, q0, p0) -> dict:
    from reference.linear.simulate import run_linear_exponent

    r = run_linear_exponent(
        config.n, rho, gamma, q0, p0, g=config.gravity, max_impacts=config.max_impacts,
        impact_law=config.impact_law, simultaneity_window=config.simultaneity_window,
    )  # fmt: skip
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
    """A simulator other than the linear model and the reference, through
    harness.simulators.run_simulator (its checks and guard), then `exponent_result`."""
    from ..simulators import is_fixed_step, run_simulator

    t_end = config.t_end
    if is_fixed_step(config.engine):
        t_end = min(t_end, fixed_step_t_end(config, rho, gamma, q0, p0))
    scene = polygon_scene(config, rho, gamma, q0, p0)
    traj = run_simulator(config.engine, scene, dt=config.dt, t_end=t_end)
    return exponent_result(traj, scene, config)


def run_reference_sample(config: SweepConfig, rho: float, gamma: float, q0, p0) -> dict:
    """The exact reference, called directly with samples at its events only (no regular
    grid): the fit reads the energy before each impact, which the sample after the
    previous event holds (energy is constant in flight and in frictionless contact
    phases).  The reference ends a nonfinite or penetrating state with an explicit
    status itself, so the engines' guard is not needed; the scene is checked as any
    (`check_scene`)."""
    from reference import ReferenceOptions, simulate
    from reference.scene import check_scene

    scene = polygon_scene(config, rho, gamma, q0, p0)
    check_scene(scene)
    traj = simulate(scene, options=ReferenceOptions(sample_dt=config.t_end))
    return exponent_result(traj, scene, config)


def exponent_result(traj, scene, config: SweepConfig) -> dict:
    """The row's results of one run: its status, t_singularity and impacts, and c
    (`reference.exponent.trajectory_exponent` on the energy above the resting level) for
    runs that reached the singularity."""
    from reference.exponent import excess_energy_of, trajectory_exponent

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
    if status != "singularity":
        return out  # as in the paper: c only for runs that reach the singularity
    fit = trajectory_exponent(
        traj, energy=excess_energy_of(traj, scene), min_decades=config.min_decades
    )
    out.update(c=fit.c, c_stderr=fit.c_stderr, fit_decades=fit.fit_decades)
    return out


def warm_up(config: SweepConfig) -> None:
    """Import and compile the simulator in this process before a local pool forks, so
    that workers inherit the compiled code (the linear kernel and, without its
    ahead-of-time build, the reference are numba-compiled: tens of seconds per process
    when the on-disk cache is stale)."""
    if config.engine in ("linear", "reference"):
        q0, p0 = initial_state(config.seed, 0, 0, 0)
        try:
            sample_runner(config.engine)(config, 0.3, 0.5, q0, p0)
        except Exception:  # best effort: the tasks themselves record any error
            pass


def sample_runner(engine: str):
    """The function (config, rho, gamma, q0, p0) -> result dict for an engine."""
    runners = {"linear": run_linear_sample, "reference": run_reference_sample}
    return runners.get(engine, run_trajectory_sample)


def run_chunk(chunk: Chunk) -> list[dict]:
    """Run every sample of a chunk; one row (dict, the store's schema) per sample.  An
    engine that offers `simulate_batch` runs the chunk's samples as one batch
    (`run_batched_chunk`)."""
    cfg = chunk.config
    rho, gamma = chunk.rho, chunk.gamma
    if cfg.engine not in ("linear", "reference") and len(chunk.samples) > 1:
        from ..simulators import offers_batch

        if offers_batch(cfg.engine):
            return run_batched_chunk(chunk)
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


def run_batched_chunk(chunk: Chunk) -> list[dict]:
    """The chunk's samples as one `harness.simulators.run_batch` call (each scene with
    its own run length, `run_trajectory_sample`'s); each row's wall_time_s and
    cpu_time_s are the batch's divided by the number of samples.  A batch that raises
    falls back to the samples one by one."""
    from ..simulators import is_fixed_step, run_batch

    cfg = chunk.config
    rho, gamma = chunk.rho, chunk.gamma
    starts = [initial_state(cfg.seed, chunk.i_gamma, chunk.i_rho, s) for s in chunk.samples]
    scenes = []
    for q0, p0 in starts:
        t_end = cfg.t_end
        if is_fixed_step(cfg.engine):
            t_end = min(t_end, fixed_step_t_end(cfg, rho, gamma, q0, p0))
        scenes.append(polygon_scene(cfg, rho, gamma, q0, p0).with_run(t_end=t_end))
    t0, c0 = time.perf_counter(), time.thread_time()
    try:
        trajs = run_batch(cfg.engine, scenes, dt=cfg.dt)
    except Exception as exc:  # recorded, never dropped
        trajs = [None] * len(scenes)
        error = _error_text(exc)
    share = 1.0 / len(scenes)
    wall, cpu = (time.perf_counter() - t0) * share, (time.thread_time() - c0) * share
    rows = []
    for s, (q0, p0), scene, traj in zip(chunk.samples, starts, scenes, trajs, strict=True):
        res = exponent_result(traj, scene, cfg) if traj is not None else failed_result(error)
        res["wall_time_s"], res["cpu_time_s"] = wall, cpu
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
