"""Where a full bake's error at the solver bench's probes is, mesh by mesh.

    .venv/bin/python scripts/bench_lib/per_mesh.py SCENE EXE ['{"convergence": 3e-4}']
        [--work DIR]

Prints the relative RMS error against the Cycles references of `scripts/bench
--solvers-only`, then per mesh its probes, share of the squared error (reference noise
taken out), mean signed error, mean reference and mean direct light; then the worst probes
of the mesh with the largest share.
"""
import json
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))

import numpy as np  # noqa: E402

from bench_lib import errors, penumbra_job  # noqa: E402
from bench_lib.main import Config, work_arg  # noqa: E402
from bench_lib.reference import Reference  # noqa: E402


def main(argv):
    work, argv = work_arg(argv)
    name, exe = argv[:2]
    extra = json.loads(argv[2]) if len(argv) > 2 else {}
    rf = Reference(name, "solvers", exe, sys.executable, work, Config(True))
    pm, pp, px = rf.probes
    _, bake = penumbra_job.run_cli(exe, rf.scene, work, "per-mesh-full", extra, keep=False)
    x = penumbra_job.colors_at(bake, pm, pp, px)
    _, bd = penumbra_job.run_cli(exe, rf.scene, work, "per-mesh-direct", {"indirect": False},
                                 keep=False)
    xd = penumbra_job.colors_at(bd, pm, pp, px)
    ref, noise = rf.ref, rf.noise
    print("rel_rms", errors.errors(x, ref, noise)["rel_rms"])
    d2 = np.maximum(((x - ref) ** 2).mean(1) - noise.mean(1), 0)
    signed = (x - ref).mean(1)
    names = [m["name"] for m in rf.scene["meshes"]]
    rows = {}
    for k in range(len(pm)):
        r = rows.setdefault(names[pm[k]], [0, 0.0, 0.0, 0.0, 0.0])
        r[0] += 1
        r[1] += d2[k]
        r[2] += signed[k]
        r[3] += ref[k].mean()
        r[4] += xd[k].mean()
    order = sorted(rows.items(), key=lambda kv: -kv[1][1])
    for nm, r in order[:15]:
        print(f"{nm:20s} n={r[0]:4d} share={r[1] / d2.sum():6.3f} "
              f"mean_signed={r[2] / r[0]:+.4f} mean_ref={r[3] / r[0]:.4f} "
              f"mean_direct={r[4] / r[0]:.4f}")
    worst = [k for k in range(len(pm)) if names[pm[k]] == order[0][0]]
    worst.sort(key=lambda k: -d2[k])
    for k in worst[:25]:
        print(pp[k], np.round(px[k], 3), "ref", round(ref[k].mean(), 4), "ours",
              round(x[k].mean(), 4), "direct", round(xd[k].mean(), 4))


if __name__ == "__main__":
    main(sys.argv[1:])
