"""Scratch space of one run of the event loop, allocated once: a records.SCRATCH record
(fixed-size arrays: contact systems, DOP853 stages, event states and lists) and the
per-contact lists below (their size is the number of contacts)."""

from collections import namedtuple

import numpy as np
from numba import njit

ContactLists = namedtuple(
    "ContactLists",
    [
        "cand",  # (n,) the free contacts a contact step examines
        "gap",  # (n,) their jets, in the order of cand
        "rate",
        "accel",
        "noise",
        "together",  # (n,) contacts reached together, landing, pushed, crossed
        "hitting",  # (n,) contacts hitting
        "near",  # (n,) contacts approaching within the gap resolution, watched
    ],
)


@njit(cache=True)
def new_contact_lists(n):
    return ContactLists(
        np.empty(n, dtype=np.int64),
        np.empty(n),
        np.empty(n),
        np.empty(n),
        np.empty(n),
        np.empty(n, dtype=np.int64),
        np.empty(n, dtype=np.int64),
        np.empty(n, dtype=np.int64),
    )
