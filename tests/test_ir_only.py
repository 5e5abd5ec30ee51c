"""reference.core.ir_only: numba compiling to LLVM IR without machine code or cache, for
the ahead-of-time build; afterwards, functions compile and run as usual."""

import importlib.util
import sys

import pytest
from numba import float64, njit
from numba.core.compiler_lock import global_compiler_lock

from reference.core import ir_only

pytestmark = pytest.mark.skipif(not ir_only.available(), reason="numba lacks the parts")

CACHED_SOURCE = """
from numba import njit

@njit(cache=True)
def cube(x):
    return x * x * x
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


def _machine_code(function):
    """The object code numba's MCJIT generated for the function's one overload (numba
    keeps it, CodeLibrary._compiled_object, to cache it), None if none was generated."""
    (result,) = function.overloads.values()
    return result.library._compiled_object


def test_inside_functions_compile_to_ir_only_and_their_entry_points_raise_type_error():
    half, half_plus_one = _fresh_functions()
    with ir_only.ir_only():
        half_plus_one.compile((float64,))
        (result,) = half_plus_one.overloads.values()
        with global_compiler_lock:  # finalised, its callee linked in, as pycc does
            result.library.finalize()
        ir = result.library.get_llvm_str()
        assert _machine_code(half_plus_one) is None and _machine_code(half) is None
        with pytest.raises(TypeError):
            half_plus_one(3.0)
    assert "half_plus_one" in ir and "fmul" in ir and "fadd" in ir


def test_on_leaving_the_overloads_are_dropped_and_calls_compile_as_usual():
    half, half_plus_one = _fresh_functions()
    with ir_only.ir_only():
        half_plus_one.compile((float64,))
    assert not half_plus_one.overloads and not half.overloads
    assert half_plus_one(3.0) == 2.5
    assert _machine_code(half_plus_one) is not None


def test_inside_numbas_cache_is_not_written_and_outside_it_is(tmp_path, monkeypatch):
    (tmp_path / "cubed.py").write_text(CACHED_SOURCE)
    monkeypatch.syspath_prepend(str(tmp_path))
    spec = importlib.util.spec_from_file_location("cubed", tmp_path / "cubed.py")
    module = importlib.util.module_from_spec(spec)
    monkeypatch.setitem(sys.modules, "cubed", module)
    spec.loader.exec_module(module)
    cache_dir = tmp_path / "__pycache__"
    with ir_only.ir_only():
        module.cube.compile((float64,))
    assert not list(cache_dir.glob("cubed.cube-*.nbc"))
    assert module.cube(2.0) == 8.0
    assert list(cache_dir.glob("cubed.cube-*.nbc"))


def test_the_replaced_methods_are_numbas_own_again_after_leaving():
    from numba.core import caching, codegen, cpu, dispatcher

    methods = [
        codegen.JITCodeLibrary._finalize_specific,
        cpu.CPUContext.get_executable,
        caching.Cache.load_overload,
        caching.Cache.save_overload,
        dispatcher.Dispatcher.add_overload,
    ]
    with ir_only.ir_only():
        assert cpu.CPUContext.get_executable is not methods[1]
    assert methods == [
        codegen.JITCodeLibrary._finalize_specific,
        cpu.CPUContext.get_executable,
        caching.Cache.load_overload,
        caching.Cache.save_overload,
        dispatcher.Dispatcher.add_overload,
    ]
