"""Build the core ahead of time: `python -m reference.core.aot` (`--part _aot` or
`--part _aot_rows` for one of its two modules: `make setup` builds them side by side; the
package's build step, setup.py, calls `build` too, so `pip install .`, `pip install -e .`
and `pip wheel .` carry the same modules).  numba.pycc compiles the event loop
`loop.run_events` into reference/core/_aot*.so, and the row-wise functions of `arrays`
and `multi_impact.multi_impact` into reference/core/_aot_rows*.so (each with everything
it calls), and writes a stamp of the core's sources beside each (reference.compiled
ignores the modules once the sources change).  Needs a C compiler; without one (or
without numba.pycc) the functions are compiled just in time on first use instead.  Why
pycc: docs/development.md."""

from __future__ import annotations

import sys
import textwrap
import time
import warnings
from pathlib import Path

from numba import from_dtype, types

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


def build(part: str, output_dir: Path = CORE_DIR) -> Path:
    """Compile the module `part` (reference.compiled.AOT_PARTS) into output_dir and write
    its stamp there; returns the module's path.  The module already there goes first: a
    failed build leaves none (of older sources) behind."""
    from reference.compiled import AOT_PARTS, jit_function, source_stamp, stamp_file

    output_dir.mkdir(parents=True, exist_ok=True)
    stamp = output_dir / stamp_file(part).name
    for old in [*output_dir.glob(f"{part}.*.so"), output_dir / f"{part}.so", stamp]:
        old.unlink(missing_ok=True)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # pycc announces its pending deprecation
        from numba.pycc import CC

    cc = CC(part)
    cc.output_dir = str(output_dir)
    cc.verbose = False
    sigs = signatures()
    for name in AOT_PARTS[part]:
        cc.export(name, sigs[name])(jit_function(name).py_func)
    cc.compile()
    stamp.write_text(source_stamp() + "\n")
    return output_dir / cc.output_file


def signature_counts() -> dict[str, int]:
    """The number of signatures numba has compiled of each core function compiled in
    this process, by "module.function" (after `build`: everything under the exported
    functions; a function inlined by numba, jit.hot_inline, has none of its own)."""
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


BUILDING = {  # what each module holds, and how long it takes to build on one core
    "_aot": ("the reference's event loop", "about 2–3 min"),
    "_aot_rows": ("the core's row-wise functions and multi-contact impact", "about 40 s"),
}


def build_or_explain(part: str, output_dir: Path = CORE_DIR) -> Path | None:
    """`build`, timed and announced; when it cannot be done (no C compiler, no
    numba.pycc) one line on stderr says so and None is returned: the core is then
    compiled just in time on first use."""
    t0 = time.perf_counter()
    what, how_long = BUILDING[part]
    print(f"building {what} ahead of time ({how_long}) ...", flush=True)
    try:
        path = build(part, output_dir)
    except Exception as exc:  # any failure: the loop is compiled just in time instead
        reason = " ".join(f"{type(exc).__name__}: {exc}".split())  # one line
        print(f"ahead-of-time build skipped ({reason}); the core will be compiled just in "
              "time on first use", file=sys.stderr)  # fmt: skip
        return None
    print(f"built {path.name} in {time.perf_counter() - t0:.0f} s", flush=True)
    print(textwrap.fill(repeated_signatures(signature_counts()), 100), flush=True)
    return path


def main(argv: list[str] | None = None) -> int:
    """Build each module (`--part NAME`: that one) unless it is already fresh beside the
    sources (`--force`: always)."""
    from reference.compiled import AOT_PARTS, fresh_aot_module

    args = sys.argv[1:] if argv is None else argv
    parts = list(AOT_PARTS)
    if "--part" in args:
        i = args.index("--part") + 1
        if i >= len(args) or args[i] not in AOT_PARTS:
            print(f"--part: one of {', '.join(AOT_PARTS)}", file=sys.stderr)
            return 2
        parts = [args[i]]
    for part in parts:
        if "--force" not in args and fresh_aot_module(part) is not None:
            print(f"the reference's ahead-of-time module {part} is up to date", flush=True)
        else:
            build_or_explain(part)
    return 0


if __name__ == "__main__":
    sys.exit(main())
