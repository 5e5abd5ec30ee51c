"""The exponent sweep: reproducible tasks, executors that agree, a store that survives
SIGKILL, failures recorded, and c equal to the estimator run directly."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from harness.sweep import exponent_sweep
from harness.sweep.grid import SweepConfig, initial_state
from harness.sweep.store import StoreError, SweepStore, load_results
from reference.trajectory import ImpactEvent, Status, Trajectory
from tests.conftest import require_extra

ROOT = Path(__file__).resolve().parents[1]
RESULT_COLUMNS = [
    "i_restitution",
    "i_gyration",
    "sample",
    "gyration",
    "restitution",
    "status",
    "c",
    "c_stderr",
    "t_singularity",
    "n_impacts",
    "message",
    "error",
]


def small_config(**kw) -> SweepConfig:
    base = dict(
        n=3,
        gyration=(0.1, 0.3, 2),
        restitution=(0.5, 0.8, 2),
        samples=6,
        seed=7,
        engine="linear",
    )
    base.update(kw)
    return SweepConfig(**base)


def paper_initial_state(seed, i_gamma, i_rho, sample):
    """The paper's (q0, p0), drawn as the sweep documents it (harness.sweep.grid docstring)."""
    rng = np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(i_gamma, i_rho, sample)))
    x = rng.uniform(-0.5, 0.5, 4)
    return [0.001 * x[2], 0.001 * x[3], 1.0], [0.1 * x[0], 0.1 * x[1], -1.0]


def rows(out: Path, engine="linear"):
    df, dups = load_results(out / engine)
    assert dups == 0
    return df


# ----------------------------------------------------------------------------- tasks


def test_initial_states_follow_the_paper_and_depend_only_on_the_task_key():
    states = {
        (ig, ir, s): initial_state(3, ig, ir, s)
        for ig in range(3)
        for ir in range(3)
        for s in range(40)
    }
    q = np.array([v[0] for v in states.values()])
    p = np.array([v[1] for v in states.values()])
    assert np.all(q[:, 2] == 1.0) and np.all(p[:, 2] == -1.0)
    assert np.all(np.abs(q[:, :2]) <= 0.0005) and np.all(np.abs(p[:, :2]) <= 0.05)
    # spread over the whole interval, not a constant
    assert np.ptp(p[:, 0]) > 0.08 and np.ptp(q[:, 1]) > 0.0008
    # same key, same state, whatever was drawn before; distinct keys, distinct states
    again = initial_state(3, 2, 1, 17)
    assert np.array_equal(again[1], states[(2, 1, 17)][1])
    assert len({tuple(v[1]) for v in states.values()}) == len(states)
    assert not np.array_equal(initial_state(4, 2, 1, 17)[1], again[1])


# ----------------------------------------------------------------------------- executors


@pytest.fixture(scope="module")
def local_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("local")
    doc = exponent_sweep(small_config(), out, workers=2, chunk_size=4, figures=False, bar=False)
    return out, doc


def test_local_and_dask_executors_give_identical_rows(local_run, tmp_path):
    distributed = require_extra("distributed", "dask")
    out_local, _ = local_run
    with distributed.LocalCluster(
        n_workers=1,
        threads_per_worker=2,
        processes=False,
        host="127.0.0.1",
        protocol="tcp://",
        dashboard_address=None,
    ) as cluster:
        doc = exponent_sweep(
            small_config(),
            tmp_path,
            executor="dask",
            scheduler=cluster.scheduler_address,
            chunk_size=3,  # another chunking too
            figures=False,
            bar=False,
        )
    assert doc["tasks"]["rows"] == 24
    a, b = rows(out_local), rows(tmp_path)
    assert len(a) == len(b) == 24
    assert a[RESULT_COLUMNS].equals(b[RESULT_COLUMNS])
    # the grid has both regimes: not a comparison of empty results
    assert a["c"].notna().sum() >= 6


def test_grid_point_c_equals_the_estimator_run_directly(local_run):
    from reference.linear.simulate import run_linear_exponent

    out, doc = local_run
    df = rows(out)
    means = {}
    for r in df.itertuples():
        q0, p0 = paper_initial_state(7, r.i_restitution, r.i_gyration, r.sample)
        direct = run_linear_exponent(3, r.gyration, r.restitution, q0, p0, g=1.0, max_impacts=20000)
        assert r.status == direct["status"]
        if direct["c"] is None:
            assert np.isnan(r.c)
        else:
            assert r.c == direct["c"]
            means.setdefault((r.restitution, r.gyration), []).append(direct["c"])
    for pt in doc["points"]:
        cs = means.get((pt["restitution"], pt["gyration"]))
        if cs:
            assert pt["mean_c"] == pytest.approx(np.mean(cs), rel=1e-12)
            assert pt["n_c"] == len(cs)
        else:
            assert pt["mean_c"] is None


def test_rerun_of_a_finished_sweep_computes_nothing(local_run):
    out, _ = local_run
    parts = sorted(p.name for p in (out / "linear" / "parts").iterdir())
    doc = exponent_sweep(small_config(), out, figures=False, bar=False)
    assert doc["tasks"]["stored_before"] == 24 and doc["tasks"]["computed"] == 0
    assert sorted(p.name for p in (out / "linear" / "parts").iterdir()) == parts


def test_other_parameters_in_the_same_directory_are_refused(local_run):
    out, _ = local_run
    with pytest.raises(StoreError, match="samples=6"):
        exponent_sweep(small_config(samples=7), out, figures=False, bar=False)


def test_cli_reports_bad_sweep_input_as_exit_status_2(tmp_path, capsys, no_sweep_figures):
    from harness.cli import main

    base = ["sweep", "exponent", "--gyration", "0.2", "--samples", "1", "--out", str(tmp_path)]
    assert main(base + ["--restitution", "0.5:1.2:3"]) == 2
    assert main(base + ["--restitution", "0.5", "--engine", "nonsense"]) == 2
    assert main(base + ["--restitution", "0.5", "--executor", "dask"]) == 2
    assert main(base + ["--restitution", "0.9", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["tasks"]["rows"] == 1 and doc["grid"]["restitution"] == [0.9]
    other = ["sweep", "exponent", "--gyration", "0.2", "--samples", "2", "--out", str(tmp_path)]
    assert main(other + ["--restitution", "0.9"]) == 2
    err = capsys.readouterr().err
    assert "samples=1 (now 2)" in err and "Traceback" not in err


def test_a_second_writer_is_refused_while_the_first_holds_the_lock(tmp_path):
    cfg = small_config()
    with SweepStore(tmp_path, cfg):
        with pytest.raises(StoreError, match="another sweep"):
            SweepStore(tmp_path, cfg).open()
    SweepStore(tmp_path, cfg).open().close()


# ----------------------------------------------------------------------------- failures


def _boom_on_sample_1(config, rho, gamma, q0, p0):
    raise ValueError(f"boom at rho={rho}")


def test_a_run_that_raises_is_recorded_with_its_error(tmp_path, monkeypatch, fork_children):
    import harness.sweep.run as sr

    real = sr.run_linear_sample
    calls = {"n": 0}

    def flaky(config, rho, gamma, q0, p0):
        calls["n"] += 1
        if rho > 0.2:
            return _boom_on_sample_1(config, rho, gamma, q0, p0)
        return real(config, rho, gamma, q0, p0)

    monkeypatch.setattr(sr, "run_linear_sample", flaky)  # reaches the pool by fork only
    cfg = small_config(samples=2)
    doc = exponent_sweep(cfg, tmp_path, workers=1, figures=False, bar=False)
    df = rows(tmp_path)
    bad = df[df["gyration"] > 0.2]
    good = df[df["gyration"] < 0.2]
    assert len(bad) == 4 and (bad["status"] == "failed").all()
    assert bad["c"].isna().all()
    assert bad["error"].str.contains("ValueError: boom at rho=0.3").all()
    assert (good["status"] != "failed").all() and good["error"].isna().all()
    assert doc["counts"]["failed"] == 4
    # a failed run is a result: a rerun does not recompute it
    doc2 = exponent_sweep(cfg, tmp_path, workers=1, figures=False, bar=False)
    assert doc2["tasks"]["computed"] == 0


def crash_on_sample_3(chunk):
    """Stand-in for run_chunk whose worker process dies on sample 3."""
    from harness.sweep.run import run_chunk

    if 3 in chunk.samples:
        os._exit(3)
    return run_chunk(chunk)


def test_a_run_that_kills_its_worker_is_recorded_and_the_others_survive(tmp_path):
    cfg = small_config(gyration=(0.3, 0.3, 1), restitution=(0.8, 0.8, 1), samples=6)
    exponent_sweep(
        cfg, tmp_path, workers=2, chunk_size=2, figures=False, bar=False, run_fn=crash_on_sample_3
    )
    df = rows(tmp_path)
    assert list(df["sample"]) == [0, 1, 2, 3, 4, 5]
    assert df.loc[3, "status"] == "failed"
    assert "worker failed" in df.loc[3, "error"]
    others = df.drop(index=3)
    # the chunks that shared the broken pool are rerun, not blamed
    assert (others["status"] != "failed").all() and others["error"].isna().all()


def half_second_chunk(chunk):
    """Stand-in for run_chunk: half a second per chunk, no rows."""
    time.sleep(0.5)
    return []


def test_a_local_pool_stopped_mid_sweep_leaves_no_thread_or_worker_running():
    import multiprocessing as mp
    import threading

    from harness.sweep.executors import run_local
    from harness.sweep.grid import all_keys, make_chunks

    cfg = small_config(samples=4)
    threads, children = set(threading.enumerate()), set(mp.active_children())
    results = run_local(make_chunks(cfg, all_keys(cfg), 1), workers=1, fn=half_second_chunk)
    next(results)  # one chunk done, the next ones in the pool's queue
    results.close()  # as a signal or an error in the consumer does
    # nothing of the pool is left for the interpreter's exit to race with
    assert set(threading.enumerate()) - threads == set()
    assert set(mp.active_children()) - children == set()


# ----------------------------------------------------------------------------- SIGKILL

SLOW_CLI = """
import sys, time
import harness.sweep.run as sr
real = sr.run_linear_sample
def slow(*a, **k):
    time.sleep(0.04)
    return real(*a, **k)
sr.run_linear_sample = slow
from harness.cli import main
sys.exit(main(sys.argv[1:]))
"""


def _children(pid: int) -> list[int]:
    out = []
    for d in Path("/proc").iterdir():
        if d.name.isdigit():
            try:
                stat = (d / "stat").read_text()
            except OSError:
                continue
            if int(stat.rsplit(")", 1)[1].split()[1]) == pid:
                out.append(int(d.name))
    return out


def _alive(pid: int) -> bool:
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state != "Z"


def test_sweep_killed_with_sigkill_resumes_and_has_every_run_once(tmp_path):
    argv = [
        "sweep",
        "exponent",
        "--gyration",
        "0.1:0.3:2",
        "--restitution",
        "0.5:0.8:2",
        "--samples",
        "40",
        "--seed",
        "11",
        "--workers",
        "2",
        "--out",
        str(tmp_path / "killed"),
        "--json",
    ]
    parts = tmp_path / "killed" / "linear" / "parts"
    proc = subprocess.Popen(
        [sys.executable, "-c", SLOW_CLI, *argv],
        cwd=ROOT,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    deadline = time.time() + 120
    while time.time() < deadline and len(list(parts.glob("part-*.parquet"))) < 2:
        time.sleep(0.05)
    workers = _children(proc.pid)
    os.kill(proc.pid, signal.SIGKILL)
    proc.wait()
    before = sorted(p.name for p in parts.glob("part-*.parquet"))
    n_before = len(rows(tmp_path / "killed"))
    assert 0 < n_before < 160, "the kill must land mid-way"
    # the pool's workers notice and exit
    t0 = time.time()
    while any(_alive(w) for w in workers) and time.time() - t0 < 10:
        time.sleep(0.1)
    assert workers and not any(_alive(w) for w in workers)

    done = subprocess.run(
        [sys.executable, "-m", "harness.cli", *argv[:-1], "--json"],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=300,
        env={**os.environ, "MPLBACKEND": "Agg"},
    )
    assert done.returncode == 0, done.stderr[-2000:]
    doc = json.loads(done.stdout)
    assert doc["tasks"]["stored_before"] == n_before
    assert doc["tasks"]["computed"] == 160 - n_before
    df = rows(tmp_path / "killed")
    keys = list(zip(df["i_restitution"], df["i_gyration"], df["sample"], strict=True))
    assert len(keys) == 160 and len(set(keys)) == 160
    # every part of the killed run is still there, untouched; no temporary files left
    assert set(before) <= {p.name for p in parts.glob("part-*.parquet")}
    assert not list(parts.glob(".tmp-*"))
    # and the result is the one an uninterrupted run gives
    ref = tmp_path / "whole"
    exponent_sweep(
        SweepConfig(3, (0.1, 0.3, 2), (0.5, 0.8, 2), 40, 11), ref, figures=False, bar=False
    )
    assert df[RESULT_COLUMNS].equals(rows(ref)[RESULT_COLUMNS])
    assert set(doc["figures"]) == {"exponent_map", "simultaneous", "sections"}
    assert all(Path(p).stat().st_size > 10_000 for p in doc["figures"].values())


# ----------------------------------------------------------------------------- Trajectory engines


def _power_law_trajectory(c: float, a: float, t_f: float, k: int = 100, with_tsing=True):
    """Impacts at t_i = t_f − 0.5^i (as hi + lo parts: the last ones are closer to t_f
    than an ulp of t_f), energy constant between impacts and equal to a (t_f − t_i)^c
    just before impact i; samples at t = 0 and at every impact (post-impact)."""
    ttg = 0.5 ** np.arange(k)
    hi = t_f - ttg
    lo = (t_f - hi) - ttg  # t_f - hi is exact (Sterbenz)
    e_pre = a * ttg**c
    t = np.concatenate([[0.0], hi])
    t_lo = np.concatenate([[0.0], lo])
    E = np.concatenate([[e_pre[0]], e_pre[1:], [e_pre[-1] * 0.5**c]])
    z = np.zeros((len(t), 3))
    return Trajectory(
        engine="stand-in",
        scene="power-law",
        t=t,
        position=z,
        quaternion=np.tile([1.0, 0, 0, 0], (len(t), 1)),
        velocity=z,
        angular_velocity=z,
        kinetic_energy=E,
        potential_energy=np.zeros(len(t)),
        impacts=[
            ImpactEvent(float(x), i % 3, 1.0, -1.0, 0.5, t_lo=float(y))
            for i, (x, y) in enumerate(zip(hi, lo, strict=True))
        ],
        status=Status.SINGULARITY,
        t_singularity=t_f if with_tsing else None,
        t_lo=t_lo,
    )


@pytest.mark.parametrize("c", [0.4, 2.0, 3.1])
def test_trajectory_exponent_recovers_a_power_law_beyond_the_clock_resolution(c):
    """100 impacts down to 0.5^99 ≈ 1.6e-30 before t_f = 4: the intervals below the
    double-double clock's resolution (~1e-28 t) are left out, and t_f − t_K (below an
    ulp of t_f) is extrapolated, not taken from t_singularity."""
    from reference.exponent import trajectory_exponent

    fit = trajectory_exponent(_power_law_trajectory(c, 1.7, 4.0), min_decades=4)
    assert fit.c == pytest.approx(c, rel=1e-9)
    assert fit.t_f_source == "extrapolated"
    assert 85 < fit.n_used < 100


@pytest.mark.parametrize("c", [2.0, 3.1])
def test_trajectory_exponent_uses_a_resolved_t_singularity(c):
    from reference.exponent import trajectory_exponent

    fit = trajectory_exponent(_power_law_trajectory(c, 1.7, 4.0, k=30))
    assert fit.t_f_source == "t_singularity" and fit.n_used == 30
    assert fit.c == pytest.approx(c, rel=1e-9)


def test_trajectory_exponent_needs_enough_decades():
    from reference.exponent import trajectory_exponent

    fit = trajectory_exponent(_power_law_trajectory(0.4, 1.0, 4.0))  # window 5.96 decades
    assert fit.c is None and 5.5 < fit.fit_decades < 6


def test_trajectory_exponent_without_t_singularity_uses_the_last_impact():
    from reference.exponent import trajectory_exponent

    # t_f taken at the last used impact: time-to-go 0.5^i − 0.5^K, still E ∝ ttg^c to
    # within the window (the last decades are left out)
    fit = trajectory_exponent(_power_law_trajectory(2.0, 1.0, 4.0, with_tsing=False))
    assert fit.t_f_source == "last_impact"
    assert fit.c == pytest.approx(2.0, rel=1e-3)


def test_trajectory_exponent_on_excess_energy_matches_the_linear_model():
    """Cross-method on one run: the exact reference (energy above the floor set by its
    invariants) against the linear model's own estimator, same initial state, where
    gravity keeps the motion self-similar (c = 2, paper section 3.4)."""
    from harness.sweep.run import polygon_scene
    from reference import ReferenceOptions, simulate
    from reference.exponent import excess_energy_of, trajectory_exponent
    from reference.linear.simulate import run_linear_exponent

    cfg = small_config(engine="reference")
    q0, p0 = paper_initial_state(0, 3, 0, 0)
    scene = polygon_scene(cfg, 0.1, 0.7, q0, p0)
    # 21 decades of energy (the default floor stops at 18): the fit then spans as many
    # decades as the linear model's own (the estimator leaves out the first 3 and last 2)
    traj = simulate(scene, t_end=50.0, options=ReferenceOptions(energy_floor=1e-21))
    fit = trajectory_exponent(traj, energy=excess_energy_of(traj, scene))
    lin = run_linear_exponent(3, 0.1, 0.7, q0, p0)
    assert traj.status is Status.SINGULARITY and lin["status"] == "singularity"
    assert fit.fit_decades > 15
    assert fit.c == pytest.approx(lin["c"], abs=0.01)
    assert abs(fit.c - 2.0) < 0.1


def test_reference_simulator_sample_agrees_with_the_linear_model(tmp_path):
    """Cross-method: the exact nonlinear reference and the linear model from the same
    initial state, where gravity keeps the motion self-similar (c = 2)."""
    cfg = dict(gyration=(0.2, 0.2, 1), restitution=(0.8, 0.8, 1), samples=2)
    exponent_sweep(small_config(**cfg), tmp_path, figures=False, bar=False)
    exponent_sweep(
        small_config(engine="reference", min_decades=4.0, **cfg), tmp_path, figures=False, bar=False
    )
    lin, ref = rows(tmp_path, "linear"), rows(tmp_path, "reference")
    assert (ref["status"] == "singularity").all()
    assert np.allclose(ref["c"], lin["c"], atol=0.02)
    assert np.allclose(ref["t_singularity"], lin["t_singularity"], rtol=0.02)
    assert (ref["error"].isna()).all()


def test_reference_sample_with_event_samples_equals_the_guarded_generic_path():
    """The sweep calls the reference directly with samples at its events only; the
    generic path (run_simulator with its checks, guard and regular sample grid) gives
    the same status, impacts, t_singularity and c."""
    from harness.sweep.run import run_reference_sample, run_trajectory_sample

    cfg = small_config(engine="reference", min_decades=4.0)
    fitted = 0
    for s in range(4):
        q0, p0 = initial_state(cfg.seed, 0, 0, s)
        direct = run_reference_sample(cfg, 0.2, 0.8, q0, p0)
        generic = run_trajectory_sample(cfg, 0.2, 0.8, q0, p0)
        for key in ("status", "n_impacts", "t_singularity", "message"):
            assert direct[key] == generic[key]
        if generic["c"] is not None:
            fitted += 1
            assert direct["c"] == pytest.approx(generic["c"], rel=1e-12)
    assert fitted > 0
