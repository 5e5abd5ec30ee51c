"""Scratch space of one run of the event loop, allocated once: a records.SCRATCH record
(fixed-size arrays: contact systems, DOP853 stages, event states and lists) and the
per-contact lists below (their size is the number of contacts)."""

from collections import namedtuple

import numpy as np
from numba import njit

ContactLists = namedtuple(
    "ContactLists",
    [
        "gap",  # (n,) jets of every contact
        "rate",
        "accel",
        "noise",
        "held",  # (n,) bool: held contacts
        "together",  # (n,) contacts reached together, landing, pushed, crossed
        "hitting",  # (n,) contacts hitting
    ],
)


@njit(cache=True)
def new_contact_lists(n):
    return ContactLists(
        np.empty(n),
        np.empty(n),
        np.empty(n),
        np.empty(n),
        np.zeros(n, dtype=np.bool_),
        np.empty(n, dtype=np.int64),
        np.empty(n, dtype=np.int64),
    )
