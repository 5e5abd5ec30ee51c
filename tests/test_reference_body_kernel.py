"""The compiled flat-ground contact kinematics equal the array expressions they replace."""

from __future__ import annotations

import numpy as np
import pytest

import reference.body as body
from reference.body import BodyModel, initial_state
from reference.contact import contact_system
from reference.scene import Body, Ground, InitialState, RunSettings, Scene


def _model_and_state(n: int):
    scene = Scene(
        name="tumbling",
        body=Body(n=n, gyration=0.45),
        ground=Ground(),
        initial=InitialState(
            (0.1, -0.2, 0.3), (0.2, -0.1, 0.7), (0.3, 0.1, -0.4), (1.1, -0.7, 2.3)
        ),
        restitution=0.5,
        gravity=9.81,
        run=RunSettings(t_end=1.0),
    )
    return BodyModel.from_scene(scene), initial_state(scene)


@pytest.mark.parametrize("n,idx", [(3, None), (7, [2]), (7, [1, 5]), (40, [0, 13, 39])])
def test_compiled_contacts_equal_the_array_expression(n, idx, monkeypatch):
    model, y = _model_and_state(n)
    fast = model.contacts(y, idx)
    monkeypatch.setattr(body, "COMPILED_KINEMATICS", False)
    slow = model.contacts(y, idx)
    for a, b in zip(fast, slow, strict=True):
        np.testing.assert_allclose(a, b, rtol=0, atol=4e-16)


@pytest.mark.parametrize("idx", [[2], [1, 5], [0, 3, 4]])
def test_compiled_contact_system_equals_the_array_expression(idx, monkeypatch):
    model, y = _model_and_state(7)
    fast = contact_system(model, y, idx)
    monkeypatch.setattr(body, "COMPILED_KINEMATICS", False)
    slow = contact_system(model, y, idx)
    for a, b in zip(fast, slow, strict=True):
        np.testing.assert_allclose(a, b, rtol=1e-14, atol=1e-14)


@pytest.mark.parametrize("k,watch", [(2, []), (1, [5]), (0, [3, 4]), (3, None)])
def test_compiled_impact_equals_the_array_expression(k, watch, monkeypatch):
    from reference.impact import impact_impulse

    model, y = _model_and_state(7)
    fast = impact_impulse(model, y, k, 0.6, watch=watch)
    monkeypatch.setattr(body, "COMPILED_KINEMATICS", False)
    slow = impact_impulse(model, y, k, 0.6, watch=watch)
    np.testing.assert_allclose(fast.y_post, slow.y_post, rtol=0, atol=1e-14)
    assert abs(fast.impulse - slow.impulse) <= 1e-14 * abs(slow.impulse)
    assert abs(fast.u_post + 0.6 * fast.u_pre) <= 1e-14 * abs(fast.u_pre)
    seen = list(range(7)) if watch is None else [k, *watch]
    np.testing.assert_allclose(fast.others_post[seen], slow.others_post[seen], rtol=0, atol=1e-14)


@pytest.mark.parametrize("contacts", [[2], [1, 5]])
def test_compiled_normal_impulses_equal_the_array_expression(contacts, monkeypatch):
    from reference.impact import apply_normal_impulses

    model, y = _model_and_state(7)
    target = np.array([0.3, -0.1][: len(contacts)])
    fast = apply_normal_impulses(model, y, contacts, target)
    np.testing.assert_allclose(model.contacts(fast, contacts)[3], target, rtol=0, atol=1e-14)
    monkeypatch.setattr(body, "COMPILED_KINEMATICS", False)
    slow = apply_normal_impulses(model, y, contacts, target)
    np.testing.assert_allclose(fast, slow, rtol=0, atol=1e-14)


def test_two_contact_lcp_in_closed_form_equals_the_enumeration():
    """_lcp_small against the generic enumeration of solve_contact_lcp on random
    positive definite 2 × 2 systems with every sign pattern of b."""
    from itertools import combinations

    from reference.contact import _lcp_small

    def enumerate_lcp(A, b):
        m = len(b)
        for size in range(m, -1, -1):
            for S in combinations(range(m), size):
                S = list(S)
                lam = np.zeros(m)
                if S:
                    lam[S] = np.linalg.solve(A[np.ix_(S, S)], -b[S])
                if np.any(lam[S] < 0):
                    continue
                an = A @ lam + b
                if all(an[i] >= 0 for i in range(m) if i not in S):
                    return [i for i in S if lam[i] > 0], lam
        raise AssertionError

    rng = np.random.default_rng(0)
    for _ in range(500):
        L = rng.normal(size=(2, 2))
        A = L @ L.T + 0.1 * np.eye(2)
        b = rng.normal(size=2)
        act, lam = enumerate_lcp(A, b)
        got, lam_got = _lcp_small([10, 11], A, b, 0.0)
        assert got == [10 + i for i in act]
        np.testing.assert_allclose(lam_got, lam[act], rtol=1e-12)
        one, _ = _lcp_small([7], A[:1, :1], b[:1], 0.0)
        assert one == ([7] if b[0] < 0 else [])
