"""Whether a run follows the reference, judged on its impacts: it reproduces at least
MATCH_FRACTION of the reference's first LEADING_IMPACTS impacts, in order (same contact,
time within the matching window of harness.metrics.matching).  The fidelity study's
criterion (harness.fidelity.criteria, whose thresholds are these by default) and the
test of `bench`'s summary: a run that lost the reference after one impact has errors of
that one impact only, which say nothing of its accuracy."""

from __future__ import annotations

LEADING_IMPACTS = 10
MATCH_FRACTION = 0.9


def impacts_pass(matched: int, leading: int, match_fraction: float = MATCH_FRACTION) -> bool:
    """matched / leading ≥ match_fraction (with leading ≥ 1)."""
    return leading > 0 and matched >= match_fraction * leading - 1e-9


def follows_reference(matched: int, reference_impacts: int) -> bool:
    """The run matched ≥ MATCH_FRACTION of the reference's first LEADING_IMPACTS impacts
    (of all of them when it has fewer; a reference without impacts is followed)."""
    if reference_impacts == 0:
        return True
    return impacts_pass(matched, min(LEADING_IMPACTS, reference_impacts))
