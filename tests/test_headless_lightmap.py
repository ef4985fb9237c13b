"""scripts/bake.py with lightmaps and glTF (bpy module), read back from the files it wrote:
the .glb a stock glTF viewer opens must show the bake."""

import json
import os
import struct
import subprocess
import sys

import numpy as np
import pytest
from conftest import ROOT, SCRIPTS

BAKE = os.path.join(SCRIPTS, "bake.py")
ROOM = ["Floor", "Ceiling", "Wall Left", "Wall Right", "Wall Back", "Wall Front", "Table", "Chair"]


def run(cmd, env=None, timeout=900):
    return subprocess.run(cmd, capture_output=True, text=True, timeout=timeout, stdin=subprocess.DEVNULL,
                          cwd=ROOT, env=dict(os.environ, **(env or {})))


def room_file(tmp_path, name="scene.blend"):
    import bpy
    import room

    bpy.ops.wm.read_factory_settings(use_empty=True)
    room.build_room()
    room.select_only(bpy.context.view_layer, [])
    path = str(tmp_path / name)
    bpy.ops.wm.save_as_mainfile(filepath=path, copy=True)
    return path


def read_glb(path):
    """(JSON, binary chunk) of a .glb."""
    data = open(path, "rb").read()
    n = struct.unpack("<I", data[12:16])[0]
    gltf = json.loads(data[20 : 20 + n])
    rest = data[20 + n :]
    m = struct.unpack("<I", rest[:4])[0]
    return gltf, rest[8 : 8 + m]


def accessor(gltf, binary, index):
    """An accessor's values as float rows (normalised integers scaled to [0, 1])."""
    acc = gltf["accessors"][index]
    view = gltf["bufferViews"][acc["bufferView"]]
    width = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4}[acc["type"]]
    dtype = {5126: np.float32, 5123: np.uint16, 5121: np.uint8, 5125: np.uint32}[acc["componentType"]]
    start = view.get("byteOffset", 0) + acc.get("byteOffset", 0)
    stride = view.get("byteStride", 0) or width * np.dtype(dtype).itemsize
    raw = np.frombuffer(binary, dtype=np.uint8, count=stride * acc["count"], offset=start).reshape(acc["count"], stride)
    vals = raw[:, : width * np.dtype(dtype).itemsize].copy().view(dtype).reshape(acc["count"], width).astype(np.float64)
    if acc.get("normalized") and dtype != np.float32:
        vals /= np.iinfo(dtype).max
    return vals


def test_vertex_colour_glb_is_unlit_with_the_bake_as_color_0(tmp_path):
    scene = room_file(tmp_path)
    out, glb = tmp_path / "baked.blend", tmp_path / "baked.glb"
    r = run([sys.executable, BAKE, scene, "--output", str(out), "--all", "--quality", "draft", "--gltf", str(glb)])
    assert r.returncode == 0, r.stdout + r.stderr
    gltf, binary = read_glb(glb)
    assert "KHR_materials_unlit" in gltf.get("extensionsUsed", [])
    colours = []
    for mesh in gltf["meshes"]:
        for prim in mesh["primitives"]:
            mat = gltf["materials"][prim["material"]]
            # Regression: the Emission material exported as a bare emissiveFactor [1, 1, 1].
            assert "KHR_materials_unlit" in mat.get("extensions", {}), mat
            assert "emissiveTexture" not in mat and mat.get("emissiveFactor", [0, 0, 0]) != [1, 1, 1]
            factor = mat.get("pbrMetallicRoughness", {}).get("baseColorFactor", [1, 1, 1, 1])
            assert np.allclose(factor[:3], 1.0)
            colours.append(accessor(gltf, binary, prim["attributes"]["COLOR_0"])[:, :3])
    c = np.concatenate(colours)
    # The bake, not white: lit and shadowed surfaces differ, and nothing is blank.
    assert c.min() < 0.05 and 0.05 < np.median(c) < 0.95


def test_gltf_holds_only_this_bake(tmp_path):
    # Regression: older bakes left in the "Penumbra Bake" collection were exported too.
    import bpy
    import room

    bpy.ops.wm.read_factory_settings(use_empty=True)
    meshes, light = room.build_room()
    room.select_only(bpy.context.view_layer, meshes + [light])
    bpy.context.scene.penumbra.quality = "DRAFT"
    assert bpy.ops.penumbra.bake() == {"FINISHED"}  # every object baked once
    room.select_only(bpy.context.view_layer, [bpy.data.objects["Floor"], light])
    scene = str(tmp_path / "rebake.blend")
    bpy.ops.wm.save_as_mainfile(filepath=scene, copy=True)
    glb = tmp_path / "floor.glb"
    r = run([sys.executable, BAKE, scene, "--output", str(tmp_path / "out.blend"), "--quality", "draft", "--gltf", str(glb)])
    assert r.returncode == 0, r.stdout + r.stderr
    gltf, _ = read_glb(glb)
    assert [m["name"] for m in gltf["meshes"]] == ["Floor_baked"]


def test_lightmap_glb_binds_the_image_on_the_lightmap_uvs(tmp_path):
    scene = room_file(tmp_path)
    out, glb = tmp_path / "lit.blend", tmp_path / "lit.glb"
    r = run([sys.executable, BAKE, scene, "--output", str(out), "--all", "--quality", "draft",
             "--lightmap", "32", "--margin", "2", "--gltf", str(glb)])
    assert r.returncode == 0, r.stdout + r.stderr
    assert "8 lightmaps 32×32" in r.stdout
    # Saved beside the .blend the bake ran in (the source file), and packed.
    assert (tmp_path / "lightmaps" / "Floor_radiosity.exr").is_file()
    gltf, _ = read_glb(glb)
    # The original meshes, not baked ones.
    assert sorted(m["name"] for m in gltf["meshes"]) == sorted(ROOM)
    for mesh in gltf["meshes"]:
        for prim in mesh["primitives"]:
            mat = gltf["materials"][prim["material"]]
            tex = mat["emissiveTexture"]
            # Engines read lightmaps from the second UV channel (Godot UV2, Unity uv2).
            assert tex.get("texCoord", 0) == 1 and "TEXCOORD_1" in prim["attributes"], (mesh["name"], prim["attributes"])
            image = gltf["images"][gltf["textures"][tex["index"]]["source"]]
            assert image["name"].endswith("_radiosity")
    # The .blend keeps the originals, their packed images and no baked objects.
    code = (
        "import bpy, json; bpy.ops.wm.open_mainfile(filepath=%r)\n"
        "print('REPORT' + json.dumps({'images': sorted(i.name for i in bpy.data.images if i.packed_file),"
        " 'baked': [o.name for o in bpy.data.objects if o.name.endswith('_baked')]}))" % str(out)
    )
    r = run([sys.executable, "-c", code])
    got = json.loads(next(x for x in r.stdout.splitlines() if x.startswith("REPORT"))[6:])
    assert got["baked"] == []
    assert got["images"] == sorted(n + "_radiosity" for n in ROOM)


def test_gltf_works_with_the_addon_installed_as_an_extension(tmp_path):
    # Regression: bake.py imported "penumbra.import_", which does not exist when the add-on
    # runs as the extension "bl_ext.user_default.penumbra".
    sys.path.insert(0, SCRIPTS)
    from package import package

    extension, _ = package(str(tmp_path / "dist"))
    scene = room_file(tmp_path)
    glb = tmp_path / "ext.glb"
    code = (
        "import sys, bpy\n"
        "r = bpy.ops.extensions.package_install_files(filepath=%r, repo='user_default', enable_on_install=True)\n"
        "assert r == {'FINISHED'}, r\n"
        "assert 'penumbra' not in sys.modules, 'the checkout must not be importable here'\n"
        "sys.path.insert(0, %r)\n"
        "sys.argv = ['bake.py', %r, '--output', %r, '--all', '--quality', 'draft', '--gltf', %r]\n"
        "import bake\n"
        "bake.main()\n"
    ) % (extension, SCRIPTS, scene, str(tmp_path / "ext.blend"), str(glb))
    r = run([sys.executable, "-c", code], env={"BLENDER_USER_RESOURCES": str(tmp_path / "user")})
    assert r.returncode == 0, r.stdout + r.stderr
    assert glb.is_file()
