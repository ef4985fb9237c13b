"""One Cycles job in its own process, so its time and peak memory are its own.

    python cycles_job.py bake  SCENE.json OUT.npz --spacing S --samples N --seed K
                               [--adaptive] [--direct-only] [--bounces B] [--threads T]
                               [--mesh-spacing H] [--jitter SEED]
    python cycles_job.py render SCENE.json OUT.png --samples N [--bake BAKE.json] ...

Prints one JSON line: {"seconds": time of the bake (or render) call, "peak_rss_mb": ...}.
"""
from __future__ import annotations

import argparse
import json
import os
import resource
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

import numpy as np  # noqa: E402

from bench_lib import blender, probes  # noqa: E402


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("kind", choices=["bake", "render"])
    ap.add_argument("scene")
    ap.add_argument("out")
    ap.add_argument("--spacing", type=float, default=0.1)
    ap.add_argument("--samples", type=int, default=64)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--adaptive", action="store_true")
    ap.add_argument("--direct-only", action="store_true")
    ap.add_argument("--bounces", type=int, default=64)
    ap.add_argument("--threads", type=int, default=os.cpu_count() or 1)
    ap.add_argument("--bake", help="render this bake JSON (emission) instead of the scene")
    ap.add_argument("--camera", help="JSON [[x,y,z],[tx,ty,tz],lens]")
    ap.add_argument("--resolution", type=int, default=200)
    ap.add_argument("--mesh-spacing", type=float,
                    help="bake a uniform mesh of this spacing and read the probes from it by "
                    "linear interpolation (a Cycles user's vertex-colour bake)")
    ap.add_argument("--jitter", type=int,
                    help="jitter the probes with this seed (probes.py)")
    a = ap.parse_args()
    scene = json.load(open(a.scene))
    blender.reset(a.samples, a.seed, a.adaptive, a.bounces, a.threads)
    if a.kind == "bake":
        lat, (pm, pp, px) = probes.scene_probes(scene, a.spacing, a.jitter)
        mesh = probes.scene_probes(scene, a.mesh_spacing)[0] if a.mesh_spacing else lat
        objs = blender.cycles_scene(scene, mesh)
        passes = {"DIRECT", "COLOR"} if a.direct_only else {"DIRECT", "INDIRECT", "COLOR"}
        dt, cols = blender.bake_vertex_colors(objs, passes)
        if a.mesh_spacing:
            probe = probes.interpolate(mesh, cols, pm, pp, px)
        else:
            probe = np.concatenate([c[l["probe"]] for c, l in zip(cols, lat)])
        np.savez(a.out, colors=probe)
    else:
        import bpy

        if a.bake:
            blender.baked_scene(json.load(open(a.bake)))
        else:
            lat, _ = probes.scene_probes(scene, 1e9)
            blender.cycles_scene(scene, lat)
        loc, tgt, lens = json.loads(a.camera)
        blender.camera(loc, tgt, lens)
        sc = bpy.context.scene
        sc.render.resolution_x = sc.render.resolution_y = a.resolution
        sc.render.resolution_percentage = 100
        sc.view_settings.view_transform = "Standard"
        sc.render.image_settings.file_format = "PNG"
        sc.render.filepath = a.out
        t = time.perf_counter()
        bpy.ops.render.render(write_still=True)
        dt = time.perf_counter() - t
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    print(json.dumps({"seconds": dt, "peak_rss_mb": rss}))


if __name__ == "__main__":
    main()
