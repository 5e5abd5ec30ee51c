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
        # a simultaneous impact under an impact law (reference.core.law_event), for up
        # to K contacts (K = 1 under `paper`, which never uses them): three arrays
        # (records.new_law_arrays), sliced where they are used (`law_lists`), so that
        # the lists every event function passes grow by three arrays only
        "law_mats",  # (2K, K) W, the law's factor
        "law_vecs",  # (5K,) u⁻, Λ, u⁺, the law's scratch (2K)
        "law_ints",  # (3K + m,) contacts, active set, order positions, the order (m)
    ],
)


@njit(cache=True)
def contact_lists(ints, floats, law_mats, law_vecs, law_ints):
    """ContactLists as rows of the caller's arrays (records.new_contact_arrays, rows in
    the order of records.CONTACT_INT_ROWS and CONTACT_FLOAT_ROWS; records.new_law_arrays);
    compiled with numba's reference counting, as the loop's entry point is, since the
    rows are views."""
    return ContactLists(
        ints[0], floats[0], floats[1], floats[2], floats[3], ints[1], ints[2], ints[3],
        law_mats, law_vecs, law_ints,
    )  # fmt: skip
