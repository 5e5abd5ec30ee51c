"""reference.core.ir_only: the functions it selects compile to LLVM IR without module
passes, machine code or cache entry, the others as usual; afterwards, everything
compiles and runs as usual."""

import importlib.util
import re
import sys

import numba.core.config
import pytest
from numba import float64, njit
from numba.core.compiler_lock import global_compiler_lock

from reference.core import ir_only
from reference.core.aot import in_loop_layers

pytestmark = pytest.mark.skipif(not ir_only.available(), reason="numba lacks the parts")

CACHED_SOURCE = """
from numba import njit

@njit(cache=True)
def cube(x):
    return x * x * x

@njit(cache=True)
def square(x):
    return x * x
"""


def _fresh_functions():
    """A caller and its callee, new to numba (nothing compiled, nothing cached)."""

    @njit
    def half(x):
        return 0.5 * x

    @njit
    def half_plus_one(x):
        return half(x) + 1.0

    return half, half_plus_one


def _everything(module, qualname):
    return True


def _halves(module, qualname):
    return qualname.endswith(".half")


def _machine_code(function):
    """The object code numba's MCJIT generated for the function's one overload (numba
    keeps it, CodeLibrary._compiled_object, to cache it), None if none was generated."""
    (result,) = function.overloads.values()
    return result.library._compiled_object


def test_selected_functions_compile_to_ir_only_and_their_entry_points_raise_type_error():
    half, half_plus_one = _fresh_functions()
    with ir_only.ir_only(_everything):
        half_plus_one.compile((float64,))
        (result,) = half_plus_one.overloads.values()
        with global_compiler_lock:  # finalised, its callee linked in, as pycc does
            result.library.finalize()
        ir = result.library.get_llvm_str()
        assert _machine_code(half_plus_one) is None and _machine_code(half) is None
        with pytest.raises(TypeError):
            half_plus_one(3.0)
    assert "half_plus_one" in ir and "fmul" in ir and "fadd" in ir


# a call to `half` (numba's mangled name: ...4half followed by its ABI tag or arguments)
CALL_TO_HALF = re.compile(r"call [^\n]*@\"?_ZN[^ \"(]*4half[BE]")


def _finalised_ir(function):
    """The LLVM IR of the function's one overload, finalised (its callees linked in), as
    pycc links it."""
    (result,) = function.overloads.values()
    with global_compiler_lock:
        result.library._ensure_finalized()
    return result.library.get_llvm_str()


def test_a_selected_library_is_linked_unoptimised_and_optimised_where_it_is_linked():
    half, half_plus_one = _fresh_functions()
    with ir_only.ir_only(_everything):
        half_plus_one.compile((float64,))
        ir_only_ir = _finalised_ir(half_plus_one)
    assert CALL_TO_HALF.search(ir_only_ir)  # no module passes: `half` not inlined
    half, half_plus_one = _fresh_functions()
    with ir_only.ir_only(_halves):  # the caller left out is optimised as usual
        half_plus_one.compile((float64,))
        optimised_ir = _finalised_ir(half_plus_one)
    assert not CALL_TO_HALF.search(optimised_ir) and "fmul" in optimised_ir


def test_a_caller_left_out_runs_with_its_selected_callee_linked_in():
    half, half_plus_one = _fresh_functions()
    with ir_only.ir_only(_halves):
        assert half_plus_one(3.0) == 2.5
        assert _machine_code(half_plus_one) is not None
        assert _machine_code(half) is None  # not generated with its caller's either
        with pytest.raises(TypeError):
            half(3.0)


def test_on_leaving_the_selected_overloads_are_dropped_and_calls_compile_as_usual():
    half, half_plus_one = _fresh_functions()
    with ir_only.ir_only(_halves):
        half_plus_one.compile((float64,))
    assert not half.overloads and len(half_plus_one.overloads) == 1
    assert half(3.0) == 1.5 and half_plus_one(3.0) == 2.5
    assert _machine_code(half) is not None


def _powers_module(tmp_path, monkeypatch):
    """CACHED_SOURCE imported afresh (new dispatchers) from tmp_path, with numba's cache
    in tmp_path for this test alone; returns the module and the cache's folder."""
    cache_dir = tmp_path / "numba-cache"
    monkeypatch.setattr(numba.core.config, "CACHE_DIR", str(cache_dir))
    if not (tmp_path / "powers.py").exists():
        (tmp_path / "powers.py").write_text(CACHED_SOURCE)
    spec = importlib.util.spec_from_file_location("powers", tmp_path / "powers.py")
    module = importlib.util.module_from_spec(spec)
    monkeypatch.setitem(sys.modules, "powers", module)
    spec.loader.exec_module(module)
    return module, cache_dir


def _cubes(module, qualname):
    return qualname == "cube"


def test_inside_only_the_functions_left_out_are_cached(tmp_path, monkeypatch):
    module, cache_dir = _powers_module(tmp_path, monkeypatch)
    with ir_only.ir_only(_cubes):
        module.cube.compile((float64,))
        module.square.compile((float64,))
    assert not list(cache_dir.rglob("powers.cube-*.nbc"))
    assert list(cache_dir.rglob("powers.square-*.nbc"))
    assert module.cube(2.0) == 8.0
    assert list(cache_dir.rglob("powers.cube-*.nbc"))


def test_with_load_cached_the_functions_left_out_are_read_from_the_cache_never_the_selected(
    tmp_path, monkeypatch
):
    module, _ = _powers_module(tmp_path, monkeypatch)
    assert module.cube(2.0) == 8.0 and module.square(2.0) == 4.0  # both cached
    module, _ = _powers_module(tmp_path, monkeypatch)
    with ir_only.ir_only(_cubes):  # the ahead-of-time build's way: nothing read
        module.square.compile((float64,))
    assert not module.square._cache_hits
    module, _ = _powers_module(tmp_path, monkeypatch)
    with ir_only.ir_only(_cubes, load_cached=True):
        module.square.compile((float64,))
        module.cube.compile((float64,))
        assert _machine_code(module.cube) is None  # compiled to IR, not read
    assert sum(module.square._cache_hits.values()) == 1
    assert not module.cube._cache_hits


def test_the_replaced_methods_are_numbas_own_again_after_leaving():
    from numba.core import caching, codegen, cpu, dispatcher

    def methods():
        return [
            codegen.JITCPUCodegen._add_module,
            cpu.CPUContext.get_executable,
            caching.Cache.load_overload,
            caching.Cache.save_overload,
            dispatcher.Dispatcher.add_overload,
            codegen.CPUCodeLibrary._optimize_final_module,
        ]

    before = methods()
    with ir_only.ir_only(_everything):
        assert all(a is not b for a, b in zip(methods(), before, strict=True))
    assert methods() == before


def test_the_linear_kernel_selects_its_functions_that_python_does_not_call():
    from reference.linear import kernel as K

    selected = K.compiled_into_entry_points
    for helper in ("_law_event", "_step", "_law_impulses", "_held_solve", "_two_sum"):
        assert selected(K.__name__, helper)
    for entry in ("start_kernel", "continue_kernel", "first_hit", "_contact_products"):
        assert not selected(K.__name__, entry)
    assert not selected("reference.core.impact_laws", "_law_event")


def test_the_build_selects_the_loops_layers_and_not_what_tests_load_from_the_cache():
    assert in_loop_layers("reference.core.phases", "contact_step")
    assert in_loop_layers("reference.core.loop", "run_steps")
    for module in ("impact_laws", "compliant", "dop853", "search", "held", "contacts"):
        assert not in_loop_layers(f"reference.core.{module}", "f")
