"""Build the core ahead of time: `python -m reference.core.aot` (run by `make setup`; the
package's build step, setup.py, calls `build` too, so `pip install .`, `pip install -e .`
and `pip wheel .` carry the same module).  numba.pycc compiles the event loop
`loop.run_events` and the row-wise functions of `arrays` (and everything they call) into
the extension module reference/core/_aot*.so, and a stamp of the core's sources is
written beside it (reference.compiled ignores the module once the sources change).
Needs a C compiler; without one (or without numba.pycc) the functions are compiled just
in time on first use instead.  Why pycc: docs/development.md."""

from __future__ import annotations

import contextlib
import os
import shutil
import sys
import tempfile
import textwrap
import threading
import time
import warnings
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

from numba import from_dtype, types

from ..process_exit import exit_now

CORE_DIR = Path(__file__).resolve().parent


def signatures() -> dict:
    """The exported functions (reference.compiled.EXPORTS) and their signatures."""
    from . import records as R

    def rec(dtype):
        return types.Array(from_dtype(dtype), 1, "C")

    f2 = types.Array(types.float64, 2, "C")
    f1 = types.Array(types.float64, 1, "C")
    i2 = types.Array(types.int64, 2, "C")
    i1 = types.Array(types.int64, 1, "C")
    f8, i8, void = types.float64, types.int64, types.void
    return {
        "run_events": types.int64(rec(R.RUN), f2, f2, f2, f2, f2, f2, f1, i2, f2, f2, f1, i1),
        "quaternion_product_rows": void(f2, f2, f2),
        "quaternion_exp_rows": void(f2, f2),
        "quaternion_log_rows": void(f2, f2),
        "rotate_rows": void(f2, f2, f2),
        "tilt_rows": void(f2, f1),
        "axis_rows": void(f2, f2),
        "contact_kinematics_rows": void(f2, f2, f2, f2),
        "energy_rows": void(f2, i8, f8, f8, f8, f8, f2),
        "free_acceleration_rows": void(f2, f8, f8, f8, f2),
        "length_scale_rows": void(f2, f8, f1),
        "multi_impact": void(
            f1, rec(R.MODEL), f2, i8, i1, i8, i1, i8, i8, f8, f2, f1, f1, f1, f2, f1, i1, i1
        ),
    }


# The event loop's own layers: only the loop calls their functions, through the module,
# so the build compiles them to LLVM IR only (reference.core.ir_only), without the
# machine code and numba-cache entries that nothing would load.  The functions of the
# other core modules keep both: the linear kernel's warm-up and the tests load them
# from numba's cache (the laws, the integrator, the flight search, the helpers tests
# call as the loop does).
LOOP_LAYERS = frozenset(
    f"reference.core.{name}" for name in ("loop", "phases", "events", "law_event", "multi_impact")
)


def in_loop_layers(module: str, qualname: str) -> bool:
    """Whether a function compiled by the build is one of the loop's own layers."""
    return module in LOOP_LAYERS


def build(output_dir: Path = CORE_DIR) -> Path:
    """Compile the module into output_dir and write its stamp there; returns the
    module's path.  Any module already there goes first: a failed build leaves none (of
    older sources) behind."""
    return build_counting(output_dir)[0]


def build_counting(output_dir: Path = CORE_DIR) -> tuple[Path, dict[str, int]]:
    """`build`, and the signatures compiled of each core function (`signature_counts`).
    The loop's own layers are compiled to LLVM IR only (LOOP_LAYERS), where this numba
    allows it, and each inlined function's untyped IR is built once
    (`inline_once.callee_ir_once`)."""
    from reference.compiled import STAMP_FILE, jit_function, source_stamp

    from . import ir_only
    from .inline_once import callee_ir_once

    output_dir.mkdir(parents=True, exist_ok=True)
    for old in [*output_dir.glob("_aot*.so"), output_dir / STAMP_FILE.name]:
        old.unlink(missing_ok=True)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # pycc announces its pending deprecation
        from numba.pycc import CC

    cc = CC("_aot")
    cc.output_dir = str(output_dir)
    cc.verbose = False
    for name, sig in signatures().items():
        cc.export(name, sig)(jit_function(name).py_func)
    only_ir = ir_only.available()
    with (
        ir_only.ir_only(in_loop_layers) if only_ir else contextlib.nullcontext(),
        callee_ir_once(),
    ):
        compile_with_helpers_beside(cc)
        counts = signature_counts()
    (output_dir / STAMP_FILE.name).write_text(source_stamp() + "\n")
    return output_dir / cc.output_file, counts


# what compile_with_helpers_beside uses of numba.pycc's CC (numba/pycc/cc.py, CC.compile)
_CC_PARTS = ("_compile_object_files", "_compile_mixins", "_toolchain", "_get_extra_ldflags")


def compile_with_helpers_beside(cc) -> None:
    """`cc.compile()` with its two independent parts side by side.  numba.pycc compiles
    the module's object file (numba and LLVM, in this process: nearly all the build)
    and then the C helpers that numba's code needs (the C compiler, ~5 s), one after
    the other, and links them.  Here the helpers compile in a thread whose compiler
    processes run at the lowest priority, so that they take a core only when one is
    idle (under `make setup` the other core installs the packages meanwhile, then
    idles): they are ready by the time the object file is.  Where this numba's CC lacks
    the parts used here, `cc.compile()` runs as it is."""
    if not all(hasattr(cc, part) for part in _CC_PARTS):
        cc.compile()
        return
    cc._toolchain.verbose = cc.verbose
    build_dir = tempfile.mkdtemp(prefix=f"pycc-build-{cc.name}-")
    try:
        with ThreadPoolExecutor(1) as pool:
            helpers = pool.submit(_at_lowest_priority, cc._compile_mixins, build_dir)
            objects, exports = cc._compile_object_files(build_dir)
            objects += helpers.result()
        cc._toolchain.link_shared(
            os.path.join(cc.output_dir, cc.output_file),
            objects,
            cc._toolchain.get_python_libraries(),
            cc._toolchain.get_python_library_dirs(),
            export_symbols=exports,
            extra_ldflags=cc._get_extra_ldflags(),
        )
    finally:
        shutil.rmtree(build_dir, ignore_errors=True)


def _at_lowest_priority(fn, *args):
    """fn(*args) with this thread (and the processes it starts) at nice 19, where the
    system allows it (Linux: a thread's nice value is its own, and its children
    inherit it)."""
    try:
        os.setpriority(os.PRIO_PROCESS, threading.get_native_id(), 19)
    except (AttributeError, OSError):  # no setpriority (Windows), or a thread id refused
        pass
    return fn(*args)


def signature_counts() -> dict[str, int]:
    """The number of signatures numba has compiled of each core function compiled in
    this process, by "module.function" (at the end of `build_counting`: everything under
    the exported functions; a function inlined by numba, jit.hot_inline, has none of its
    own)."""
    from numba.core.registry import CPUDispatcher

    counts = {}
    for name, module in sorted(sys.modules.items()):
        if not name.startswith("reference.core."):
            continue
        for attr, value in vars(module).items():
            compiled = isinstance(value, CPUDispatcher) and value.overloads
            if compiled and value.__module__ == name:
                counts[f"{name.rsplit('.', 1)[1]}.{attr}"] = len(value.overloads)
    return counts


def repeated_signatures(counts: dict[str, int]) -> str:
    """One line: how many functions and signatures were compiled, and the functions
    compiled more than once (jit.py: each signature compiles the function and all it
    calls again)."""
    repeated = {k: n for k, n in counts.items() if n > 1}
    line = f"{len(counts)} functions, {sum(counts.values())} signatures"
    if not repeated:
        return line + "; each function compiled once"
    listed = ", ".join(f"{k} ×{n}" for k, n in sorted(repeated.items()))
    return f"{line}; compiled more than once: {listed}"


def build_or_explain(output_dir: Path = CORE_DIR) -> Path | None:
    """`build`, timed and announced; when it cannot be done (no C compiler, no
    numba.pycc) one line on stderr says so and None is returned: the loop is then
    compiled just in time on first use."""
    t0 = time.perf_counter()
    print("building the reference's event loop ahead of time (about 2 min) ...", flush=True)
    try:
        path, counts = build_counting(output_dir)
    except Exception as exc:  # any failure: the loop is compiled just in time instead
        reason = " ".join(f"{type(exc).__name__}: {exc}".split())  # one line
        print(f"ahead-of-time build skipped ({reason}); the loop will be compiled just in "
              "time on first use", file=sys.stderr)  # fmt: skip
        return None
    print(f"built {path.name} in {time.perf_counter() - t0:.0f} s", flush=True)
    print(textwrap.fill(repeated_signatures(counts), 100), flush=True)
    return path


def main(argv: list[str] | None = None) -> int:
    """Build unless the module beside the sources is already fresh (`--force`: always)."""
    from reference.compiled import fresh_aot_module

    args = sys.argv[1:] if argv is None else argv
    if "--force" not in args and fresh_aot_module() is not None:
        print("the reference's ahead-of-time module is up to date", flush=True)
        return 0
    build_or_explain()
    return 0


if __name__ == "__main__":
    exit_now(main())
