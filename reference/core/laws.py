"""The registry of impact laws: what every part of the project reads the laws from.

A law is one `ImpactLaw` entry of `LAWS`: its name (the scene's `impact_law`, the CLI's
`--impact-law`, `ReferenceOptions.impact_law`, `harness branches`, the linear model),
its integer code (the core's `model.law`), a one-line help text, and where its compiled
function lives ("module:function" under reference.core): the function that maps the
touching contacts' Delassus matrix W, their normal velocities u⁻ and the restitution γ
to impulses.  `paper` has none: the loop's own events are the paper's rule, and a
simultaneous impact ends the run there.

Every law function has one signature (LAW_ARGUMENTS):

    impulses(W, u_pre, gamma, k, lam, u_post, work) -> (status, single impacts)

W[:k, :k] and u_pre[:k] in; lam[:k] (Λ ≥ 0) and u_post[:k] (u⁻ + WΛ) out; `work` a
records.LawWork of scratch arrays and the law's settings (the function allocates
nothing); status one of impact_laws.SETTLED / NOT_SETTLED / SINGULAR / TOO_MANY.  The
core dispatches on the code through `law_dispatch.solve_law`, built from LAWS, so that
adding a law is its function and its entry here (docs/architecture.md, "Adding an
impact law").  This module imports nothing compiled: the scene, the options and the
CLI read it without loading numba.
"""

from collections import namedtuple

# A law: name, integer code (model.law), help text, "module:function" of its compiled
# impulse function under reference.core (None: the paper's rule, the loop's events);
# optional: `separating` (the impact takes the touching contacts that separate too: the
# others can push them back) and `work_size` ("module:function" k → floats of scratch
# `work.vec` it needs; None: 2k).
ImpactLaw = namedtuple(
    "ImpactLaw",
    ["name", "code", "help", "impulses", "separating", "work_size"],
    defaults=(False, None),
)

# the law functions' arguments, in order
LAW_ARGUMENTS = ("W", "u_pre", "gamma", "k", "lam", "u_post", "work")

LAWS = (
    ImpactLaw(
        "paper", 0,
        "the paper's rule: a simultaneous impact ends the run simultaneous_impact",
        None,
    ),
    ImpactLaw(
        "moreau", 1,
        "Moreau's frictionless law over every touching contact (least-norm impulses)",
        "impact_laws:moreau_law",
    ),
    ImpactLaw(
        "sequential", 2,
        "single impacts one contact at a time, the fastest approach first",
        "impact_laws:sequential_law",
    ),
    ImpactLaw(
        "compliant", 3,
        "the rigid limit of a spring and dashpot at every touching contact, one stiffness",
        "compliant:compliant_law", separating=True, work_size="compliant:work_size",
    ),
    ImpactLaw(
        "compliant-mass", 4,
        "compliant, each contact's stiffness in its effective mass",
        "compliant:compliant_mass_law", separating=True, work_size="compliant:work_size",
    ),
)  # fmt: skip

LAW_PAPER = 0
DEFAULT_LAW = "paper"


def law_names(laws=LAWS):
    """The laws' names, in registry order."""
    return tuple(law.name for law in laws)


def law_code(name, laws=LAWS):
    """The integer code of the law called `name` (ValueError if there is none)."""
    return law_of_name(name, laws).code


def law_help(laws=LAWS):
    """'name: help; …' of every law (the CLI's help text)."""
    return "; ".join(f"{law.name}: {law.help}" for law in laws)


def resolving_laws(laws=LAWS):
    """The laws that resolve a simultaneous impact (every one with a function)."""
    return tuple(law for law in laws if law.impulses is not None)


def law_of(code, laws=LAWS):
    """The registry entry of the law with integer code `code`."""
    for law in laws:
        if law.code == code:
            return law
    raise KeyError(code)


def work_floats(law, k):
    """Floats of `work.vec` scratch the law needs for k contacts (at least 2k)."""
    if law.work_size is None:
        return 2 * k
    if callable(law.work_size):
        return max(2 * k, int(law.work_size(k)))
    import importlib

    module, name = law.work_size.split(":")
    size = getattr(importlib.import_module(f"reference.core.{module}"), name)(k)
    return max(2 * k, int(size))


def law_of_name(name, laws=LAWS):
    """The registry entry of the law called `name` (ValueError naming the laws if none)."""
    for law in laws:
        if law.name == name:
            return law
    raise ValueError(f"impact law must be one of {', '.join(law_names(laws))}, got {name!r}")


def with_law(law, laws=LAWS):
    """`laws` with `law` added (its name and code new)."""
    if law.name in law_names(laws) or law.code in {x.code for x in laws}:
        raise ValueError(f"law {law.name!r} (code {law.code}) is already registered")
    return (*laws, law)


LAW_NAMES = law_names()
