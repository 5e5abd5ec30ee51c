"""The sweep store checks what it reads: a part proves it belongs by its content
hash and its own parameters; damaged, foreign, off-grid and duplicated parts are set
aside (said in the text output) and their runs recomputed; a lost manifest is never
trusted over the parts' own parameters."""

from __future__ import annotations

import json
import random

import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from harness.sweep.parts import (
    SCHEMA,
    checked_columns,
    content_hash,
    part_bytes,
    part_name,
    rows_mismatch,
)
from harness.sweep.store import StoreError, load_results
from tests.test_sweep_heal import config, fake_chunk, stored_c, sweep


@pytest.fixture
def finished(tmp_path):
    doc = sweep(tmp_path)
    assert doc["tasks"]["rows"] == 12
    return tmp_path, stored_c(tmp_path)


def parts_of(out):
    return sorted((out / "linear" / "parts").glob("part-*.parquet"))


def rows_of(path):
    return pq.read_table(path).to_pylist()


def plant(out, rows, cfg, label="0000"):
    """A well-formed part (valid hash, `cfg` as its own parameters) named to sort first."""
    data = part_bytes(rows, cfg)
    path = out / "linear" / "parts" / part_name(label, data)
    path.write_bytes(data)
    return path


def test_a_lost_manifest_and_another_t_end_are_refused_not_mixed(finished):
    out, c = finished
    (out / "linear" / "manifest.json").write_text("{damaged")
    with pytest.raises(StoreError, match=r"another sweep \(t_end=200.0 \(now 0.5\)\)"):
        sweep(out, config(t_end=0.5))
    assert stored_c(out) == c


def test_every_flipped_bit_is_caught_and_the_run_recomputed(finished):
    out, c = finished
    rng = random.Random(34)
    for _ in range(5):
        part = rng.choice(parts_of(out))
        data = bytearray(part.read_bytes())
        k = rng.randrange(len(data) * 8)
        data[k // 8] ^= 1 << (k % 8)
        part.write_bytes(bytes(data))
        doc = sweep(out)
        assert doc["tasks"]["computed"] == 1 and stored_c(out) == c
        text = " ".join(doc["text"].split())  # the text wraps long lines
        assert f"set aside corrupt part {part.name}.corrupt-" in text


def test_a_part_of_another_seed_is_set_aside_and_recomputed(finished):
    out, c = finished
    rows = rows_of(parts_of(out)[0])
    planted = plant(out, [r | {"seed": 6, "c": -5.0} for r in rows], config(seed=6))
    doc = sweep(out)
    assert stored_c(out) == c and doc["tasks"]["computed"] == 0
    assert f"foreign part {planted.name}" in doc["text"] and "seed=6 (now 5)" in doc["text"]


def test_a_parquet_file_of_other_columns_is_set_aside(finished):
    out, c = finished
    sink = pa.BufferOutputStream()
    pq.write_table(pa.table({"x": [1.0]}), sink)
    data = sink.getvalue().to_pybytes()
    (out / "linear" / "parts" / f"part-x-{content_hash(data)}.parquet").write_bytes(data)
    (out / "linear" / "parts" / "part-by-hand.parquet").write_bytes(data)
    doc = sweep(out)
    assert doc["tasks"]["rows"] == 12 and doc["tasks"]["missing"] == 0 and stored_c(out) == c
    assert "other columns than a sweep's" in doc["text"]
    assert "unverified part part-by-hand.parquet" in doc["text"]


def test_rows_outside_the_grid_are_refused(finished):
    out, c = finished
    rows = rows_of(parts_of(out)[0])
    plant(out, [r | {"sample": 7} for r in rows], config())
    doc = sweep(out)
    assert doc["tasks"]["rows"] == 12 and stored_c(out) == c
    assert "rows off this sweep's grid: samples beyond 3" in doc["text"]


@pytest.mark.parametrize(
    ("change", "why"),
    [
        ({}, ""),
        ({"engine": "mujoco"}, "engine ['mujoco'] (now 'linear')"),
        ({"n": 4}, "n [4] (now 3)"),
        ({"seed": 6}, "seed [6] (now 5)"),
        ({"i_gyration": 2}, "grid indices beyond this grid"),
        ({"i_restitution": -1}, "grid indices beyond this grid"),
        ({"i_gyration": None}, "grid indices beyond this grid"),
        ({"sample": 3}, "samples beyond 3"),
        ({"gyration": 0.2 + 1e-12}, "other grid values"),
        ({"restitution": None}, "other grid values"),
        ({"dt": 1e-3}, "another dt"),
    ],
)
def test_rows_off_the_grid_are_named_by_what_is_off(finished, change, why):
    """Every row of a finished part with one field changed (a null: None), and the
    reason `rows_mismatch` gives; the part as stored has none."""
    out, _ = finished
    rows = [r | change for r in rows_of(parts_of(out)[0])]
    table = pa.Table.from_pylist(rows, schema=SCHEMA)
    assert rows_mismatch(checked_columns(table), config()) == why


def test_a_duplicate_part_that_sorts_first_is_refused_with_the_one_it_doubles(finished):
    out, c = finished
    original = parts_of(out)[0]
    plant(out, [r | {"c": 99.0} for r in rows_of(original)], config())
    doc = sweep(out)
    assert doc["text"].count("duplicate part") == 2
    assert doc["tasks"]["computed"] == 1 and stored_c(out) == c  # recomputed, not 99


def test_load_results_reads_only_parts_that_belong(finished):
    out, c = finished
    plant(out, [r | {"c": 99.0} for r in fake_chunk_rows()], config(seed=6))
    df, refused = load_results(out / "linear")
    assert df["c"].tolist() == c and refused == 1


def fake_chunk_rows():
    from harness.sweep.grid import make_chunks

    cfg = config(seed=6)
    chunk = make_chunks(cfg, [(0, 0, 0)], 1)[0]
    return fake_chunk(chunk)


def test_each_part_carries_the_sweep_parameters(finished):
    out, _ = finished
    meta = pq.read_schema(parts_of(out)[0]).metadata
    assert json.loads(meta[b"harness.sweep.config"]) == config().to_dict()
