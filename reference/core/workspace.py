"""Scratch arrays of one run of the event loop, allocated once."""

from collections import namedtuple

import numpy as np
from numba import njit

from .dop853 import new_stepper
from .held import new_work

Workspace = namedtuple(
    "Workspace",
    [
        "work",  # held.Work: contact systems of up to three contacts
        "stepper",  # dop853.Stepper
        "gap",  # (n,) jets of every contact
        "rate",
        "accel",
        "noise",
        "held",  # (n,) bool: held contacts
        "together",  # (n,) contacts reached together / landing
        "cand",  # (4,) candidate contacts of an impact or activation
        "active",  # (4,) the LCP's answer
        "y_event",  # (13,) scratch states
        "y_chunk",
        "y_start",
        "atol",  # (13,) absolute tolerances of a chunk
    ],
)


@njit(cache=True)
def new_workspace(n):
    return Workspace(
        new_work(),
        new_stepper(),
        np.empty(n),
        np.empty(n),
        np.empty(n),
        np.empty(n),
        np.zeros(n, dtype=np.bool_),
        np.empty(n, dtype=np.int64),
        np.empty(4, dtype=np.int64),
        np.empty(4, dtype=np.int64),
        np.empty(13),
        np.empty(13),
        np.empty(13),
        np.empty(13),
    )
