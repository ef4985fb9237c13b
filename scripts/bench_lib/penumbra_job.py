"""One `penumbra bake` process (wall time and peak RSS of that child alone), and its
colours interpolated at the probe points."""
from __future__ import annotations

import json
import os
import subprocess
import tempfile
import time

import numpy as np


def timed(cmd: list[str], timeout: float | None = None):
    """Runs `cmd`; returns (exit code or None on timeout, wall s, peak RSS MB, stdout, stderr).

    Peak RSS comes from /usr/bin/time (its child is forked from the small `time` process;
    a child forked straight from this Python, which holds bpy, would inherit our RSS as its
    high-water mark); without /usr/bin/time, from wait4."""
    fd, tf = tempfile.mkstemp(suffix=".time")
    os.close(fd)
    full = (["/usr/bin/time", "-o", tf, "-f", "%M"] + cmd) if os.path.exists("/usr/bin/time") \
        else cmd
    t = time.perf_counter()
    p = subprocess.Popen(full, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    try:
        out, err = p.communicate(timeout=timeout)
        code = p.returncode
    except subprocess.TimeoutExpired:
        # Kill the job itself (time's child), then collect time's report.
        subprocess.run(["pkill", "-KILL", "-P", str(p.pid)], check=False)
        out, err = p.communicate()
        code = None
    wall = time.perf_counter() - t
    peak = float("nan")
    try:
        txt = open(tf).read().split()
        peak = int(txt[-1]) / 1024.0
    except (OSError, ValueError, IndexError):
        pass
    os.remove(tf)
    return code, wall, peak, out.decode(errors="replace"), err.decode(errors="replace")


def run_cli(exe: str, scene: dict, workdir: str, tag: str, settings: dict | None = None,
            keep: bool = True, timeout: float | None = None):
    """Bakes `scene` with `settings` merged in. Returns (record, bake dict); on timeout the
    record has timed_out and the bake is None."""
    s = dict(scene)
    s["settings"] = {**scene.get("settings", {}), **(settings or {})}
    sp = os.path.join(workdir, f"{tag}.scene.json")
    bp = os.path.join(workdir, f"{tag}.bake.json")
    with open(sp, "w") as f:
        json.dump(s, f)
    code, wall, peak, _, err = timed([exe, "bake", sp, "-o", bp], timeout)
    if code is None:
        return dict(wall=wall, peak_mb=peak, stats=None, settings=s["settings"],
                    timed_out=True), None
    if code != 0:
        raise RuntimeError(f"penumbra bake {tag} failed ({code}): {err.strip()}")
    with open(bp) as f:
        bake = json.load(f)
    if not keep:
        os.remove(bp)
    rec = dict(wall=wall, peak_mb=peak, stats=bake["stats"], settings=s["settings"],
               timed_out=False)
    return rec, bake


def colors_at(bake: dict, probe_mesh, probe_poly, probe_pos):
    """Penumbra's colour at each probe by barycentric interpolation in the bake triangle of
    the probe's own source polygon that holds it (nearest, through a BVH per polygon)."""
    import bpy  # noqa: F401  (the bpy module brings mathutils)
    from mathutils import Vector
    from mathutils.bvhtree import BVHTree

    out = np.full((len(probe_pos), 3), np.nan)
    for mi, m in enumerate(bake["meshes"]):
        sel = np.nonzero(probe_mesh == mi)[0]
        if len(sel) == 0:
            continue
        P = np.asarray(m["positions"], dtype=np.float64)
        T = np.asarray(m["triangles"], dtype=np.int64).reshape(-1, 3)
        C = np.asarray(m["colors"], dtype=np.float64)
        src = np.asarray(m["source_polygon"], dtype=np.int64)
        order = np.argsort(src, kind="stable")
        bounds = np.searchsorted(src[order], np.arange(src.max() + 2 if len(src) else 1))
        for poly in np.unique(probe_poly[sel]):
            tri_ids = order[bounds[poly]:bounds[poly + 1]]
            pts = sel[probe_poly[sel] == poly]
            if len(tri_ids) == 0:
                continue
            # The tree over this polygon's own vertices only: the whole mesh's, converted
            # for each polygon, took 171 of per_mesh.py's 238 s on room-245.
            used, local = np.unique(T[tri_ids], return_inverse=True)
            tris = T[tri_ids]
            tree = BVHTree.FromPolygons(P[used].tolist(), local.reshape(-1, 3).tolist(),
                                        all_triangles=True)
            for k in pts:
                loc, _, ti, _ = tree.find_nearest(Vector(probe_pos[k]))
                if ti is None:
                    continue
                a, b, c = P[tris[ti]]
                x = np.asarray(loc)
                v0, v1, v2 = b - a, c - a, x - a
                d00, d01, d11 = v0 @ v0, v0 @ v1, v1 @ v1
                d20, d21 = v2 @ v0, v2 @ v1
                den = d00 * d11 - d01 * d01
                w1 = (d11 * d20 - d01 * d21) / den
                w2 = (d00 * d21 - d01 * d20) / den
                w0 = 1.0 - w1 - w2
                ia, ib, ic = tris[ti]
                out[k] = w0 * C[ia] + w1 * C[ib] + w2 * C[ic]
    return out
