"""scripts/bake.py from the command line: in a real `blender -b` (Debian's Blender 3.4,
whose Python is the system's) and with the bpy module."""

import json
import os
import struct
import subprocess
import sys

import pytest
from conftest import BLENDER, ROOT, SCRIPTS

BAKE = os.path.join(SCRIPTS, "bake.py")
needs_blender = pytest.mark.skipif(BLENDER is None, reason="Debian's blender is not installed (scripts/setup installs it as root)")

BUILD_ROOM = """
import sys
sys.path.insert(0, {scripts!r})
import bpy, room
bpy.ops.wm.read_factory_settings(use_empty=True)
meshes, light = room.build_room()
room.select_only(bpy.context.view_layer, {select})
bpy.ops.wm.save_as_mainfile(filepath={path!r})
"""

REPORT = """
import bpy, json
coll = bpy.data.collections.get("Penumbra Bake")
objs = sorted(coll.objects, key=lambda o: o.name) if coll else []
print("REPORT" + json.dumps({
    "version": list(bpy.app.version),
    "baked": [o.name for o in objs],
    "colors": [o.data.color_attributes.active_color.name for o in objs],
    "triangles": sum(len(o.data.polygons) for o in objs),
    "summary": bpy.context.scene.penumbra.last_summary if hasattr(bpy.context.scene, "penumbra") else None,
}))
"""


def run(cmd, timeout=900):
    return subprocess.run(cmd, capture_output=True, text=True, timeout=timeout, stdin=subprocess.DEVNULL, cwd=ROOT)


def blender_python(expr, blend=None):
    cmd = [BLENDER, "-b", "--factory-startup"] + ([blend] if blend else []) + ["--python-exit-code", "1", "--python-expr", expr]
    return run(cmd)


def room_blend(path, select="meshes + [light]"):
    """The demo room written by Debian's Blender itself, so that 3.4 can read it back."""
    r = blender_python(BUILD_ROOM.format(scripts=SCRIPTS, select=select, path=str(path)))
    assert r.returncode == 0 and os.path.isfile(path), r.stdout + r.stderr
    return str(path)


def report(blend):
    """What the baked .blend holds, read back with the bpy module in a fresh process."""
    code = "import bpy; bpy.ops.wm.open_mainfile(filepath=%r)\n%s" % (str(blend), REPORT)
    r = run([sys.executable, "-c", code])
    assert r.returncode == 0, r.stdout + r.stderr
    line = next(x for x in r.stdout.splitlines() if x.startswith("REPORT"))
    return json.loads(line[len("REPORT") :])


ROOM_BAKED = sorted(n + "_baked" for n in ["Floor", "Ceiling", "Wall Left", "Wall Right", "Wall Back", "Wall Front", "Table", "Chair"])


@needs_blender
def test_blender_b_bakes_a_file_it_wrote(tmp_path):
    scene = room_blend(tmp_path / "scene.blend")
    out, glb = tmp_path / "baked.blend", tmp_path / "baked.glb"
    r = run([BLENDER, "-b", "--factory-startup", scene, "--python", BAKE, "--", "--output", str(out), "--quality", "draft", "--gltf", str(glb)])
    assert r.returncode == 0, r.stdout + r.stderr
    assert "Penumbra: baked 8 objects" in r.stdout
    assert out.is_file() and glb.is_file() and glb.stat().st_size > 1000
    got = report(out)
    assert got["baked"] == ROOM_BAKED
    assert set(got["colors"]) == {"Radiosity"}
    assert got["triangles"] > 0


@needs_blender
def test_blender_b_reports_a_missing_file(tmp_path):
    r = run([BLENDER, "-b", "--factory-startup", "--python", BAKE, "--", str(tmp_path / "nope.blend"), "--output", str(tmp_path / "x.blend")])
    assert r.returncode != 0
    assert "no such file" in r.stderr


@needs_blender
def test_blender_b_reports_nothing_to_bake(tmp_path):
    scene = room_blend(tmp_path / "scene.blend", select="[]")
    r = run([BLENDER, "-b", "--factory-startup", scene, "--python", BAKE, "--", "--output", str(tmp_path / "x.blend")])
    assert r.returncode != 0
    assert "nothing to bake" in r.stderr and "--all" in r.stderr
    assert not (tmp_path / "x.blend").exists()


def test_bpy_module_bakes_all_visible_meshes(tmp_path):
    import bpy
    import room

    bpy.ops.wm.read_factory_settings(use_empty=True)
    room.build_room()
    room.select_only(bpy.context.view_layer, [])
    scene = str(tmp_path / "scene5.blend")
    bpy.ops.wm.save_as_mainfile(filepath=scene, copy=True)
    out, glb = tmp_path / "sub" / "baked.blend", tmp_path / "baked.glb"
    r = run([sys.executable, BAKE, scene, "--output", str(out), "--all", "--quality", "draft", "--hide-originals", "--gltf", str(glb)])
    assert r.returncode == 0, r.stdout + r.stderr
    assert report(out)["baked"] == ROOM_BAKED
    # The .glb carries the baked colours as vertex colours.
    data = glb.read_bytes()
    n = struct.unpack("<I", data[12:16])[0]
    gltf = json.loads(data[20 : 20 + n])
    assert sorted(m["name"] for m in gltf["meshes"]) == ROOM_BAKED
    assert all("COLOR_0" in p["attributes"] for m in gltf["meshes"] for p in m["primitives"])


def test_bpy_module_reports_a_missing_file(tmp_path):
    r = run([sys.executable, BAKE, str(tmp_path / "nope.blend"), "--output", str(tmp_path / "x.blend")])
    assert r.returncode != 0 and "no such file" in r.stderr


def test_bpy_module_needs_an_output(tmp_path):
    r = run([sys.executable, BAKE, str(tmp_path / "nope.blend")])
    assert r.returncode != 0 and "--output" in r.stderr
