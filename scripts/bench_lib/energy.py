"""Energy in a closed scene: the power its surfaces absorb over the power its lights emit.

    .venv/bin/python scripts/bench_lib/energy.py SCENE EXE ['{"convergence": 1e-4}']
        [--work DIR]

Bakes the built-in scene SCENE with `lighting_only` (colours E/π), sums (1 − ρ)·E·A over
the bake's triangles and divides by Σ π·L·A over the polygon lights, per channel. In a
closed scene every watt emitted is absorbed somewhere, so 1 is exact; what falls short
was lost by the bake (or by interpolating a concave field linearly between vertices,
which `rust/core/tests/energy.rs` bounds at about 0.1 % for an empty room). Scenes with
emissive faces or round lights are refused: their emitted power is not summed here.
"""
import json
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))

import numpy as np  # noqa: E402

from bench_lib import penumbra_job  # noqa: E402
from bench_lib.main import work_arg  # noqa: E402


def polygon_area(poly):
    p = np.asarray(poly, dtype=np.float64)
    return 0.5 * np.linalg.norm(np.cross(p[1:-1] - p[0], p[2:] - p[0]).sum(0))


def main(argv):
    work, argv = work_arg(argv)
    name, exe = argv[:2]
    extra = json.loads(argv[2]) if len(argv) > 2 else {}
    os.makedirs(work, exist_ok=True)
    path = os.path.join(work, f"energy-{name}.json")
    subprocess.run([exe, "scene", name, "-o", path], check=True)
    with open(path) as f:
        scene = json.load(f)
    if any("emission" in m for m in scene["meshes"]) or any(
            "polygon" not in l for l in scene["lights"]):
        sys.exit(f"energy: {name}: only scenes lit by polygon lights alone are summed")
    emitted = sum(np.pi * np.asarray(l["radiance"]) * polygon_area(l["polygon"])
                  for l in scene["lights"])
    _, bake = penumbra_job.run_cli(exe, scene, work, f"energy-{name}",
                                   {**extra, "lighting_only": True}, keep=False)
    absorbed = np.zeros(3)
    for src, m in zip(scene["meshes"], bake["meshes"]):
        P = np.asarray(m["positions"], dtype=np.float64).reshape(-1, 3)
        T = np.asarray(m["triangles"], dtype=np.int64).reshape(-1, 3)
        C = np.asarray(m["colors"], dtype=np.float64).reshape(len(P), -1)[:, :3]
        alb = np.asarray(src.get("albedo", [0.8, 0.8, 0.8]), dtype=np.float64)
        if alb.ndim == 2:  # per polygon
            alb = alb[np.asarray(m["source_polygon"], dtype=np.int64)]
        area = 0.5 * np.linalg.norm(
            np.cross(P[T[:, 1]] - P[T[:, 0]], P[T[:, 2]] - P[T[:, 0]]), axis=1)
        e = np.pi * C[T].mean(1)
        absorbed += ((1.0 - alb) * e * area[:, None]).sum(0)
    print("absorbed/emitted", " ".join(f"{x:.5f}" for x in absorbed / emitted))


if __name__ == "__main__":
    main(sys.argv[1:])
