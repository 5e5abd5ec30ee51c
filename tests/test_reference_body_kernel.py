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
