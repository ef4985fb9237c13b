"""Probe points on the receivers: every polygon of every scene mesh is fanned into
triangles and each triangle is split into a lattice of spacing about `spacing`. The
lattice vertices strictly inside the polygon are the probes (the boundary is left out: a
vertex there is shared by faces meeting at a crease, where a bake value is ambiguous).

The same lattice, as a mesh, is what Cycles bakes vertex colours on: it has the scene's
exact geometry, only more vertices.

With `jitter` (a seed) every interior vertex moves by a random offset in its polygon's
plane, at most a quarter of the lowest altitude of the lattice triangles around it (so no
triangle folds and no probe leaves its polygon). The built-in scenes are made of round
numbers, and a lattice of round spacing can put a whole row of probes on a shadow's edge,
or none near it: data1's umbra edge y = 0.4 is a lattice line at spacing 0.16 and is
missed at 0.31, and a mesh's error read there differs by 10× between the two.
"""
from __future__ import annotations

import math

import numpy as np


def polygon_lattice(poly: np.ndarray, spacing: float, rng=None):
    """Lattice of one convex polygon (k, 3) → (vertices (V,3), triangles (T,3), interior mask),
    its interior vertices jittered by `rng` if given (module doc)."""
    k = len(poly)
    c = poly.mean(0)
    if np.max(np.linalg.norm(poly - c, axis=1)) < 0.5 * spacing:
        # Smaller than one lattice cell: one probe at the centre, fanned to the corners.
        tris = np.array([(i, (i + 1) % k, k) for i in range(k)], dtype=np.int64)
        return _jittered(np.vstack([poly, c]), tris, np.r_[np.zeros(k, bool), True], rng)
    verts: list[np.ndarray] = []
    index: dict[tuple, int] = {}
    tris: list[tuple[int, int, int]] = []
    interior: list[bool] = []

    def vid(p: np.ndarray, inside: bool) -> int:
        key = tuple(np.round(p, 9))
        i = index.get(key)
        if i is None:
            i = len(verts)
            index[key] = i
            verts.append(p)
            interior.append(inside)
        else:
            interior[i] = interior[i] and inside
        return i

    for t in range(1, k - 1):
        a, b, c = poly[0], poly[t], poly[t + 1]
        longest = max(np.linalg.norm(b - a), np.linalg.norm(c - b), np.linalg.norm(a - c))
        m = max(3, math.ceil(longest / spacing))
        ids = {}
        for i in range(m + 1):
            for j in range(m + 1 - i):
                l = m - i - j
                p = (i * a + j * b + l * c) / m
                # On the polygon's boundary: b-c (i = 0) always, a-b (l = 0) only in the
                # first fan triangle, c-a (j = 0) only in the last; fan diagonals are inside.
                on = (i == 0) or (l == 0 and t == 1) or (j == 0 and t == k - 2)
                ids[i, j] = vid(p, not on)
        for i in range(m):
            for j in range(m - i):
                tris.append((ids[i, j], ids[i + 1, j], ids[i, j + 1]))
                if i + j + 1 < m:
                    tris.append((ids[i + 1, j], ids[i + 1, j + 1], ids[i, j + 1]))
    return _jittered(np.array(verts), np.array(tris, dtype=np.int64),
                     np.array(interior, dtype=bool), rng)


def _jittered(verts: np.ndarray, tris: np.ndarray, interior: np.ndarray, rng):
    if rng is None:
        return verts, tris, interior
    a, b, c = verts[tris[:, 0]], verts[tris[:, 1]], verts[tris[:, 2]]
    n = np.cross(b - a, c - a)
    twice = np.linalg.norm(n, axis=1)
    longest = np.max([np.linalg.norm(b - a, axis=1), np.linalg.norm(c - b, axis=1),
                      np.linalg.norm(a - c, axis=1)], axis=0)
    lowest = twice / longest
    # A vertex moved by d changes a distance to an opposite edge by at most d, and moving
    # that edge's two ends by d moves the edge by at most d: with d ≤ lowest / 4 every
    # triangle keeps at least half its lowest altitude.
    reach = np.full(len(verts), np.inf)
    for k in range(3):
        np.minimum.at(reach, tris[:, k], 0.25 * lowest)
    normal = n.sum(0)
    normal /= np.linalg.norm(normal)
    e1 = np.cross(normal, [1.0, 0.0, 0.0])
    if np.linalg.norm(e1) < 0.5:
        e1 = np.cross(normal, [0.0, 1.0, 0.0])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(normal, e1)
    angle = rng.uniform(0.0, 2.0 * np.pi, len(verts))
    radius = reach * np.sqrt(rng.uniform(0.0, 1.0, len(verts)))
    move = np.where(interior, radius, 0.0)
    out = verts + (move * np.cos(angle))[:, None] * e1 + (move * np.sin(angle))[:, None] * e2
    return out, tris, interior


def scene_probes(scene: dict, spacing: float, jitter: int | None = None):
    """Per mesh: lattice vertices, triangles, and per vertex (polygon index, is-probe); the
    interior vertices jittered with seed `jitter` if given (module doc).

    Returns a list of dicts {name, verts, tris, polygon, probe} and the probes gathered as
    arrays (mesh index, polygon index, position)."""
    meshes = []
    pm, pp, px = [], [], []
    for mi, m in enumerate(scene["meshes"]):
        pos = np.asarray(m["positions"], dtype=np.float64)
        V, T, P, I = [], [], [], []
        off = 0
        for pi, poly in enumerate(m["polygons"]):
            rng = None if jitter is None else np.random.default_rng([jitter, mi, pi])
            v, t, inside = polygon_lattice(pos[poly], spacing, rng)
            V.append(v)
            T.append(t + off)
            P.append(np.full(len(v), pi))
            I.append(inside)
            off += len(v)
        verts, polys, inside = np.concatenate(V), np.concatenate(P), np.concatenate(I)
        if m.get("output", True) is False:
            # Scenery: Cycles sees it, nothing of it is scored (Penumbra outputs none).
            inside = np.zeros_like(inside)
        meshes.append(dict(name=m["name"], verts=verts, tris=np.concatenate(T),
                           polygon=polys, probe=inside))
        pm.append(np.full(inside.sum(), mi))
        pp.append(polys[inside])
        px.append(verts[inside])
    return meshes, (np.concatenate(pm), np.concatenate(pp), np.concatenate(px))


def interpolate(lattices: list[dict], colors: list[np.ndarray], probe_mesh, probe_poly,
                probe_pos) -> np.ndarray:
    """Values at the probes read from vertex colours on other lattices (a uniform mesh a
    Cycles user would bake): linear over the lattice triangle of the probe's polygon that
    holds it, as a viewport shows a vertex-colour bake. NaN where no triangle holds it."""
    out = np.full((len(probe_pos), 3), np.nan)
    for mi, (lat, col) in enumerate(zip(lattices, colors)):
        V, T = lat["verts"], lat["tris"]
        tri_poly = lat["polygon"][T[:, 0]]
        for pi in np.unique(probe_poly[probe_mesh == mi]):
            sel = np.nonzero((probe_mesh == mi) & (probe_poly == pi))[0]
            tris = T[tri_poly == pi]
            a, b, c = V[tris[:, 0]], V[tris[:, 1]], V[tris[:, 2]]
            n = np.cross(b - a, c - a)
            nn = np.einsum("ij,ij->i", n, n)
            x = probe_pos[sel][:, None, :]  # (P, 1, 3)
            # Barycentric coordinates of every probe in every triangle of the polygon.
            wb = np.einsum("ptk,tk->pt", np.cross(x - a, c - a), n) / nn
            wc = np.einsum("ptk,tk->pt", np.cross(b - a, x - a), n) / nn
            wa = 1.0 - wb - wc
            inside = np.minimum(np.minimum(wa, wb), wc)
            best = np.argmax(inside, axis=1)
            k = np.arange(len(sel))
            ok = inside[k, best] > -1e-6
            t = tris[best]
            val = (wa[k, best, None] * col[t[:, 0]] + wb[k, best, None] * col[t[:, 1]]
                   + wc[k, best, None] * col[t[:, 2]])
            out[sel[ok]] = val[ok]
    return out


def scene_diagonal(scene: dict) -> float:
    """Bounding-box diagonal of meshes and lights, as the core computes it for defaults."""
    pts = [np.asarray(m["positions"], dtype=np.float64) for m in scene["meshes"]]
    for l in scene["lights"]:
        if "polygon" in l:
            pts.append(np.asarray(l["polygon"], dtype=np.float64))
        elif "point" in l:
            pts.append(np.asarray([l["point"]], dtype=np.float64))
    p = np.concatenate(pts)
    return float(np.linalg.norm(p.max(0) - p.min(0)))


def total_area(scene: dict) -> float:
    a = 0.0
    for m in scene["meshes"]:
        pos = np.asarray(m["positions"], dtype=np.float64)
        for poly in m["polygons"]:
            v = pos[poly]
            a += 0.5 * np.linalg.norm(np.cross(v[1:-1] - v[0], v[2:] - v[0]).sum(0))
    return a


def buried(scene: dict, probe_mesh, probe_poly, probe_pos) -> np.ndarray:
    """True for probes nobody can see, whose bake value is arbitrary (left out of the error):
    * covered by a coplanar polygon facing the other way (the floor under a box standing on
      it, and the box's bottom);
    * inside a closed solid (a face of one box inside another it intersects): the ray from
      just in front of the probe along its normal first meets the back of a face, or the
      probe lies strictly inside a closed convex component of another polygon (`_solids`).
      The ray alone misses probes whose ray meets the front of a third box within the
      solid: in a heap of clutter nearly every direction does (room-245: 141 of the 1,150
      probes kept before lay inside other boxes, 0 in Cycles, whatever a bake gives)."""
    polys, owner = [], {}
    for mi, m in enumerate(scene["meshes"]):
        pos = np.asarray(m["positions"], dtype=np.float64)
        for pi, poly in enumerate(m["polygons"]):
            owner[mi, pi] = len(polys)
            polys.append(pos[poly])
    N = np.array([np.cross(p[1:-1] - p[0], p[2:] - p[0]).sum(0) for p in polys])
    N /= np.linalg.norm(N, axis=1, keepdims=True)
    D = np.array([n @ p[0] for n, p in zip(N, polys)])
    diag = scene_diagonal(scene)
    tol = 1e-7 * diag
    out = np.zeros(len(probe_pos), dtype=bool)
    pid = np.array([owner[int(a), int(b)] for a, b in zip(probe_mesh, probe_poly)])
    opposite = (N @ N.T) < -0.999
    for p in np.unique(pid):
        cands = np.nonzero(opposite[p] & (np.abs(D + D[p]) < tol))[0]
        if len(cands) == 0:
            continue
        sel = np.nonzero(pid == p)[0]
        x = probe_pos[sel]
        for q in cands:
            v = polys[q]
            e = np.roll(v, -1, axis=0) - v
            # Inside the convex polygon q (counter-clockwise about N[q]) or on its boundary.
            side = np.stack([np.cross(e[k], x - v[k]) @ N[q] for k in range(len(v))], axis=1)
            out[sel[np.all(side >= -tol * diag, axis=1)]] = True

    import bpy  # noqa: F401  (the bpy module brings mathutils)
    from mathutils import Vector
    from mathutils.bvhtree import BVHTree

    verts, tris, tri_poly = [], [], []
    for q, v in enumerate(polys):
        o = len(verts)
        verts.extend(v.tolist())
        for i in range(1, len(v) - 1):
            tris.append((o, o + i, o + i + 1))
            tri_poly.append(q)
    tree = BVHTree.FromPolygons(verts, tris, all_triangles=True)
    eps = 1e-6 * diag
    for k in np.nonzero(~out)[0]:
        n = N[pid[k]]
        hit, _, ti, _ = tree.ray_cast(Vector(probe_pos[k] + eps * n), Vector(n))
        if hit is not None and N[tri_poly[ti]] @ n > 0:
            out[k] = True
    for planes, members in _solids(scene, tol):
        inside = np.all(probe_pos @ planes[:, :3].T - planes[:, 3] < -tol, axis=1)
        inside &= ~np.isin(pid, members)
        out |= inside
    return out


def _solids(scene: dict, tol: float):
    """Closed convex components of the scene's meshes (polygons joined by shared vertices,
    every edge on two polygons, every vertex on or behind every polygon's plane), each as
    its planes `[nx, ny, nz, d]` (n·x = d on the plane, outward n) and the global indices
    of its polygons."""
    out, base = [], 0
    for m in scene["meshes"]:
        pos = np.asarray(m["positions"], dtype=np.float64)
        if len(pos) == 0:
            base += len(m["polygons"])
            continue
        # Vertices at one place are one vertex, whether the polygons share its index or not.
        _, first, same = np.unique(np.round(pos / max(tol, 1e-300)), axis=0,
                                   return_index=True, return_inverse=True)
        same = same.ravel()
        polys = [[int(same[i]) for i in p] for p in m["polygons"]]
        pos = pos[first]
        parent = list(range(len(pos)))

        def find(i):
            while parent[i] != i:
                parent[i] = parent[parent[i]]
                i = parent[i]
            return i

        for p in polys:
            for i in p[1:]:
                parent[find(i)] = find(p[0])
        groups = {}
        for pi, p in enumerate(polys):
            groups.setdefault(find(p[0]), []).append(pi)
        for members in groups.values():
            edges = {}
            for pi in members:
                p = polys[pi]
                for a, b in zip(p, p[1:] + p[:1]):
                    e = (min(a, b), max(a, b))
                    edges[e] = edges.get(e, 0) + 1
            if len(members) < 4 or any(c != 2 for c in edges.values()):
                continue
            verts = pos[sorted({i for pi in members for i in polys[pi]})]
            planes = []
            for pi in members:
                v = pos[polys[pi]]
                n = np.cross(v[1:-1] - v[0], v[2:] - v[0]).sum(0)
                n /= np.linalg.norm(n)
                planes.append([*n, n @ v[0]])
            planes = np.array(planes)
            if np.all(verts @ planes[:, :3].T - planes[:, 3] <= tol):
                out.append((planes, np.array(members) + base))
        base += len(polys)
    return out
