"""The message of a run whose impact law left a simultaneous impact undecided: one
sentence for the exact core's runs (reference.simulate) and the linear model's
(reference.linear.segment) alike."""

from .impact_laws import MAX_LAW_CONTACTS, MAX_SEQUENTIAL_IMPACTS, NOT_SETTLED, SINGULAR, TOO_MANY
from .law_event import NO_PROGRESS


def undecided_message(law, outcome, t, contacts, hits=None):
    """Why the law called `law` left the simultaneous impact of `contacts` at t undecided
    (its function's status, impact_laws.NOT_SETTLED …, or law_event.NO_PROGRESS; `hits`:
    the single impacts it made, MAX_SEQUENTIAL_IMPACTS when not known): the message of
    the exact core's and the linear model's runs alike."""
    if outcome == NOT_SETTLED:
        hits = MAX_SEQUENTIAL_IMPACTS if hits is None else hits
        return (f"the {law} law did not settle after {hits} single impacts at t = {t:.17g} "
                f"(contacts {contacts}): undecidable")  # fmt: skip
    if outcome == SINGULAR:
        return f"a contact of {contacts} takes no impulse at t = {t:.17g}"
    if outcome == NO_PROGRESS:
        return f"the {law} law made no progress at t = {t:.17g}: stopped (undecidable)"
    if outcome == TOO_MANY:
        return (f"contacts touch at t = {t:.17g} beyond the {MAX_LAW_CONTACTS} the impact "
                "laws take (undecidable)")  # fmt: skip
    return f"the {law} law failed at t = {t:.17g} (contacts {contacts})"
