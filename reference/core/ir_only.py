"""numba compiling chosen functions to LLVM IR only, for the ahead-of-time build
(`reference.core.aot`, which chooses the event loop's own layers: `aot.LOOP_LAYERS`)
and for the linear model's kernel (`reference.linear.kernel.load_entry_points`, which
chooses every function of the kernel that Python does not call).

numba.pycc compiles each function that an exported function calls as numba's own
just-in-time function: lowered to LLVM IR, its library optimised whole (LLVM's module
passes, inlining included) after linking in its callees' libraries, then turned into
machine code for the build's process (LLVM's MCJIT) and written, with that machine code,
to numba's on-disk cache.  pycc links the libraries into the module and optimises the
module once more.  `ir_only(selected)` leaves out, for the functions it is given:

- the machine code and the cache entry.  The build runs none of that machine code.  Of
  the cache entries, the linear kernel's warm-up and the tests load those of the laws,
  the integrator, the flight search and the helpers tests call as the loop does; those
  of the loop's own layers, which only the loop calls, nothing loads.
- the module passes.  Run in every layer's library, they optimise each layer again in
  every layer above it (56 s of a build's LLVM time); left to the library that links
  them, pycc's module, they run once over everything (18.7 s in all).  The module runs
  the same number of instructions as one built with every layer optimised (callgrind
  over the benchmark's cases).

A chosen function's library is never handed to MCJIT, whose code generation would also
rewrite its IR in place (LLVM's CodeGenPrepare) before its callers link it, so the module
is built from that function's IR as numba's function passes left it.  docs/performance.md
("Where the set-up's time goes") has the measurements."""

from __future__ import annotations

import ctypes
from contextlib import contextmanager


def _numba_parts():
    """numba's modules whose classes `ir_only` replaces methods of, or None where this
    numba lacks one of the methods (`_replacements` names them: numba/core/codegen.py,
    cpu.py, caching.py, dispatcher.py) or `_dynfunc.make_function`."""
    try:
        from numba import _dynfunc
        from numba.core import caching, codegen, cpu, dispatcher
    except ImportError:
        return None
    parts = codegen, cpu, caching, dispatcher, _dynfunc
    try:  # the replacements read the methods they replace
        replaced = _replacements(parts, lambda module, qualname: False, set(), set(), False)
    except AttributeError:
        return None
    has_all = all(hasattr(cls, name) for cls, name in replaced)
    return parts if has_all and hasattr(_dynfunc, "make_function") else None


def available() -> bool:
    """Whether this numba has the parts `ir_only` replaces."""
    return _numba_parts() is not None


# The entry point given to a function compiled without machine code: CPython's
# PyObject_Call, which has the signature numba's entry points have (self, args, kwargs)
# and, called with numba's closure object as `self`, raises TypeError (the closure is
# not callable) instead of jumping to code that does not exist.
_RAISING_ENTRY = ctypes.cast(ctypes.pythonapi.PyObject_Call, ctypes.c_void_p).value


@contextmanager
def ir_only(selected, load_cached: bool = False):
    """Inside, for each function that numba compiles and `selected(module, qualname)`
    accepts: its library is finalised without module passes or machine code, its entry
    point raises TypeError when called, and it is not written to numba's on-disk cache.
    The other functions compile as usual, with machine code, and are cached (a selected
    callee's IR linked into theirs and optimised there).  A selected function is never
    read from numba's cache inside; the others are where `load_cached` (the linear
    kernel's entry points, `reference.linear.kernel.load_entry_points`), and
    otherwise not, so that what is compiled depends on the sources alone (the
    ahead-of-time build).  On leaving, the overloads of the selected functions are
    dropped, so that a later call compiles them as usual.  Raises RuntimeError where
    this numba lacks the parts replaced (`available()`)."""
    parts = _numba_parts()
    if parts is None:
        raise RuntimeError("this numba lacks the internals that ir_only replaces")
    ir_libraries = set()  # the libraries of the selected functions
    placeholders = set()  # the dispatchers holding a placeholder entry point
    methods = _replacements(parts, selected, ir_libraries, placeholders, load_cached)
    with _replaced(methods):
        try:
            yield
        finally:
            for function in placeholders:
                function._reset_overloads()


def _replacements(parts, selected, ir_libraries, placeholders, load_cached) -> dict:
    """numba's methods that `ir_only` replaces, by (class, name), and their
    replacements; `ir_libraries` and `placeholders` are filled as functions compile."""
    codegen, cpu, caching, dispatcher, dynfunc = parts
    add_module = codegen.JITCPUCodegen._add_module
    get_executable = cpu.CPUContext.get_executable
    load_overload = caching.Cache.load_overload
    save_overload = caching.Cache.save_overload
    add_overload = dispatcher.Dispatcher.add_overload
    optimize_final_module = codegen.CPUCodeLibrary._optimize_final_module

    def add_module_for_machine_code(self, module):
        # a selected library's module is kept from MCJIT, which generates the machine
        # code of every module it holds when a library is finalised
        if not any(module is library._final_module for library in ir_libraries):
            return add_module(self, module)
        return None

    def optimize_unless_ir_only(self):
        # a selected library's module passes are left to the library that links it: run
        # at every layer, they would optimise each callee again in each of its callers
        if self not in ir_libraries:
            optimize_final_module(self)

    def placeholder_executable(self, library, fndesc, env):
        if not selected(fndesc.modname, fndesc.qualname):
            return get_executable(self, library, fndesc, env)
        ir_libraries.add(library)
        name = fndesc.qualname.split(".")[-1]
        doc = "compiled to LLVM IR only (reference.core.ir_only): not callable"
        return dynfunc.make_function(
            fndesc.lookup_module(), name, doc, _RAISING_ENTRY, env, (library,)
        )

    def load_unless_selected(self, sig, target_context):
        function = getattr(self, "_py_func", None)  # numba's Cache keeps its function
        if function is None or not load_cached:
            return None
        if selected(function.__module__, function.__qualname__):
            return None
        return load_overload(self, sig, target_context)

    def save_with_machine_code(self, sig, data):
        if data.library not in ir_libraries:
            save_overload(self, sig, data)

    def recording_add_overload(self, cres):
        if cres.library in ir_libraries:
            placeholders.add(self)
        add_overload(self, cres)

    return {
        (codegen.JITCPUCodegen, "_add_module"): add_module_for_machine_code,
        (cpu.CPUContext, "get_executable"): placeholder_executable,
        (caching.Cache, "load_overload"): load_unless_selected,
        (caching.Cache, "save_overload"): save_with_machine_code,
        (dispatcher.Dispatcher, "add_overload"): recording_add_overload,
        (codegen.CPUCodeLibrary, "_optimize_final_module"): optimize_unless_ir_only,
    }


@contextmanager
def _replaced(methods: dict):
    """The classes' methods replaced inside (`methods`: (class, name) → function), and
    put back on leaving: a class's own method set again, an inherited one uncovered by
    deleting the replacement."""
    originals = {(cls, name): vars(cls).get(name) for cls, name in methods}
    try:
        for (cls, name), method in methods.items():
            setattr(cls, name, method)
        yield
    finally:
        for (cls, name), method in originals.items():
            if method is None:
                delattr(cls, name)
            else:
                setattr(cls, name, method)
