"""Scratch space of one run of the event loop, allocated once by the caller: a
records.SCRATCH record (fixed-size arrays: contact systems, DOP853 stages, event states
and lists) and the per-contact lists below (their size is the number of contacts), rows
of two arrays."""

from collections import namedtuple

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
def contact_lists(ints, floats):
    """ContactLists as rows of the caller's arrays (records.new_contact_arrays, rows in
    the order of records.CONTACT_INT_ROWS and CONTACT_FLOAT_ROWS); compiled with numba's
    reference counting, as the loop's entry point is, since the rows are views."""
    return ContactLists(
        ints[0], floats[0], floats[1], floats[2], floats[3], ints[1], ints[2], ints[3]
    )
