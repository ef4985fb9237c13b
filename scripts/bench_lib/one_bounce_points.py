"""One bounce at points, against a closed form: tests/one_bounce.rs's scene through the CLI.

    .venv/bin/python scripts/bench_lib/one_bounce_points.py EXE ['{"element_size": 0.02}']
        [--lamp X0,X1,Y0,Y1,Z]

A 1 × 1 floor (albedo 0.8) at z = 0, a near-black wall (albedo 1e-3) at x = 0 facing it, a
lamp of radiance 10 facing down (default 0.375–0.625 × 0.375–0.625 at z = 1). The floor's
irradiance is Lambert's contour formula; the wall's indirect irradiance at 12 points is the
floor's radiosity times the point-to-point kernel, summed over a 200 × 200 grid of the
floor. Penumbra's is its full bake minus its direct-only bake at those points, read as
the bench reads probes. Prints the floor's direct light against the formula, then at
each wall point the closed form, the closed form with Penumbra's floor light in place of
the formula's, and Penumbra.
"""
import argparse
import json
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))

import numpy as np  # noqa: E402

from bench_lib import penumbra_job  # noqa: E402
from bench_lib.main import ROOT  # noqa: E402

RHO_FLOOR, RHO_WALL, RADIANCE, GRID = 0.8, 1e-3, 10.0, 200


def lambert(p, n, poly):
    """Form factor from each of the points `p` (normal `n`) to the polygon `poly`."""
    f = np.zeros(len(p))
    for i in range(len(poly)):
        a, b = poly[i] - p, poly[(i + 1) % len(poly)] - p
        a /= np.linalg.norm(a, axis=1)[:, None]
        b /= np.linalg.norm(b, axis=1)[:, None]
        c = np.cross(a, b)
        s = np.linalg.norm(c, axis=1)
        f += (c @ n) / np.maximum(s, 1e-300) * np.arctan2(s, (a * b).sum(1))
    return np.abs(f) / (2 * np.pi)


def main(argv):
    ap = argparse.ArgumentParser()
    ap.add_argument("exe")
    ap.add_argument("settings", nargs="?", default="{}")
    ap.add_argument("--lamp", default="0.375,0.625,0.375,0.625,1.0")
    a = ap.parse_args(argv)
    settings = json.loads(a.settings)
    x0, x1, y0, y1, z = (float(v) for v in a.lamp.split(","))
    lamp = np.array([[x0, y0, z], [x0, y1, z], [x1, y1, z], [x1, y0, z]])
    scene = {"format": "penumbra-scene", "version": 1, "settings": {}, "meshes": [
        {"name": "Floor", "positions": [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]],
         "polygons": [[0, 1, 2, 3]], "albedo": [RHO_FLOOR] * 3},
        {"name": "Wall", "positions": [[0, 0, 0], [0, 1, 0], [0, 1, 1], [0, 0, 1]],
         "polygons": [[0, 1, 2, 3]], "albedo": [RHO_WALL] * 3}],
        "lights": [{"name": "Lamp", "polygon": lamp.tolist(), "radiance": [RADIANCE] * 3}]}
    c = (np.arange(GRID) + 0.5) / GRID
    fx, fy = np.meshgrid(c, c, indexing="ij")
    floor = np.stack([fx.ravel(), fy.ravel(), np.zeros(GRID * GRID)], 1)
    e = RADIANCE * np.pi * lambert(floor, np.array([0, 0, 1.0]), lamp)

    work = os.path.join(ROOT, "target", "bench-work", "one-bounce")
    os.makedirs(work, exist_ok=True)
    _, full = penumbra_job.run_cli(a.exe, scene, work, "full", settings, keep=False)
    _, direct = penumbra_job.run_cli(a.exe, scene, work, "direct",
                                     {**settings, "indirect": False}, keep=False)
    zero = np.zeros(len(floor), int)
    ours = penumbra_job.colors_at(direct, zero, zero, floor)[:, 0] * np.pi / RHO_FLOOR
    print(f"floor direct light: mean {ours.mean() / e.mean() - 1:+.4%} against the formula, "
          f"worst point {np.abs(ours / e - 1).max():.4%}")

    wall = np.array([[0, y, z] for y in (0.2, 0.5, 0.8) for z in (0.15, 0.3, 0.5, 0.8)], float)

    def gathered(b):
        out = []
        for q in wall:
            d = floor - q
            r2 = (d ** 2).sum(1)
            cos_q, cos_p = d[:, 0] / np.sqrt(r2), -d[:, 2] / np.sqrt(r2)
            out.append((b * cos_p * cos_q / (np.pi * r2)).sum() / GRID ** 2)
        return np.array(out)

    closed, with_ours = gathered(RHO_FLOOR * e), gathered(RHO_FLOOR * ours)
    one = np.ones(len(wall), int)

    def at(bake):
        return penumbra_job.colors_at(bake, one, one * 0, wall)[:, 0] * np.pi / RHO_WALL

    # Both bakes share the wall's mesh, so the difference takes out how the direct light's
    # linear interpolation misses between vertices (near the lamp, far more than the
    # indirect light itself).
    for q, cf, wo, x in zip(wall, closed, with_ours, at(full) - at(direct)):
        print(f"wall {q}: closed form {cf:.5f}, with Penumbra's floor {wo / cf - 1:+.2%}, "
              f"Penumbra {x / cf - 1:+.2%}")


if __name__ == "__main__":
    main(sys.argv[1:])
