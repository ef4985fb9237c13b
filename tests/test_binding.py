"""penumbra._core from plain Python: scene in, threaded job, bake out, errors."""

import json
import threading
import time

import numpy as np
import pytest

from penumbra import BakeError, _core


def plane_under_square_light(n=1, element_size=None):
    """A 2 m floor (split into n×n quads) under a 0.5 m square light 1 m up, facing down."""
    xs = np.linspace(-1.0, 1.0, n + 1)
    gx, gy = np.meshgrid(xs, xs, indexing="ij")
    positions = np.stack([gx.ravel(), gy.ravel(), np.zeros(gx.size)], axis=1)
    quads = []
    for i in range(n):
        for j in range(n):
            a = i * (n + 1) + j
            quads.append([a, a + n + 1, a + n + 2, a + 1])  # counter-clockwise from +Z
    quads = np.array(quads)
    light = np.array([[-0.25, 0.25, 1.0], [0.25, 0.25, 1.0], [0.25, -0.25, 1.0], [-0.25, -0.25, 1.0]])
    settings = {"indirect": False}
    if element_size:
        settings.update(element_size=element_size, penumbra_element_size=element_size)
    return {
        "meshes": [
            {
                "name": "Floor",
                "positions": positions,
                "polygon_vertices": quads.ravel(),
                "polygon_counts": np.full(len(quads), 4),
                "albedo": np.full((len(quads), 3), 0.8),
            }
        ],
        "lights": [{"name": "Lamp", "polygon": light, "radiance": np.array([10.0, 10.0, 10.0])}],
        "settings": settings,
    }


def error_of(scene):
    with pytest.raises(BakeError) as info:
        _core.validate(scene)
    return info.value


def test_bake_error_is_reexported():
    assert BakeError is _core.BakeError
    assert issubclass(BakeError, Exception)


def test_dict_scene_becomes_the_scene_json_the_cli_reads():
    text = _core.scene_json(plane_under_square_light())
    data = json.loads(text)
    assert data["format"] == "penumbra-scene" and data["version"] == 1
    assert data["meshes"][0]["polygons"] == [[0, 2, 3, 1]]
    assert data["lights"][0]["radiance"] == [10.0, 10.0, 10.0]
    assert _core.validate(text) == []


def test_lists_and_uniform_colours_are_accepted():
    scene = plane_under_square_light()
    m = scene["meshes"][0]
    m["positions"] = m["positions"].tolist()
    m["albedo"] = [0.5, 0.5, 0.5]
    m["emission"] = np.zeros(3, dtype=np.float32)
    data = json.loads(_core.scene_json(scene))
    assert data["meshes"][0]["albedo"] == [0.5, 0.5, 0.5]


def test_nan_position_names_mesh_and_field():
    scene = plane_under_square_light()
    scene["meshes"][0]["positions"][1, 2] = np.nan
    e = error_of(scene)
    assert e.kind == "invalid"
    assert "Floor" in e.object and e.field.startswith("positions")
    assert "Floor" in str(e) and "positions" in str(e)


def test_bad_polygon_counts_name_the_field():
    scene = plane_under_square_light()
    scene["meshes"][0]["polygon_counts"] = np.array([5])
    e = error_of(scene)
    assert (e.kind, e.field) == ("invalid", "polygon_counts")


def test_bad_shape_names_the_field():
    scene = plane_under_square_light()
    scene["meshes"][0]["positions"] = np.zeros((4, 2))
    e = error_of(scene)
    assert e.field == "positions" and "(N, 3)" in str(e)


def test_unknown_light_field_is_refused_like_scene_json():
    scene = plane_under_square_light()
    scene["lights"][0]["colour"] = [1, 1, 1]
    e = error_of(scene)
    assert e.kind == "invalid" and "Lamp" in e.object and "colour" in str(e)


def test_zero_area_light_names_the_light():
    scene = plane_under_square_light()
    scene["lights"][0]["polygon"] = np.zeros((4, 3))
    e = error_of(scene)
    assert e.kind == "invalid" and "Lamp" in e.object


def test_wrong_version_and_bad_setting():
    assert error_of('{"format": "penumbra-scene", "version": 99}').kind == "format"
    scene = plane_under_square_light()
    scene["settings"]["convergence"] = 2.0
    e = error_of(scene)
    assert (e.kind, e.field) == ("setting", "convergence")


def test_nothing_to_bake():
    scene = plane_under_square_light()
    scene["lights"] = []
    assert error_of(scene).kind == "empty"


def test_tolerance_setting_refines_and_is_checked():
    # A tighter tolerance gives more elements, each refinement pass counted (issue 13). At
    # 3 % the starting lattice already meets it on this smooth field (no pass splits).
    counts, passes = [], []
    for tol in (0.03, 0.001):
        scene = plane_under_square_light()
        scene["settings"]["tolerance"] = tol
        stats = _core.bake(scene)["stats"]
        counts.append(stats["N_e"])
        passes.append(stats["refine_passes"])
    assert passes[1] >= 1 and passes[1] >= passes[0]
    assert counts[1] > counts[0]
    scene = plane_under_square_light()
    scene["settings"]["tolerance"] = 0.0
    e = error_of(scene)
    assert (e.kind, e.field) == ("setting", "tolerance")


def test_vertex_values_are_fitted_unless_asked_for_exact():
    # Under a square light the floor's light is concave near its peak, so linear
    # interpolation of the exact vertex values reads low between them: the fit lifts the
    # vertices there, on the same mesh, each by at most 0.4 × tolerance × (light + floor).
    baked = {}
    for mode in ("fitted", "exact"):
        scene = plane_under_square_light()
        scene["settings"]["vertex_values"] = mode
        baked[mode] = _core.bake(scene)["meshes"][0]
    f, e = baked["fitted"], baked["exact"]
    assert np.array_equal(f["positions"], e["positions"])
    assert np.array_equal(f["triangles"], e["triangles"])
    fc, ec = f["colors"].astype(np.float64), e["colors"].astype(np.float64)
    centre = np.argmin(np.linalg.norm(f["positions"][:, :2], axis=1))
    assert fc[centre, 0] > ec[centre, 0]
    assert fc.sum() > ec.sum()
    bound = 0.4 * 0.01 * (ec + 0.01 * ec.max(axis=0)) * (1 + 1e-5) + 1e-7
    assert (np.abs(fc - ec) <= bound).all()
    scene = plane_under_square_light()
    scene["settings"]["vertex_values"] = "sampled"
    e = error_of(scene)
    assert (e.kind, e.field) == ("setting", "vertex_values")


def test_errors_arrive_through_the_job_too():
    scene = plane_under_square_light()
    scene["settings"]["element_size"] = -1.0
    job = _core.start_bake(scene)
    with pytest.raises(BakeError) as info:
        job.result()
    assert info.value.kind == "setting"
    assert job.done()


def test_cancel_stops_the_bake():
    # Fine elements make a bake long enough to be caught running.
    job = _core.start_bake(plane_under_square_light(n=8, element_size=0.004))
    stage, fraction = job.progress()
    assert isinstance(stage, str) and 0.0 <= fraction <= 1.0
    job.cancel()
    assert job.cancelled()
    t0 = time.perf_counter()
    with pytest.raises(BakeError) as info:
        job.result()
    assert info.value.kind == "cancelled"
    assert time.perf_counter() - t0 < 30.0
    assert job.done()


def test_bake_returns_numpy_arrays_per_mesh():
    result = _core.bake(plane_under_square_light(n=2))
    assert set(result) == {"meshes", "stats", "warnings"}
    (m,) = result["meshes"]
    assert m["name"] == "Floor"
    v, t = len(m["positions"]), len(m["triangles"])
    assert v >= 9 and t >= 8
    assert m["positions"].shape == (v, 3) and m["positions"].dtype == np.float64
    assert m["triangles"].shape == (t, 3) and m["triangles"].dtype == np.uint32
    assert m["colors"].shape == (v, 3) and m["colors"].dtype == np.float32
    assert m["source_polygon"].shape == (t,) and m["source_polygon"].dtype == np.uint32
    assert m["relation"].shape == (t, 1) and m["relation"].dtype == np.uint8
    assert m["triangles"].max() < v and m["source_polygon"].max() < 4
    assert np.isfinite(m["colors"]).all() and (m["colors"] >= 0).all()
    assert set(np.unique(m["relation"])) <= {1, 2, 3}
    assert result["stats"]["N_e"] == t
    # Unoccluded floor right under the light: lit, and brighter than the corners.
    centre = np.argmin(np.linalg.norm(m["positions"][:, :2], axis=1))
    corner = np.argmax(np.linalg.norm(m["positions"][:, :2], axis=1))
    assert m["colors"][centre, 0] > m["colors"][corner, 0] > 0.0


def test_job_is_polled_to_the_end_while_python_runs():
    job = _core.start_bake(plane_under_square_light(n=4))
    seen = set()
    while True:  # polled at least once, even when the bake is already over
        seen.add(job.progress()[0])
        if job.done():
            break
        time.sleep(0.001)
    result = job.result()
    assert result["meshes"][0]["triangles"].shape[1] == 3
    assert seen and all(isinstance(s, str) for s in seen)
    # result() can be asked again and gives the same bake.
    again = job.result()
    assert np.array_equal(again["meshes"][0]["colors"], result["meshes"][0]["colors"])


def test_the_gil_is_released_during_a_blocking_bake():
    # If the bake held the GIL, this thread could not count while the other one is inside it.
    state = {"inside": False, "done": False}

    def bake():
        state["inside"] = True
        try:
            _core.bake(plane_under_square_light(n=4, element_size=0.02))
        finally:
            state["inside"] = False
            state["done"] = True

    t = threading.Thread(target=bake)
    t.start()
    counted = 0
    while not state["done"]:
        if state["inside"]:
            counted += 1
    t.join()
    assert counted > 100


def test_float_polygon_vertices_are_refused_not_truncated():
    scene = plane_under_square_light()
    m = scene["meshes"][0]
    m["polygon_vertices"] = m["polygon_vertices"].astype(np.float64) + 0.7
    e = error_of(scene)
    assert (e.kind, e.field) == ("invalid", "polygon_vertices")
    assert "Floor" in e.object and "integers" in str(e)
    m["polygon_vertices"] = np.round(m["polygon_vertices"] - 0.7).astype(np.float32)
    assert error_of(scene).field == "polygon_vertices"  # even when whole: a float is no index
    scene = plane_under_square_light()
    scene["meshes"][0]["polygon_counts"] = [4.0]
    assert error_of(scene).field == "polygon_counts"


def test_unsigned_indices_past_int64_are_reported_as_written():
    scene = plane_under_square_light()
    m = scene["meshes"][0]
    v = m["polygon_vertices"].astype(np.uint64)
    v[3] = np.uint64(2**64 - 1)
    m["polygon_vertices"] = v
    e = error_of(scene)
    assert e.field == "polygon_vertices[3]"
    assert "18446744073709551615" in str(e) and "-1" not in str(e)
    # In range, unsigned indices are fine.
    m["polygon_vertices"] = plane_under_square_light()["meshes"][0]["polygon_vertices"].astype(np.uint32)
    assert _core.validate(scene) == []


def test_complex_and_boolean_coordinates_are_refused():
    scene = plane_under_square_light()
    scene["meshes"][0]["positions"] = scene["meshes"][0]["positions"] + 0j
    e = error_of(scene)
    assert (e.field, "complex" in str(e)) == ("positions", True)
    scene = plane_under_square_light()
    scene["meshes"][0]["albedo"] = np.ones((1, 3), dtype=bool)
    assert error_of(scene).field == "albedo"
    # Integer coordinates are real numbers: accepted.
    scene = plane_under_square_light()
    scene["meshes"][0]["positions"] = scene["meshes"][0]["positions"].astype(np.int32)
    assert _core.validate(scene) == []


def test_settings_and_lights_by_position_are_refused():
    scene = plane_under_square_light()
    scene["settings"] = [0.05]
    e = error_of(scene)
    assert "settings" in str(e) and "got a list" in str(e)
    scene = plane_under_square_light()
    scene["lights"] = [["Lamp", scene["lights"][0]["polygon"], [10.0, 10.0, 10.0]]]
    e = error_of(scene)
    assert "lights[0]" in str(e) and "got a list" in str(e)


def test_format_errors_name_the_path():
    scene = plane_under_square_light()
    scene["lights"][0]["radiance"] = [1.0, 1.0]
    e = error_of(scene)
    assert (e.kind, e.field) == ("invalid", "radiance")
    assert "Lamp" in e.object and "line" not in str(e)
