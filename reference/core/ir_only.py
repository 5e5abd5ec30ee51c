"""numba compiling to LLVM IR only, for the ahead-of-time build (`reference.core.aot`).

numba.pycc compiles each function that an exported function calls as numba's own
just-in-time function: numba lowers it to LLVM IR and optimises it (the IR that pycc
links into the module), and then also generates its machine code for this process (LLVM's
MCJIT) and writes both to numba's on-disk cache.  The build never runs that machine code
and never reads that cache entry: generating them took 35 s of a 149 s build
(docs/performance.md, "The core's build").  `ir_only()` leaves both out.

One difference follows, measured: MCJIT's code generation rewrites a library's IR in place
(LLVM's CodeGenPrepare) before numba links it into its callers, so with machine code
the module is built from callees' IR after that rewrite, and here from the IR as numba's
optimiser left it.  59 of the module's 930 functions come out a few hundred bytes apart
in size; the module's speed is the same (paired benchmark, docs/performance.md)."""

from __future__ import annotations

import ctypes
from contextlib import contextmanager


def _numba_parts():
    """numba's classes that `ir_only` replaces methods of, or None where this numba
    lacks one of them (numba/core/codegen.py, cpu.py, caching.py, dispatcher.py)."""
    try:
        from numba import _dynfunc
        from numba.core import caching, codegen, cpu, dispatcher
    except ImportError:
        return None
    parts = {
        (codegen.JITCodeLibrary, "_finalize_specific"),
        (cpu.CPUContext, "get_executable"),
        (caching.Cache, "load_overload"),
        (caching.Cache, "save_overload"),
        (dispatcher.Dispatcher, "add_overload"),
    }
    has_all = all(hasattr(cls, name) for cls, name in parts)
    if not (has_all and hasattr(_dynfunc, "make_function")):
        return None
    return codegen, cpu, caching, dispatcher, _dynfunc


def available() -> bool:
    """Whether this numba has the parts `ir_only` replaces."""
    return _numba_parts() is not None


# The entry point given to a function compiled without machine code: CPython's
# PyObject_Call, which has the signature numba's entry points have (self, args, kwargs)
# and, called with numba's closure object as `self`, raises TypeError (the closure is
# not callable) instead of jumping to code that does not exist.
_RAISING_ENTRY = ctypes.cast(ctypes.pythonapi.PyObject_Call, ctypes.c_void_p).value


@contextmanager
def ir_only():
    """Inside: numba's just-in-time libraries are finalised without machine code, each
    compiled function's entry point raises TypeError when called, and numba's on-disk
    cache is neither read nor written (what is compiled depends on the sources alone).
    On leaving, the overloads compiled inside are dropped, so that a later call
    compiles its function as usual.  Raises RuntimeError where this numba lacks the
    parts replaced (`available()`)."""
    parts = _numba_parts()
    if parts is None:
        raise RuntimeError("this numba lacks the internals that ir_only replaces")
    codegen, cpu, caching, dispatcher, dynfunc = parts
    compiled = set()
    add_overload = dispatcher.Dispatcher.add_overload

    def recording_add_overload(self, cres):
        compiled.add(self)
        add_overload(self, cres)

    def placeholder_executable(self, library, fndesc, env):
        name = fndesc.qualname.split(".")[-1]
        doc = "compiled to LLVM IR only (reference.core.ir_only): not callable"
        return dynfunc.make_function(
            fndesc.lookup_module(), name, doc, _RAISING_ENTRY, env, (library,)
        )

    replaced = {
        (codegen.JITCodeLibrary, "_finalize_specific"): lambda self: None,
        (cpu.CPUContext, "get_executable"): placeholder_executable,
        (caching.Cache, "load_overload"): lambda self, sig, target_context: None,
        (caching.Cache, "save_overload"): lambda self, sig, data: None,
        (dispatcher.Dispatcher, "add_overload"): recording_add_overload,
    }
    # each class's own method (None: the method is inherited, and put back by deleting
    # the replacement)
    originals = {(cls, name): vars(cls).get(name) for cls, name in replaced}
    try:
        for (cls, name), method in replaced.items():
            setattr(cls, name, method)
        yield
    finally:
        for (cls, name), method in originals.items():
            if method is None:
                delattr(cls, name)
            else:
                setattr(cls, name, method)
        for function in compiled:
            function._reset_overloads()
