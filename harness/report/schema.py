"""What `harness report` reads from each kind of result document, checked before any HTML
is built: every field a section uses, with its type.  A document that lacks one or holds
the wrong type is refused with one line naming the field (`check_document`), instead of
failing deep inside a table or a figure.

Specs: "str", "num" (int or float, not bool), "int", "bool", "any", "link" (a file path
or an http(s) URL: no other scheme, harness.report.links); `Opt(spec)` also allows null;
a dict is an object whose keys must be present (a key ending in "?" may be absent); a
one-element list is a list of items of that spec; `Each(spec)` an object of any keys
whose values follow spec.  Fields the report does not read are not checked.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from .links import link_problem


@dataclass(frozen=True)
class Opt:
    spec: Any


@dataclass(frozen=True)
class Each:
    spec: Any


class SchemaError(ValueError):
    """`field` (a path such as engines[0].status) is missing or of the wrong type."""

    def __init__(self, field: str, problem: str):
        super().__init__(f"field {field}: {problem}")
        self.field = field


NUM = Opt("num")
QUANTILES = Opt(["num"])
HORIZON = Opt(
    {
        "matched_quantiles?": QUANTILES,
        "within?": Opt("bool"),
        "own_error?": NUM,
        "own_error_quantiles?": QUANTILES,
        "lyapunov_per_impact?": NUM,
        "sentence?": Opt("str"),
    }
)
PROVENANCE = Opt({"command?": "str", "created?": "str", "host?": "str", "versions?": Each("any")})
EXPONENT = Opt({"c?": NUM})
# compare: the branch a run follows after the reference's undecidable state
BRANCH = Opt(
    {
        "branch": "str",
        "law": "str",
        "impacts": "int",
        "skipped": "int",
        "of": "int",
        "until": NUM,
        "distance": NUM,
        "decided": "bool",
        "sentence?": Opt("str"),
        "candidates": [{"branch": "str", "distance": NUM}],
    }
)

COMPARE = {
    "scene": "str",
    "restitution?": NUM,
    "reference": {
        "status": "str",
        "t_final": NUM,
        "n_impacts?": Opt("int"),
        "wall_time_s?": NUM,
        "exponent?": EXPONENT,
    },
    "engines": [
        {
            "engine": "str",
            "dt": NUM,
            "status": "str",
            "impacts_matched": "int",
            "reference_impacts": "int",
            "first_divergence_time": NUM,
            "energy_error_agreeing": NUM,
            "impact_time_error": NUM,
            "wall_time_s": NUM,
            "verdict?": Opt("str"),
            "exponent?": EXPONENT,
            "horizon?": HORIZON,
            "branch?": BRANCH,
        }
    ],
    "first_to_diverge?": Opt({"why": "str"}),
    "recording?": Opt("link"),
}

BENCH = {
    "scene": "str",
    "t_end": "num",
    "truth": {"setting": "str", "status": "str", "impacts": "int"},
    "repeats": "int",
    "budget_s": "num",
    "results": [
        {
            "engine": "str",
            "setting": "str",
            "status": "str",
            "dt": NUM,
            "contact_rtol": NUM,
            "wall_time_s": NUM,
            "impacts_matched": "int",
            "reference_impacts": "int",
            "impact_time_error": NUM,
            "energy_error": NUM,
            "energy_error_agreeing": NUM,
        }
    ],
    "skipped?": [{"engine": "str", "setting": "str", "reason": "str"}],
    "derived?": Each(Each(Each("any"))),
    "load?": Opt({"before?": Opt(["num"]), "after?": Opt(["num"])}),
}

FIDELITY_STAR_BOUND = {
    "bound": "str",
    "alpha_star": NUM,
    "alpha_lowest_pass": NUM,
    "alpha_below_lowest_pass": NUM,
}
FIDELITY_STAR = {
    "horizon?": FIDELITY_STAR_BOUND,
    "engine": "str",
    "dt": NUM,
    "bound": "str",
    "alpha_star": NUM,
    "alpha_lowest_pass": NUM,
    "alpha_below_lowest_pass": NUM,
}
FIDELITY = {
    "scene": "str",
    "scaling": "str",
    "window": "str",
    "criteria": {"leading": "int", "match_fraction": "num"},
    "engines": ["str"],
    "eps": ["num"],
    "reference": [
        {
            "eps": "num",
            "alpha": "num",
            "status": "str",
            "impacts": "int",
            "leading": "int",
            "leading_t_last_scaled": NUM,
            "c": NUM,
            "same_contacts_as_first": Opt("bool"),
            "scaled_time_shift": NUM,
        }
    ],
    "runs": [
        {
            "engine": "str",
            "dt": NUM,
            "eps": "num",
            "alpha": "num",
            "leading": "int",
            "passes": Opt("bool"),
            "skipped": Opt("str"),
            "leading_matched?": Opt("int"),
            "match_fraction?": NUM,
            "c_check?": Opt("str"),
            "status?": Opt("str"),
        }
    ],
    "alpha_star": [FIDELITY_STAR],
    "fits": [{"engine": "str", "k": NUM, "k_stderr": NUM, "lowest?": Opt(Each("any"))}],
}

STRESS = {
    "dt": "num",
    "budget_s": "num",
    "cases": [
        {
            "case": "str",
            "engine": "str",
            "verdict": "str",
            "status": Opt("str"),
            "reason?": Opt("str"),
            "energy_gain": NUM,
            "missed_impacts": Opt("int"),
            "spurious_impacts": Opt("int"),
        }
    ],
}

SWEEP = {
    "engine": "str",
    "n": "int",
    "manifest": {
        "n": "int",
        "gyration": ["num"],
        "restitution": ["num"],
        "samples": "int",
        "seed": "int",
        "engine": "str",
        "dt": NUM,
        "t_end": "num",
    },
    "grid": {"restitution": ["num"], "gyration": ["num"], "samples": "int", "seed": "int"},
    "tasks": {"rows": "int", "total": "int"},
    "counts?": Each("int"),
    "mean_c?": NUM,
    "points": [
        {
            "restitution": "num",
            "gyration": "num",
            "runs": "int",
            "n_c": "int",
            "mean_c": NUM,
            "std_c": NUM,
            "frac_simultaneous": NUM,
        }
    ],
}

RESTITUTION_ROW = {
    "geometry": "str",
    "dt": NUM,
    "phase?": NUM,
    "gamma": "num",
    "speed": "num",
    "u_pre": NUM,
    "e_eff": NUM,
    "e_error": NUM,
    "faithful": Opt("bool"),
    "energy_change": NUM,
    "energy_loss_exact": NUM,
    "energy_gained": Opt("bool"),
    "penetration": NUM,
    "contact_time": NUM,
    "outcome": "str",
    "applicable?": Opt("bool"),
}
RESTITUTION = {
    "faithful": "num",
    "grid": {
        "gamma": ["num"],
        "speed": ["num"],
        "geometry": ["str"],
        "phase?": ["num"],
    },
    "engines": [
        {
            "rows": [RESTITUTION_ROW],
            "contract": [{"dt": NUM, "geometry": "str", "range": "any"}],
        }
    ],
}

SCHEMAS = {
    "compare": COMPARE,
    "bench": BENCH,
    "fidelity": FIDELITY,
    "stress": STRESS,
    "sweep": SWEEP,
    "restitution": RESTITUTION,
}


def check_document(doc: Any, kind: str) -> None:
    """SchemaError naming the first field of `doc` that its kind's schema refuses."""
    _check(doc, {**SCHEMAS[kind], "provenance?": PROVENANCE}, "")


def _check(value: Any, spec: Any, where: str) -> None:
    if isinstance(spec, Opt):
        if value is not None:
            _check(value, spec.spec, where)
    elif isinstance(spec, str):
        _check_scalar(value, spec, where)
    elif isinstance(spec, list):
        if not isinstance(value, list):
            raise SchemaError(where, f"a list expected, got {_kind(value)}")
        for k, item in enumerate(value):
            _check(item, spec[0], f"{where}[{k}]")
    elif isinstance(spec, Each):
        _check_object(value, where)
        for key, item in value.items():
            _check(item, spec.spec, _join(where, key))
    else:
        _check_object(value, where)
        for key, sub in spec.items():
            name = key.rstrip("?")
            if name not in value:
                if key.endswith("?"):
                    continue
                raise SchemaError(_join(where, name), "missing")
            _check(value[name], sub, _join(where, name))


def _check_object(value: Any, where: str) -> None:
    if not isinstance(value, dict):
        raise SchemaError(where or "(document)", f"an object expected, got {_kind(value)}")


def _check_scalar(value: Any, spec: str, where: str) -> None:
    ok = {
        "any": True,
        "str": isinstance(value, str),
        "link": isinstance(value, str),
        "bool": isinstance(value, bool),
        "int": isinstance(value, int) and not isinstance(value, bool),
        "num": isinstance(value, int | float) and not isinstance(value, bool),
    }[spec]
    if not ok:
        expected = {"num": "a number", "int": "an integer", "bool": "true or false"}
        raise SchemaError(where, f"{expected.get(spec, 'a string')} expected, got {_kind(value)}")
    if spec == "link":
        problem = link_problem(value)
        if problem:
            raise SchemaError(where, problem)


def _join(where: str, key: str) -> str:
    return f"{where}.{key}" if where else key


def _kind(value: Any) -> str:
    if value is None:
        return "null"
    return {bool: "true/false", int: "a number", float: "a number", str: "a string"}.get(
        type(value), {list: "a list", dict: "an object"}.get(type(value), type(value).__name__)
    )
