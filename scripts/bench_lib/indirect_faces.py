"""Indirect light alone, face by face, against Cycles: where a bake is too dark or too bright.

    .venv/bin/python scripts/bench_lib/indirect_faces.py SCENE EXE ['{"convergence": 1e-4}']
        [--close] [--samples N] [--bounces N]

SCENE is a built-in scene name (`penumbra scene NAME`). `--close` adds a sixth wall to the
Cornell box (y = 0, facing in, albedo 0.73), so that no light leaves it. Indirect light is
taken as full bake minus direct-only bake, on both sides: Penumbra's two CLI bakes, and two
Cycles bakes (seeds 1 and 2, `--samples` each, default 512) of each kind at the probes, with
`--bounces` diffuse bounces (default 64; 2 compares with `max_shots: 1, ambient: false`).
The probes are the bench's at half its spacing. Cycles' bakes are kept under
target/bench-work/indirect-SCENE[-closed]/ and reused by later runs.

Prints the direct light's signed error per face (a check that what is subtracted is right),
then per face the indirect light's mean, signed error and the reference's standard error
(all in % of the face's mean indirect light), and the overall signed error.
"""
import argparse
import json
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))

import numpy as np  # noqa: E402

from bench_lib import penumbra_job, probes  # noqa: E402
from bench_lib.main import ROOT, Config, cycles  # noqa: E402


def close_box(scene):
    box = next(m for m in scene["meshes"] if m["name"] == "Box")
    base = len(box["positions"])
    box["positions"] += [[0, 0, 1], [1, 0, 1], [1, 0, 0], [0, 0, 0]]
    box["polygons"].append([base, base + 1, base + 2, base + 3])
    box["albedo"].append([0.73, 0.73, 0.73])


def main(argv):
    ap = argparse.ArgumentParser()
    ap.add_argument("scene")
    ap.add_argument("exe")
    ap.add_argument("settings", nargs="?", default="{}")
    ap.add_argument("--close", action="store_true")
    ap.add_argument("--samples", type=int, default=512)
    ap.add_argument("--bounces", type=int, default=64)
    a = ap.parse_args(argv)
    settings = json.loads(a.settings)
    work = os.path.join(ROOT, "target", "bench-work",
                        f"indirect-{a.scene}{'-closed' if a.close else ''}")
    os.makedirs(work, exist_ok=True)
    path = os.path.join(work, "scene.json")
    subprocess.run([a.exe, "scene", a.scene, "-o", path], check=True)
    scene = json.load(open(path))
    if a.close:
        close_box(scene)
        json.dump(scene, open(path, "w"))
    spacing = probes.scene_diagonal(scene) * Config(True).probe_frac / 2
    _, (pm, pp, px) = probes.scene_probes(scene, spacing)
    keep = ~probes.buried(scene, pm, pp, px)

    def reference(direct, bounces):
        out = []
        for seed in (1, 2):
            f = os.path.join(work, f"ref-{seed}-{a.samples}-b{bounces}{'-d' if direct else ''}.npz")
            if not os.path.exists(f):
                cycles(sys.executable, ["bake", path, f, "--spacing", spacing, "--bounces",
                                        bounces, "--samples", a.samples, "--seed", seed]
                       + (["--direct-only"] if direct else []), "reference")
            out.append(np.load(f)["colors"][keep])
        return out

    (f1, f2), (d1, d2) = reference(False, a.bounces), reference(True, 64)
    ref_d = (d1 + d2) / 2
    ref = (f1 + f2) / 2 - ref_d
    noise = (f1 - f2) ** 2 / 4  # the variance of the mean of the two full bakes
    pm, pp, px = pm[keep], pp[keep], px[keep]
    _, bf = penumbra_job.run_cli(a.exe, scene, work, "full", settings, keep=False)
    _, bd = penumbra_job.run_cli(a.exe, scene, work, "direct", {**settings, "indirect": False},
                                 keep=False)
    xd = penumbra_job.colors_at(bd, pm, pp, px)
    x = penumbra_job.colors_at(bf, pm, pp, px) - xd
    err, total = 0.0, 0.0
    for mi, poly in sorted(set(zip(pm.tolist(), pp.tolist()))):
        sel = (pm == mi) & (pp == poly)
        r = ref[sel].mean(0)
        d = (x[sel] - ref[sel]).mean(0)
        lit = ref_d[sel].mean(0)
        dd = np.where(lit > 0, (xd[sel] - ref_d[sel]).mean(0) / np.maximum(lit, 1e-300), 0.0)
        se = np.sqrt(noise[sel].mean(0) / sel.sum())
        err += d.mean() * sel.sum()
        total += r.mean() * sel.sum()
        print(f"{scene['meshes'][mi]['name']:8s} polygon {poly:2d} n={sel.sum():4d} "
              f"direct {f'{np.round(dd * 100, 2)} %' if lit.any() else 'unlit'}, indirect {np.round(r, 4)} "
              f"signed {np.round(d / r * 100, 2)} ± {np.round(se / r * 100, 2)} %")
    print(f"overall indirect signed error {err / total * 100:+.3f} %")


if __name__ == "__main__":
    main(sys.argv[1:])
