"""Build the core ahead of time: `python -m reference.core.aot` (run by `make setup`).
numba.pycc compiles the event loop `loop.run_events` and the row-wise functions of
`arrays` (and everything they call) into the extension module reference/core/_aot*.so,
and a stamp of the core's sources is written beside it (reference.compiled ignores the
module once the sources change).  Needs a C compiler; without one the functions are
compiled just in time on first use instead."""

from __future__ import annotations

import sys
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
    f8, i8, void = types.float64, types.int64, types.void
    return {
        "run_events": types.int64(rec(R.RUN), f2, f2, f2, f2, f2, f2, f1, i2, f2),
        "quaternion_product_rows": void(f2, f2, f2),
        "quaternion_exp_rows": void(f2, f2),
        "quaternion_log_rows": void(f2, f2),
        "rotate_rows": void(f2, f2, f2),
        "tilt_rows": void(f2, f1),
        "axis_rows": void(f2, f2),
        "contact_kinematics_rows": void(f2, f2, i8, f2, f2),
        "energy_rows": void(f2, i8, f8, f8, f8, f8, f2),
        "free_acceleration_rows": void(f2, f8, f8, f8, f2),
        "length_scale_rows": void(f2, f8, f1),
    }


def build() -> Path:
    """Compile the module and write its stamp; returns the module's path."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # pycc announces its pending deprecation
        from numba.pycc import CC

    from reference.compiled import STAMP_FILE, jit_function, source_stamp

    cc = CC("_aot")
    cc.output_dir = str(CORE_DIR)
    cc.verbose = False
    for name, sig in signatures().items():
        cc.export(name, sig)(jit_function(name).py_func)
    cc.compile()
    STAMP_FILE.write_text(source_stamp() + "\n")
    return next(CORE_DIR.glob("_aot*.so"))


def main() -> int:
    t0 = time.perf_counter()
    print("building the reference's event loop ahead of time (about a minute) ...", flush=True)
    try:
        path = build()
    except Exception as exc:  # no compiler: the loop is compiled just in time instead
        print(f"ahead-of-time build skipped ({type(exc).__name__}: {exc}); the loop will be "
              "compiled just in time on first use", file=sys.stderr)  # fmt: skip
        return 0
    print(f"built {path.name} in {time.perf_counter() - t0:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
