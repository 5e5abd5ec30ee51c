"""ImpactLog and PhaseLog: the array-backed stores read like the lists they replace."""

from __future__ import annotations

import numpy as np
import pytest

from reference.trajectory import ImpactEvent, ImpactLog, Phase, PhaseLog


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


def test_impact_log_from_rows_equals_the_events():
    ev = _events(5)
    rows = [[e.t, e.t_lo, e.contact, e.impulse, e.v_normal_pre, e.v_normal_post] for e in ev]
    assert list(ImpactLog.from_rows(np.array(rows))) == ev


def test_phase_log_reads_rows_as_phases():
    rows = np.array([[0.0, 0.5, 0, -1, -1, -1], [0.5, 0.75, 1, 2, 4, -1]])
    log = PhaseLog(rows)
    assert list(log) == [Phase(0.0, 0.5, "flight", ()), Phase(0.5, 0.75, "contact", (2, 4))]
    assert log[-1].contacts == (2, 4) and len(log) == 2 and log[:1] == [log[0]]
