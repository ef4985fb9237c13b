"""A flat box's shadowed side, lit only by the floor it stands on, against Cycles (issue 11).

A 10 × 10 × 1.3 cm box on a lit floor, the area light behind it, so its −y side gets no
direct light. What it gets from the floor rises within millimetres of the contact line (the
box's own penumbra on the floor), and the side's elements spanned its whole height: the
linear interpolant between its bottom and top rows lay 13 % under Cycles over the side
(room-78's clutter, the largest error left there). The indirect stage now splits elements
where the gathered light is not linear (`indirect::hierarchical::subdivide`).

Cycles bakes a copy of the box whose −y side is a grid of 2 × 0.65 mm cells; Penumbra bakes
the plain box, read at the grid's interior vertices by barycentric interpolation over its
baked triangles. Two seeds, their noise taken out.
"""

import bpy
import numpy as np

import cycles_ref as cr

SAMPLES = 1024
HALF = 0.05
HEIGHT = 0.013
NX, NZ = 50, 20


def _box(gridded):
    """The box; with `gridded`, its −y side (y = −HALF) is NX × NZ quads."""
    x0, x1, y0, y1, z0, z1 = -HALF, HALF, -HALF, HALF, 0.0, HEIGHT
    verts = [(x0, y0, z0), (x1, y0, z0), (x1, y1, z0), (x0, y1, z0),
             (x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)]
    faces = [(0, 3, 2, 1), (4, 5, 6, 7), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7)]
    if gridded:
        xs, zs = np.linspace(x0, x1, NX + 1), np.linspace(z0, z1, NZ + 1)
        base = len(verts)
        verts += [(x, y0, z) for z in zs for x in xs]
        for j in range(NZ):
            for i in range(NX):
                a = base + j * (NX + 1) + i
                faces.append((a, a + 1, a + NX + 2, a + NX + 1))
    else:
        faces.append((0, 1, 5, 4))
    me = bpy.data.meshes.new("Box")
    me.from_pydata(verts, [], faces)
    me.update()
    me.materials.append(cr.diffuse_material("BoxMat", (0.5, 0.5, 0.5)))
    ob = bpy.data.objects.new("Box", me)
    bpy.context.scene.collection.objects.link(ob)
    return ob


def _build(seed, gridded):
    cr.new_bounce_scene(SAMPLES, seed)
    cr.add_grid(2, 1.0, material=cr.diffuse_material("FloorMat", (0.8, 0.8, 0.8)), name="Floor")
    box = _box(gridded)
    cr.add_light("AREA", location=(0.0, 0.3, 1.2), name="Lamp", energy=60.0, size=0.3)
    bpy.context.view_layer.update()
    return box


def _interpolated(name, pos, normal_axis=1, side=-HALF):
    """Penumbra's colours of `<name>_baked` at `pos`, interpolated over its triangles that
    lie in the plane y = `side`."""
    co, col, tri = cr.baked_mesh(name)
    on = np.all(np.abs(co[tri][:, :, normal_axis] - side) < 1e-7, axis=1)
    tri = tri[on]
    uv = co[:, [0, 2]]
    out = np.full((len(pos), 3), np.nan)
    for k, p in enumerate(pos[:, [0, 2]]):
        a, b, c = uv[tri[:, 0]], uv[tri[:, 1]], uv[tri[:, 2]]
        d = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (c[:, 0] - a[:, 0]) * (b[:, 1] - a[:, 1])
        l1 = ((b[:, 0] - p[0]) * (c[:, 1] - p[1]) - (c[:, 0] - p[0]) * (b[:, 1] - p[1])) / d
        l2 = ((c[:, 0] - p[0]) * (a[:, 1] - p[1]) - (a[:, 0] - p[0]) * (c[:, 1] - p[1])) / d
        l3 = 1.0 - l1 - l2
        inside = np.where((l1 >= -1e-9) & (l2 >= -1e-9) & (l3 >= -1e-9))[0]
        assert len(inside), f"probe {p} lies in no baked triangle"
        t = inside[0]
        out[k] = l1[t] * col[tri[t, 0]] + l2[t] * col[tri[t, 1]] + l3[t] * col[tri[t, 2]]
    return out


def test_shadowed_side_of_a_flat_box_takes_the_floor_light_like_cycles():
    refs = []
    for seed in (1, 2):
        refs.append(cr.bake_vertex_colors(_build(seed, gridded=True)))
    (pos, a), (_, b) = refs
    m = 1e-6
    keep = ((np.abs(pos[:, 1] + HALF) < m) & (np.abs(pos[:, 0]) < HALF - m)
            & (pos[:, 2] > m) & (pos[:, 2] < HEIGHT - m))
    pos, a, b = pos[keep], a[keep], b[keep]
    assert len(pos) == (NX - 1) * (NZ - 1)
    _build(3, gridded=False)
    for o in bpy.context.scene.objects:
        o.select_set(True)
    bpy.context.scene.penumbra.use_indirect = True
    assert bpy.ops.penumbra.bake() == {"FINISHED"}
    ours = _interpolated("Box", pos)
    ref = 0.5 * (a + b)
    rms, noise = cr.noise_free_rel_rms(ours, a, b)
    low = pos[:, 2] < 0.004
    bias = ours.mean() / ref.mean() - 1.0
    bias_low = ours[low].mean() / ref[low].mean() - 1.0
    print(f"\n[contact side] ours {ours.mean():.4f} Cycles {ref.mean():.4f} bias {bias:+.4f} "
          f"lowest 4 mm {bias_low:+.4f} rel RMS {rms:.4f} noise {noise:.4f}")
    assert ref.mean() > 0.01, "the floor must light the side in Cycles"
    assert abs(bias) <= 0.04
    assert abs(bias_low) <= 0.06
    assert rms <= 0.06
