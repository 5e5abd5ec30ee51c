"""The impact-law registry (reference/core/laws.py): every consumer reads it, and the
recipe of docs/architecture.md ("Adding an impact law") adds a law with its function and
one entry, reached by the core's dispatch."""

from __future__ import annotations

import importlib
import inspect
import re
import sys
from pathlib import Path

import numpy as np
import pytest

from reference.core import laws
from reference.core.impact_laws import SETTLED
from reference.core.law_dispatch import dispatcher, law_function
from reference.core.records import LawWork
from reference.scene import IMPACT_LAWS, SceneError, check_impact_law
from tests.oracle.lcp import moreau_lcp

ROOT = Path(__file__).resolve().parent.parent
SECTION = "### Adding an impact law"


# the sequential law's cap on single impacts, in the scratch and in the core's call alike
MAX_HITS = 1000


def _work(k, law=None):
    """The law's scratch for k contacts (its entry's work_size; 2k floats by default)."""
    vec = np.zeros(laws.work_floats(law, k) if law is not None else 2 * k)
    return LawWork(np.zeros((k, k)), vec, np.zeros(k, dtype=np.int64),
                   np.zeros(0, dtype=np.int64), 0, MAX_HITS)  # fmt: skip


def _system(seed=0, k=3):
    """A random positive definite W and approaching u⁻."""
    rng = np.random.default_rng(seed)
    G = rng.normal(size=(k, k + 2))
    return G @ G.T + 0.1 * np.eye(k), -rng.uniform(0.1, 1.0, size=k)


def _recipe_blocks():
    """The two python blocks of the docs' recipe: the function's file, the entry."""
    text = (ROOT / "docs" / "architecture.md").read_text()
    section = text[text.index(SECTION) :]
    section = section[: section.index("\n### ", len(SECTION))]
    return re.findall(r"```python\n(.*?)```", section, flags=re.S)


def test_every_law_has_a_unique_name_and_code_and_a_function_of_the_signature():
    assert len(set(laws.LAW_NAMES)) == len(laws.LAWS)
    assert len({x.code for x in laws.LAWS}) == len(laws.LAWS)
    assert laws.law_code("paper") == laws.LAW_PAPER
    for law in laws.resolving_laws():
        fn = law_function(law).py_func
        assert tuple(inspect.signature(fn).parameters) == laws.LAW_ARGUMENTS


def test_the_scene_the_cli_and_branches_read_the_registry():
    from harness.cli import build_parser

    assert IMPACT_LAWS == laws.LAW_NAMES
    for name in laws.LAW_NAMES:
        assert check_impact_law(name) == name
    with pytest.raises(SceneError, match="impact_law"):
        check_impact_law("newton")
    parser = build_parser()
    sub = next(a for a in parser._actions if a.dest == "command")
    action = next(a for a in sub.choices["simulate"]._actions if a.dest == "impact_law")
    assert tuple(action.choices) == laws.LAW_NAMES
    for law in laws.LAWS:
        assert law.help in laws.law_help()


def _impact_through_the_core(scene, law):
    """The compiled core's multi-contact impact (`multi_impact`, the path the event loop
    runs: its law dispatch included) on every contact of `scene`, the body tilted and
    falling: (W, u⁻, λ, u⁺, status, whether the bounces were completed)."""
    from reference.compiled import function
    from reference.geometry import initial_state
    from reference.simulate import model_record

    y = initial_state(scene.initial).copy()
    y[3:7] = [np.cos(0.002), np.sin(0.002), 0.0, 0.0]  # tilted about x by 0.004 rad
    y[7:10], y[10:13] = [0.1, -0.2, -1.0], [0.3, -0.1, 0.2]
    k = scene.body.n
    W, chol = np.zeros((k, k)), np.zeros((k, k))
    u_pre, lam, u_post = np.zeros(k), np.zeros(k), np.zeros(k)
    vec = np.zeros(laws.work_floats(law, k))
    active, result = np.zeros(k, dtype=np.int64), np.zeros(3, dtype=np.int64)
    pts = np.ascontiguousarray(scene.contacts.core_points, dtype=float)
    no_order = np.zeros(0, dtype=np.int64)
    function("multi_impact")(
        y, model_record(scene), pts, law.code, np.arange(k, dtype=np.int64), k, no_order, 0,
        MAX_HITS, 1e-6, W, u_pre, lam, u_post, chol, vec, active, result,
    )  # fmt: skip
    return W, u_pre, lam, u_post, result[0], bool(result[2])


def test_the_dispatch_reaches_each_registered_law_by_its_code():
    from reference.scenes import as_scene

    scene = as_scene("triangle-chatter")
    for law in laws.resolving_laws():
        W, u, lam, u_post, status, completed = _impact_through_the_core(scene, law)
        assert status == SETTLED and (u < 0).all()
        gamma = 0.0 if completed else scene.restitution
        lam2, u_post2 = np.zeros(len(u)), np.zeros(len(u))
        fn = law_function(law)
        assert fn(W, u, gamma, len(u), lam2, u_post2, _work(len(u), law))[0] == SETTLED
        assert np.array_equal(lam, lam2) and np.array_equal(u_post, u_post2), law.name


def test_the_documented_recipe_adds_a_law_the_dispatch_reaches(tmp_path, monkeypatch):
    """The docs' plastic law, built from its two blocks: its file as a module, its entry
    appended to the registry; the dispatch of the new registry gives the independent
    LCP's impulses with γ = 0, and the other laws still theirs."""
    source, entry = _recipe_blocks()
    module = tmp_path / "plastic_recipe.py"
    module.write_text(source)
    monkeypatch.syspath_prepend(str(tmp_path))
    plastic = importlib.import_module("plastic_recipe")
    law = eval(entry.strip(), {"ImpactLaw": laws.ImpactLaw})  # noqa: S307 (the docs' entry)
    assert law.impulses.split(":")[1] == "plastic_law"
    registry = laws.with_law(law._replace(impulses=plastic.plastic_law))
    assert laws.law_names(registry) == (*laws.LAW_NAMES, "plastic")
    assert law.help in laws.law_help(registry)
    with pytest.raises(ValueError, match="already registered"):
        laws.with_law(law, registry)
    solve = dispatcher(registry)
    W, u = _system(1)
    lam, u_post = np.zeros(3), np.zeros(3)
    assert solve(law.code, W, u, 0.5, 3, lam, u_post, _work(3)) == (SETTLED, 1)
    oracle = moreau_lcp(W, u, 0.0)
    assert lam == pytest.approx(oracle.impulses, rel=1e-10)
    assert u_post == pytest.approx(np.zeros(3), abs=1e-12)
    moreau = laws.law_code("moreau")
    assert solve(moreau, W, u, 0.5, 3, lam, u_post, _work(3)) == (SETTLED, 1)
    assert lam == pytest.approx(moreau_lcp(W, u, 0.5).impulses, rel=1e-10)
    sys.modules.pop("plastic_recipe", None)
