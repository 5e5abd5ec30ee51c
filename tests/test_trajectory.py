"""ImpactLog and SampleBuffer: the array-backed stores behave like the lists they replace."""

from __future__ import annotations

import numpy as np
import pytest

from reference.trajectory import ImpactEvent, ImpactLog, SampleBuffer


def _events(k: int) -> list[ImpactEvent]:
    return [
        ImpactEvent(
            t=0.1 * i,
            contact=i % 3,
            impulse=1.0 + i,
            v_normal_pre=-i,
            v_normal_post=0.5 * i,
            t_lo=1e-18 * i,
        )
        for i in range(k)
    ]


def test_impact_log_reads_back_the_events_appended_one_by_one_and_in_blocks():
    ev = _events(600)  # beyond the initial capacity: growth is exercised
    log = ImpactLog(ev[:300])
    rows = np.array(
        [[e.t, e.t_lo, e.contact, e.impulse, e.v_normal_pre, e.v_normal_post] for e in ev[300:]]
    )
    log.extend_rows(rows)
    assert len(log) == 600
    assert log == ev and list(log) == ev
    assert log[-1] == ev[-1] and log[5] == ev[5] and log[2:7] == ev[2:7]
    assert isinstance(log[0].contact, int)
    np.testing.assert_array_equal(log.column("t"), [e.t for e in ev])
    np.testing.assert_array_equal(log.column("contact"), [e.contact for e in ev])
    with pytest.raises(IndexError):
        log[600]


def test_sample_buffer_keeps_rows_in_order_across_single_and_block_appends():
    buf = SampleBuffer(capacity=4)
    y = np.arange(13.0)
    buf.add(0.0, 1e-20, y, 1.0, 2.0)
    k = 10
    t = np.column_stack([np.arange(1, k + 1, dtype=float), np.zeros(k)])
    Y = np.tile(y, (k, 1)) + np.arange(1, k + 1)[:, None]
    E = np.column_stack([np.ones(k), np.full(k, 2.0)])
    buf.extend(t, Y, E)
    buf.add(11.0, 0.0, y + 11, 1.0, 2.0)
    a = buf.arrays()
    assert len(buf) == 12
    np.testing.assert_array_equal(a["t"], np.arange(12.0))
    assert a["t_lo"][0] == 1e-20
    np.testing.assert_array_equal(a["states"][:, 0], np.arange(12.0))
    np.testing.assert_array_equal(a["states"][:, 12], 12.0 + np.arange(12.0))
