"""A sweep directory heals: damaged parts and manifests are set aside (renamed, never
deleted) and recomputed, no finished run is lost, and a directory that is no sweep's, or a
grid that cannot run, is refused before anything is written."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from harness.sweep import SweepError, exponent_sweep
from harness.sweep.grid import SweepConfig, initial_state
from harness.sweep.run import failed_result, make_row
from harness.sweep.store import StoreError, load_results


def config(**kw) -> SweepConfig:
    base = dict(n=3, gyration=(0.2, 0.4, 2), restitution=(0.5, 0.7, 2), samples=3, seed=5)
    return SweepConfig(**(base | kw))


def fake_chunk(chunk) -> list[dict]:
    """Rows without physics: c = 10 i_gamma + i_rho + sample / 10 (tells rows apart)."""
    rows = []
    for s in chunk.samples:
        q0, p0 = initial_state(chunk.config.seed, chunk.i_gamma, chunk.i_rho, s)
        res = failed_result("")
        res.update(status="singularity", c=10 * chunk.i_gamma + chunk.i_rho + s / 10)
        rows.append(make_row(chunk, s, q0, p0, res))
    return rows


def sweep(out: Path, cfg: SweepConfig | None = None, **kw) -> dict:
    return exponent_sweep(
        cfg or config(),
        out,
        workers=1,
        chunk_size=1,
        figures=False,
        bar=False,
        run_fn=fake_chunk,
        **kw,
    )


def stored_c(out: Path) -> list[float]:
    return load_results(out / "linear")[0]["c"].tolist()


@pytest.fixture
def finished(tmp_path):
    doc = sweep(tmp_path)
    assert doc["tasks"]["rows"] == 12
    return tmp_path, stored_c(tmp_path)


def test_a_corrupt_manifest_is_set_aside_and_nothing_is_recomputed(finished):
    out, c = finished
    manifest = out / "linear" / "manifest.json"
    manifest.write_text("{not json")
    doc = sweep(out)
    assert doc["tasks"]["computed"] == 0 and stored_c(out) == c
    aside = list((out / "linear").glob("manifest.json.corrupt-*"))
    assert len(aside) == 1 and aside[0].read_text() == "{not json"
    assert json.loads(manifest.read_text()) == config().to_dict()


def test_a_truncated_part_is_set_aside_and_its_runs_recomputed(finished):
    out, c = finished
    parts = sorted((out / "linear" / "parts").glob("part-*.parquet"))
    damaged = parts[3]
    data = damaged.read_bytes()
    damaged.write_bytes(data[: len(data) // 2])
    doc = sweep(out)
    assert doc["tasks"]["stored_before"] == 11 and doc["tasks"]["computed"] == 1
    assert stored_c(out) == c
    aside = list(damaged.parent.glob(damaged.name + ".corrupt-*"))
    assert len(aside) == 1 and aside[0].read_bytes() == data[: len(data) // 2]


def test_a_corrupt_manifest_over_runs_of_other_parameters_is_refused(finished):
    out, c = finished
    (out / "linear" / "manifest.json").write_text("[]")
    with pytest.raises(StoreError, match="another sweep"):
        sweep(out, config(seed=6))
    assert stored_c(out) == c


def test_a_manifest_over_no_runs_does_not_block_the_corrected_command(tmp_path):
    (tmp_path / "linear" / "parts").mkdir(parents=True)
    wrong = config(samples=10**9 // 4).to_dict()  # e.g. left by an old, too large sweep
    (tmp_path / "linear" / "manifest.json").write_text(json.dumps(wrong))
    doc = sweep(tmp_path)
    assert doc["tasks"]["rows"] == 12
    assert len(list((tmp_path / "linear").glob("manifest.json.unused-*"))) == 1


def test_other_parameters_over_stored_runs_are_still_refused(finished):
    out, _ = finished
    with pytest.raises(StoreError, match="other parameters"):
        sweep(out, config(samples=4))


@pytest.mark.parametrize(
    "cfg,fragment",
    [
        (config(gyration=(0.0, 0.5, 3)), "rho = 0"),
        (config(restitution=(0.5, 1.5, 3)), "[0, 1]"),
        (config(gyration=(0.1, 0.5, 10_000), restitution=(0.0, 1.0, 10_000)), "at most"),
        (config(n=10**7), "--n"),
    ],
)
def test_a_sweep_that_cannot_run_writes_nothing(tmp_path, cfg, fragment):
    with pytest.raises(SweepError, match=fragment.replace("[", r"\[")):
        sweep(tmp_path / "sw", cfg)
    assert not (tmp_path / "sw").exists()


@pytest.mark.parametrize(
    "foreign", ["readme.md", "linear/notes.txt", "linear/parts/mine.csv", "other/x.txt"]
)
def test_a_directory_that_is_no_sweep_is_refused(tmp_path, foreign):
    (tmp_path / foreign).parent.mkdir(parents=True, exist_ok=True)
    (tmp_path / foreign).write_text("mine")
    with pytest.raises(StoreError, match="not a sweep directory"):
        sweep(tmp_path)
    assert (tmp_path / foreign).read_text() == "mine"
    assert not (tmp_path / "linear" / "manifest.json").exists()


@pytest.mark.parametrize("address", ["closed", "ucx://host:8786", "tcp://[::1", "tcp://:8786"])
def test_a_bad_scheduler_is_one_line_before_anything_is_written(tmp_path, capsys, address):
    import socket

    from harness.cli import main

    if address == "closed":  # a port that was free a moment ago: nobody listens
        with socket.socket() as s:
            s.bind(("127.0.0.1", 0))
            address = f"tcp://127.0.0.1:{s.getsockname()[1]}"
    argv = ["sweep", "exponent", "--gyration", "0.3", "--restitution", "0.5", "--samples", "1"]
    code = main(
        [*argv, "--out", str(tmp_path / "sw"), "--executor", "dask", "--scheduler", address]
    )
    err = [x for x in capsys.readouterr().err.splitlines() if x.strip()]
    assert code == 2 and len(err) == 1 and "scheduler" in err[0].lower()
    assert not (tmp_path / "sw").exists()
