"""A whole scene with indirect light, baked by the add-on's operator and by Cycles.

A closed box room (red and green side walls, white elsewhere) with a block on the floor,
lit by a square area light under the ceiling, so that a good part of the light on the
walls and all of it in the block's shadow arrives after one or more diffuse bounces.
The walls are grids; Cycles bakes vertex colours (Diffuse: direct + indirect + colour,
64 diffuse bounces, no clamping, adaptive sampling off) at the grid's interior vertices,
which are also vertices of Penumbra's output mesh (its triangles conform to every input
polygon), so the two are compared where each computes its value directly, without
interpolation. Cycles' own noise is estimated from two seeds and taken out of the error.
"""

import bpy
import numpy as np
import pytest

import cycles_ref as cr

SAMPLES = 1024
GRID = 7  # vertices per side of each wall
SIDE = 2.0
TOL = 0.03


def _wall(name, origin, u, v, color):
    """A GRID×GRID-vertex grid spanning origin + s·u + t·v (s, t in [0, 1]); it faces u × v."""
    t = np.linspace(0.0, 1.0, GRID)
    s, r = np.meshgrid(t, t, indexing="xy")
    verts = np.asarray(origin) + s.reshape(-1, 1) * np.asarray(u) + r.reshape(-1, 1) * np.asarray(v)
    faces = [(j * GRID + i, j * GRID + i + 1, (j + 1) * GRID + i + 1, (j + 1) * GRID + i)
             for j in range(GRID - 1) for i in range(GRID - 1)]
    me = bpy.data.meshes.new(name)
    me.from_pydata(verts.tolist(), [], faces)
    me.update()
    me.materials.append(cr.diffuse_material(name, color))
    ob = bpy.data.objects.new(name, me)
    bpy.context.scene.collection.objects.link(ob)
    return ob


def _block(lo, hi, color):
    return cr.add_block(lo, hi, color)


def _build(seed):
    cr.new_bounce_scene(SAMPLES, seed)
    a = SIDE / 2
    white, red, green = (0.7, 0.7, 0.7), (0.7, 0.1, 0.08), (0.1, 0.6, 0.1)
    walls = [
        _wall("Floor", (-a, -a, 0), (SIDE, 0, 0), (0, SIDE, 0), white),
        _wall("Ceiling", (-a, -a, SIDE), (0, SIDE, 0), (SIDE, 0, 0), white),
        _wall("Left", (-a, -a, 0), (0, SIDE, 0), (0, 0, SIDE), red),
        _wall("Right", (a, -a, 0), (0, 0, SIDE), (0, SIDE, 0), green),
        _wall("Back", (-a, a, 0), (SIDE, 0, 0), (0, 0, SIDE), white),
        _wall("Front", (-a, -a, 0), (0, 0, SIDE), (SIDE, 0, 0), white),
    ]
    # Off the grid lines, so that no probe lies on the block's contact outline.
    block = _block((-0.45, -0.25, 0.0), (0.05, 0.3, 0.7), (0.6, 0.6, 0.6))
    light = cr.add_light("AREA", location=(0.2, -0.1, SIDE - 0.05), name="Lamp", energy=60.0, size=0.5)
    bpy.context.view_layer.update()
    return walls, block, light


def _interior(pos):
    """Grid vertices off their wall's border (where it meets the next wall) and clear of
    the block's footprint and contact outline."""
    a, m = SIDE / 2, 1e-6
    on_bounds = (np.abs(np.abs(pos[:, 0]) - a) < m).astype(int) + (np.abs(np.abs(pos[:, 1]) - a) < m)
    on_bounds += (np.abs(pos[:, 2]) < m) | (np.abs(pos[:, 2] - SIDE) < m)
    near_block = (
        (pos[:, 0] > -0.45 - 0.03) & (pos[:, 0] < 0.05 + 0.03)
        & (pos[:, 1] > -0.25 - 0.03) & (pos[:, 1] < 0.3 + 0.03) & (pos[:, 2] < 0.7 + 0.03)
    )
    return (on_bounds == 1) & ~near_block


def _ours_at(name, pos):
    return cr.baked_colors_at(name, pos)


@pytest.mark.parametrize("quality", ["MEDIUM"])
def test_room_with_indirect_light_matches_cycles(quality):
    refs = {}
    for seed in (1, 2):
        walls, block, light = _build(seed)
        for w in walls:
            pos, baked = cr.bake_vertex_colors(w)
            refs.setdefault(w.name, []).append((pos, baked))
    # Penumbra bakes the scene of the second build (same geometry) with the operator.
    for o in bpy.context.scene.objects:
        o.select_set(True)
    bpy.context.scene.penumbra.quality = quality
    assert bpy.ops.penumbra.bake() == {"FINISHED"}

    sq_err, sq_noise, total, count = 0.0, 0.0, 0.0, 0
    for name, ((pos, a), (_, b)) in refs.items():
        keep = _interior(pos)
        ref = 0.5 * (a + b)
        ours = _ours_at(name, pos[keep])
        e = ours - ref[keep]
        sq_err += float(np.sum(e * e))
        sq_noise += float(np.sum((a[keep] - b[keep]) ** 2)) / 4.0  # variance of the mean
        total += float(np.sum(ref[keep]))
        count += e.size
        print(f"\n[scene-cycles] {name:8s} ours {ours.mean():.4f}  Cycles {ref[keep].mean():.4f}"
              f"  rel RMS {np.sqrt(np.mean(e * e)) / ref[keep].mean():.4f}")
    mean_ref = total / count
    rms = np.sqrt(max(sq_err - sq_noise, 0.0) / count) / mean_ref
    noise = np.sqrt(sq_noise / count) / mean_ref
    print(f"[scene-cycles] relative RMS {rms:.4f} (Cycles noise {noise:.4f} taken out)")
    assert noise < TOL / 2, "the reference is too noisy to judge a 3% error"
    assert rms <= TOL
