"""Writes the small scenes that used to take minutes (issue 15) as scene JSON, for timing:

    python3 scripts/worst_cases.py DIR [--no-indirect]
    target/release/penumbra bake DIR/soup200.json -o /dev/null --stats

soup200:  200 random triangles (seeded) over a 4 m floor, one area light
quads2000: 2,000 small quads in a 45 × 45 grid over a floor, one area light
disks1000: a 1,000-gon disk over another 1,000-gon disk, one area light
"""

import json
import math
import random
import sys
from pathlib import Path


def scene(meshes, indirect):
    light = [[-0.3, -0.3, 3.0], [-0.3, 0.3, 3.0], [0.3, 0.3, 3.0], [0.3, -0.3, 3.0]]
    return {
        "format": "penumbra-scene",
        "version": 1,
        "meshes": meshes,
        "lights": [{"name": "Lamp", "polygon": light, "radiance": [20, 20, 20]}],
        "settings": {"indirect": indirect},
    }


def floor(half=2.0):
    h = half
    return {"name": "Floor", "positions": [[-h, -h, 0], [h, -h, 0], [h, h, 0], [-h, h, 0]], "polygons": [[0, 1, 2, 3]]}


def soup(n=200, seed=15):
    r = random.Random(seed)
    pos, polys = [], []
    for _ in range(n):
        c = (r.uniform(-1.5, 1.5), r.uniform(-1.5, 1.5), r.uniform(0.2, 2.0))
        polys.append([len(pos), len(pos) + 1, len(pos) + 2])
        pos += [[c[0] + r.uniform(-0.3, 0.3), c[1] + r.uniform(-0.3, 0.3), c[2] + r.uniform(-0.3, 0.3)] for _ in range(3)]
    return [floor(), {"name": "Soup", "positions": pos, "polygons": polys}]


def quads(n=2000):
    side = math.ceil(math.sqrt(n))
    pos, polys = [], []
    step, half = 3.0 / side, 0.3 * 3.0 / side
    for k in range(n):
        x, y = -1.5 + (k % side + 0.5) * step, -1.5 + (k // side + 0.5) * step
        z = 0.5 + 0.3 * ((k * 7919) % 13) / 13
        polys.append([len(pos), len(pos) + 1, len(pos) + 2, len(pos) + 3])
        pos += [[x - half, y - half, z], [x + half, y - half, z], [x + half, y + half, z], [x - half, y + half, z]]
    return [floor(), {"name": "Quads", "positions": pos, "polygons": polys}]


def disk(name, n, r, z):
    return {
        "name": name,
        "positions": [[r * math.cos(2 * math.pi * k / n), r * math.sin(2 * math.pi * k / n), z] for k in range(n)],
        "polygons": [list(range(n))],
    }


def disks(n=1000):
    return [disk("Lower", n, 1.5, 0.0), disk("Upper", n, 0.6, 1.0)]


if __name__ == "__main__":
    out = Path(sys.argv[1])
    out.mkdir(parents=True, exist_ok=True)
    indirect = "--no-indirect" not in sys.argv
    for name, meshes in [("soup200", soup()), ("quads2000", quads()), ("disks1000", disks())]:
        (out / f"{name}.json").write_text(json.dumps(scene(meshes, indirect)))
