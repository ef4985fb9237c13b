"""The bench reads a Cycles user's uniform-mesh bake at the probes by linear interpolation
(`bench_lib.probes.interpolate`): a field linear over each polygon comes back exactly, and a
probe no triangle holds stays NaN instead of taking a neighbour's value; and it leaves out
the probes nobody can see (`bench_lib.probes.buried`)."""
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))),
                                "scripts"))

from bench_lib import probes  # noqa: E402


def _scene():
    # A floor quad and a tilted triangle, as scene JSON.
    return {"meshes": [
        {"name": "Floor", "positions": [[0, 0, 0], [2, 0, 0], [2, 1, 0], [0, 1, 0]],
         "polygons": [[0, 1, 2, 3]]},
        {"name": "Tilt", "positions": [[0, 0, 1], [1, 0, 1.5], [0, 1, 2]],
         "polygons": [[0, 1, 2]]}], "lights": []}


def test_linear_field_is_read_exactly_at_probes_off_the_mesh_vertices():
    scene = _scene()
    _, (pm, pp, px) = probes.scene_probes(scene, 0.3)
    fine = probes.scene_probes(scene, 0.083)[0]

    def field(x):
        return np.stack([1 + 2 * x[:, 0], x[:, 1] - 3 * x[:, 2], 0.5 * x[:, 2] + 0.1], axis=1)

    y = probes.interpolate(fine, [field(m["verts"]) for m in fine], pm, pp, px)
    assert len(px) > 10
    assert not np.isnan(y).any()
    np.testing.assert_allclose(y, field(px), atol=1e-12)
    # The probes are not lattice vertices of the finer mesh: interpolation did the work.
    fv = np.concatenate([m["verts"] for m in fine])
    d = np.min(np.linalg.norm(px[:, None, :] - fv[None, :, :], axis=2), axis=1)
    assert (d > 1e-6).sum() > len(px) // 2


def test_a_probe_outside_its_polygon_stays_nan():
    scene = _scene()
    fine = probes.scene_probes(scene, 0.1)[0]
    cols = [np.ones((len(m["verts"]), 3)) for m in fine]
    pm = np.array([0, 0])
    pp = np.array([0, 0])
    px = np.array([[0.5, 0.5, 0.0], [3.0, 0.5, 0.0]])
    y = probes.interpolate(fine, cols, pm, pp, px)
    np.testing.assert_allclose(y[0], 1.0)
    assert np.isnan(y[1]).all()


def _box(lo, hi):
    (x0, y0, z0), (x1, y1, z1) = lo, hi
    v = [[x0, y0, z0], [x1, y0, z0], [x1, y1, z0], [x0, y1, z0],
         [x0, y0, z1], [x1, y0, z1], [x1, y1, z1], [x0, y1, z1]]
    f = [[0, 3, 2, 1], [4, 5, 6, 7], [0, 1, 5, 4], [1, 2, 6, 5], [2, 3, 7, 6], [3, 0, 4, 7]]
    return v, f


def test_probe_inside_a_box_behind_a_third_box_is_buried():
    # Box A's +x side passes through B; inside B, right in front of that side, stands the
    # -x face of C (which B also holds in part). A probe on A's side inside B sees C's front
    # along its normal, yet lies inside B: nobody sees it. A probe on A's side outside B is
    # seen. A floor closes nothing, so the scene is open, as the bench's are not.
    meshes = []
    for name, lo, hi in [("A", (0, 0, 0), (1, 1, 1)), ("B", (0.8, 0.2, 0.2), (1.6, 0.6, 0.6)),
                         ("C", (1.3, 0.35, 0.35), (1.4, 0.45, 0.45))]:
        v, f = _box(lo, hi)
        meshes.append({"name": name, "positions": v, "polygons": f})
    scene = {"meshes": meshes, "lights": []}
    side = 3  # A's +x face in _box's order.
    px = np.array([[1.0, 0.4, 0.4], [1.0, 0.8, 0.8]])
    out = probes.buried(scene, np.array([0, 0]), np.array([side, side]), px)
    assert out.tolist() == [True, False]


def test_jittered_probes_stay_in_their_polygons_and_no_triangle_folds():
    # A pentagon (fan of three triangles) and the tilted triangle: the jitter moves every
    # interior vertex, within its plane, and leaves the boundary where it was.
    scene = _scene()
    scene["meshes"].append({"name": "Penta", "positions": [
        [0, 0, 3], [1, 0, 3], [1.4, 0.8, 3], [0.5, 1.4, 3], [-0.4, 0.8, 3]],
        "polygons": [[0, 1, 2, 3, 4]]})
    plain, (pm, pp, px) = probes.scene_probes(scene, 0.2)
    moved, (qm, qp, qx) = probes.scene_probes(scene, 0.2, jitter=7)
    again = probes.scene_probes(scene, 0.2, jitter=7)[1][2]
    np.testing.assert_array_equal(qx, again)
    assert (pm == qm).all() and (pp == qp).all()
    shift = np.linalg.norm(qx - px, axis=1)
    assert (shift > 1e-9).all() and shift.max() < 0.2
    for a, b in zip(plain, moved):
        np.testing.assert_array_equal(a["verts"][~a["probe"]], b["verts"][~b["probe"]])
        V, T = b["verts"], b["tris"]
        n0 = np.cross(a["verts"][T[:, 1]] - a["verts"][T[:, 0]],
                      a["verts"][T[:, 2]] - a["verts"][T[:, 0]])
        n1 = np.cross(V[T[:, 1]] - V[T[:, 0]], V[T[:, 2]] - V[T[:, 0]])
        # Every triangle keeps its orientation: none folds.
        assert (np.einsum("ij,ij->i", n0, n1) > 0).all()
        # Still in the polygon's plane.
        normal = n0.sum(0) / np.linalg.norm(n0.sum(0))
        np.testing.assert_allclose((V - a["verts"]) @ normal, 0.0, atol=1e-12)
