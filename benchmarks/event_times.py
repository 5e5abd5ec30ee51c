"""Event times of the 17 check scenes, compared bit for bit between two versions.

    PYTHONPATH=/work/main python benchmarks/event_times.py dump before.json
    PYTHONPATH=$PWD python benchmarks/event_times.py dump after.json
    python benchmarks/event_times.py compare before.json after.json

The check scenes: the ten built-in scenes (both grounds, the rod n = 2, chatter,
contact phases, grazing and near-simultaneous contacts) and seven generated ones from
`benchmarks/reference_speed.py` (tumbling n = 10 γ = 0 and n = 100 γ = 0.5 with contact
phases and chatter, n = 1000 γ = 1 with the vertex windows, the three-point ground at
γ = 0 and γ = 1 (whose rim reaches the floor plane 0.1 a under the bumps after 3
impacts: `left_model`; before that limit it left the bumps after 10), fast spin n = 16
γ = 1 and n = 100 γ = 0.5 (the circle step and the rim descent)).  Each run's impacts
(t, t_lo, contact, impulse, normal velocities), phases, status, final time and
t_singularity are written as the hex of their doubles, so `compare` is exact.  Only the
public API is used.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))


def check_scenes() -> dict:
    # the version on PYTHONPATH first: reference_speed puts its own tree on sys.path,
    # and the modules already imported are the ones it then uses
    from harness.scenes import builtin_names, resolve_scene

    # isort: split
    from reference_speed import fast_spin, tumbling

    out = {f"builtin {name}": resolve_scene(name) for name in builtin_names()}
    out["tumbling n=10 γ=0 flat"] = tumbling(10, 0.0)
    out["tumbling n=100 γ=0.5 flat"] = tumbling(100, 0.5)
    out["tumbling n=1000 γ=1 flat"] = tumbling(1000, 1.0)
    out["tumbling γ=0 three-point"] = tumbling(3, 0.0, "three_point")
    out["tumbling γ=1 three-point"] = tumbling(3, 1.0, "three_point")
    out["fast spin n=16 γ=1"] = fast_spin(16, 1.0)
    out["fast spin n=100 γ=0.5"] = fast_spin(100, 0.5)
    return out


def _hex(x) -> str:
    return "none" if x is None else float(x).hex()


def record(scene) -> dict:
    from reference.simulate import simulate

    traj = simulate(scene)
    return {
        "status": str(traj.status.value),
        "t_final": _hex(traj.t_final),
        "t_singularity": _hex(traj.t_singularity),
        "impacts": [
            [
                _hex(i.t),
                _hex(i.t_lo),
                int(i.contact),
                _hex(i.impulse),
                _hex(i.v_normal_pre),
                _hex(i.v_normal_post),
            ]  # fmt: skip
            for i in traj.impacts
        ],
        "phases": [[_hex(p.t_start), _hex(p.t_end), p.kind, list(p.contacts)] for p in traj.phases],
    }


def dump(path: str) -> None:
    scenes = check_scenes()
    out = {}
    for name, scene in scenes.items():
        out[name] = record(scene)
        print(f"{name:36s} {out[name]['status']:20s} {len(out[name]['impacts']):6d} impacts")
    Path(path).write_text(json.dumps(out))


def _first_difference(a: list, b: list) -> str:
    for i, (x, y) in enumerate(zip(a, b, strict=False)):
        if x != y:
            return f"row {i}: {x} vs {y}"
    return f"lengths {len(a)} vs {len(b)}"


def compare(path_a: str, path_b: str) -> int:
    a = json.loads(Path(path_a).read_text())
    b = json.loads(Path(path_b).read_text())
    bad = 0
    for name, ra in a.items():
        rb = b.get(name)
        diffs = [key for key in ra if rb is None or ra[key] != rb.get(key)]
        print(f"{name:36s} {'identical' if not diffs else 'DIFFERS: ' + ', '.join(diffs)}")
        for key in diffs:
            if rb is not None and isinstance(ra[key], list):
                print(f"    {key}: {_first_difference(ra[key], rb[key])}")
        bad += bool(diffs)
    print(f"{len(a) - bad} of {len(a)} scenes bit-identical")
    return 1 if bad else 0


if __name__ == "__main__":
    if len(sys.argv) == 3 and sys.argv[1] == "dump":
        dump(sys.argv[2])
    elif len(sys.argv) == 4 and sys.argv[1] == "compare":
        sys.exit(compare(sys.argv[2], sys.argv[3]))
    else:
        sys.exit(__doc__)
