"""Every array of the linear model's runs of the check scenes, compared between two
versions (bit for bit, else the largest relative difference).

    PYTHONPATH=/work/main python benchmarks/linear_runs.py dump before.pkl paper
    PYTHONPATH=$PWD python benchmarks/linear_runs.py dump after.pkl paper
    python benchmarks/linear_runs.py compare before.pkl after.pkl

The scenes: benchmarks/event_times.py's check scenes the linear model covers, and four
of its own undecidable starts (a triangle and a hexagon landing flat, a triangle
landing on an edge beside its held vertex, two vertices 1e-10 apart in time with a
window of 1e-9).  LAWS (comma-separated) are run on each; `scene` keeps the scene's
own.  Per run: the LinearRun's 19 arrays (rows, times, impulses, velocities, energies,
states), status, reason, message, impacts, t_singularity and the simultaneous impacts
the law resolved.  Times are compared as t_hi + t_lo; a run one END row longer after a
last IMPACT row is compared on the common rows and said so.
"""

from __future__ import annotations

import pickle
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

FIELDS = (
    "kind contact contact2 held dt log2_dt t_hi t_lo impulse v_pre v_post energy_pre "
    "energy_post log2_energy q_pre p_pre q_post p_post acc"
).split()
SCALARS = ("status", "reason", "message", "n_impacts", "t_sing", "simultaneous")
STATES = ("q_pre", "p_pre", "q_post", "p_post", "acc")


def _scene(n, gamma, q, window=0.0):
    from reference.scene import scene_from_dict

    return scene_from_dict({
        "restitution": gamma, "simultaneity_window": window,
        "body": {"n": n, "radius": 1.0, "mass": 1.0, "gyration": 0.5},
        "ground": {"kind": "flat"}, "initial": {"q": list(q), "p": [0.0, 0.0, 0.0]},
        "run": {"t_end": 5.0, "max_impacts": 100_000},
    })  # fmt: skip


def scenes() -> dict:
    from event_times import check_scenes

    from reference.linear.model import LinearModel

    out = dict(check_scenes())
    q = np.linalg.solve(LinearModel.polygon(3, 0.5, 0.5).F, [0.02, 0.01, 0.01 + 1e-10])
    out["flat n=3"] = _scene(3, 0.6, (0, 0, 0.02))
    out["flat n=6"] = _scene(6, 0.6, (0, 0, 0.02))
    out["edge beside a held vertex"] = _scene(3, 0.5, (0.0, 0.02, 0.02))
    out["window 1e-9"] = _scene(3, 0.5, q, window=1e-9)
    return out


def record(scene) -> dict:
    """The run's arrays and outcome (run_linear's LinearRun, as simulate_linear runs it)."""
    import reference.linear.simulate as S

    runs = []
    run_linear = S.run_linear

    def keep(*args, **kwargs):
        runs.append(run_linear(*args, **kwargs))
        return runs[-1]

    S.run_linear = keep
    try:
        traj = S.simulate_linear(scene)
    finally:
        S.run_linear = run_linear
    run = runs[-1]
    out = {f: None if getattr(run, f) is None else np.array(getattr(run, f)) for f in FIELDS}
    out.update(status=run.status.value, reason=run.reason, message=run.message,
               n_impacts=run.n_impacts, t_sing=traj.t_singularity,
               simultaneous=(traj.stats or {}).get("simultaneous_impacts"))  # fmt: skip
    return out


def dump(path: str, laws: list[str]) -> None:
    out = {}
    for name, scene in scenes().items():
        for law in laws:
            key = f"{name} | {law}"
            try:
                out[key] = record(scene if law == "scene" else scene.with_impact_law(law))
            except Exception as e:  # a scene the linear model does not cover
                out[key] = {"error": repr(e)}
                continue
            print(f"{key:44s} {out[key]['status']:20s} {out[key]['n_impacts']:7d}")
    Path(path).write_bytes(pickle.dumps(out))


def _rel(u, v, field) -> float:
    """Largest |u − v| relative to max(|u|, |v|) (to the array's largest for states)."""
    scale = np.maximum(np.abs(u), np.abs(v))
    if field in STATES:
        scale = np.maximum(scale, np.abs(u).max())
    with np.errstate(invalid="ignore"):  # inf − inf where both are inf
        d = np.abs(u - v) / np.where(scale > 0, scale, 1.0)
    return float(d[np.isfinite(d)].max(initial=0.0))


def differences(x: dict, y: dict) -> tuple[list[str], float]:
    n = len(x["kind"])
    longer = len(y["kind"]) == n + 1 and x["kind"][-1] == 1 and y["kind"][-1] == 3
    said, worst = ["(+1 END row)"] if longer else [], 0.0
    for f in FIELDS:
        u, v = x[f], y[f]
        if u is None or v is None:
            if (u is None) != (v is None):
                said.append(f"{f}: recorded in one only")
            continue
        if f == "t_lo":
            u, v = x["t_hi"] + x["t_lo"], y["t_hi"] + y["t_lo"]
        v = v[:n] if longer else v
        if u.shape != v.shape:
            said.append(f"{f}: shape {u.shape} -> {v.shape}")
        elif not np.array_equal(u, v, equal_nan=True):
            if u.dtype.kind != "f" or not np.array_equal(np.isfinite(u), np.isfinite(v)):
                said.append(f"{f}: differs")
                continue
            r = _rel(u, v, f)
            worst = max(worst, r)
            said.append(f"{f}: {r:.2e}")
    for s in SCALARS:
        if x[s] != y[s] and not (s == "simultaneous" and x[s] is None):
            said.append(f"{s}: {x[s]!r} -> {y[s]!r}")
    return said, worst


def compare(a: str, b: str) -> int:
    """Print each run's differences; returns 1 when a run differs or is missing, else 0."""
    A, B = pickle.loads(Path(a).read_bytes()), pickle.loads(Path(b).read_bytes())
    runs = same = arrays = values = failed = 0
    worst = 0.0
    for key, x in A.items():
        y = B.get(key)
        if y is None or "error" in x or "error" in y:
            if x != y:
                failed += 1
                print(f"{key:44s} {x.get('error')} -> {y and y.get('error')}")
            continue
        runs += 1
        arrays += sum(x[f] is not None for f in FIELDS)
        values += sum(x[f].size for f in FIELDS if x[f] is not None)
        said, w = differences(x, y)
        worst = max(worst, w)
        same += not said
        print(f"{key:44s} {'same' if not said else ' '.join(said)}")
    print(f"{same} of {runs} runs bit-identical ({arrays} arrays, {values} values); "
          f"largest relative difference {worst:.3g}")  # fmt: skip
    return int(failed > 0 or same < runs)


if __name__ == "__main__":
    if len(sys.argv) >= 3 and sys.argv[1] == "dump":
        dump(sys.argv[2], (sys.argv[3] if len(sys.argv) > 3 else "paper").split(","))
    elif len(sys.argv) == 4 and sys.argv[1] == "compare":
        sys.exit(compare(sys.argv[2], sys.argv[3]))
    else:
        print(__doc__)
        sys.exit(2)
