"""Which part of a full bake's error at the solver bench's probes moves between two builds.

    .venv/bin/python scripts/bench_lib/compare.py SCENE EXE_A EXE_B [VAR=VALUE ...]
        [--work DIR]

Bakes SCENE (one of the bench's scenes) full and direct-only with each build (B under the
environment variables given), and prints each build's relative RMS error against the
Cycles references of `scripts/bench --solvers-only` (made in DIR if missing), the errors of
each build's direct light with the other's indirect light, and the probes that moved most.
"""
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
    name, a_exe, b_exe = argv[:3]
    b_env = dict(x.split("=", 1) for x in argv[3:])
    rf = Reference(name, "solvers", a_exe, sys.executable, work, Config(True))
    pm, pp, px = rf.probes
    res = {}
    for tag, exe, env in [("a", a_exe, {}), ("b", b_exe, b_env)]:
        old = dict(os.environ)
        os.environ.update(env)
        for kind, st in [("full", {}), ("direct", {"indirect": False})]:
            rec, bake = penumbra_job.run_cli(exe, rf.scene, work, f"compare-{tag}-{kind}", st,
                                             keep=False)
            res[tag, kind] = penumbra_job.colors_at(bake, pm, pp, px)
            print(tag, kind, "wall", round(rec["wall"], 2), "N_e", bake["stats"]["N_e"],
                  flush=True)
        os.environ.clear()
        os.environ.update(old)

    def e(x):
        return errors.errors(x, rf.ref, rf.noise)["rel_rms"]

    print("full a", e(res["a", "full"]), "full b", e(res["b", "full"]))
    print("b's direct + a's indirect", e(res["b", "direct"] + res["a", "full"] - res["a", "direct"]))
    print("a's direct + b's indirect", e(res["a", "direct"] + res["b", "full"] - res["b", "direct"]))
    ref = rf.ref
    moved = np.abs(res["b", "full"] - res["a", "full"]).max(axis=1) / np.maximum(ref.mean(axis=1), 1e-9)
    names = [m["name"] for m in rf.scene["meshes"]]
    for k in np.argsort(-moved)[:15]:
        print(names[pm[k]], pp[k], np.round(px[k], 3), "ref", np.round(ref[k].mean(), 4),
              "a", np.round(res["a", "full"][k].mean(), 4),
              "b", np.round(res["b", "full"][k].mean(), 4),
              "direct a/b", np.round(res["a", "direct"][k].mean(), 4),
              np.round(res["b", "direct"][k].mean(), 4))


if __name__ == "__main__":
    main(sys.argv[1:])
