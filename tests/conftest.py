"""Tests run inside the bpy module (Blender 5 as a Python module) with the add-on
registered from addon/, as a user's Blender would load it."""

import os
import shutil
import sys

import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
ADDON = os.path.join(ROOT, "addon")
SCRIPTS = os.path.join(ROOT, "scripts")
sys.path[:0] = [ADDON, SCRIPTS]

import bpy  # noqa: E402
import numpy as np  # noqa: E402

import penumbra  # noqa: E402
import room  # noqa: E402

BLENDER = shutil.which("blender")


@pytest.fixture(scope="session", autouse=True)
def addon():
    penumbra.register()
    yield penumbra
    penumbra.unregister()


@pytest.fixture
def empty():
    bpy.ops.wm.read_factory_settings(use_empty=True)
    return bpy.context


@pytest.fixture
def room_scene(empty):
    """The demo room, meshes and light selected, draft quality so that bakes are quick."""
    meshes, light = room.build_room(empty.scene)
    room.select_only(empty.view_layer, meshes + [light])
    empty.scene.penumbra.quality = "DRAFT"
    return meshes, light


def snapshot():
    """Everything a failed or cancelled bake must leave as it was."""
    # matrix_world of objects made by script is only computed at the next depsgraph update,
    # which an operator call triggers: update first so that only real changes show.
    bpy.context.view_layer.update()
    objects = {}
    for o in bpy.data.objects:
        entry = [o.type, tuple(map(tuple, o.matrix_world)), o.hide_render, o.hide_viewport, o.select_get()]
        if o.type == "MESH":
            co = np.empty(len(o.data.vertices) * 3, dtype=np.float32)
            o.data.vertices.foreach_get("co", co)
            entry += [o.data.name, len(o.data.polygons), co.tobytes(), sorted(a.name for a in o.data.attributes)]
        objects[o.name] = entry
    return {
        "objects": objects,
        "meshes": sorted(m.name for m in bpy.data.meshes),
        "collections": sorted(c.name for c in bpy.data.collections),
        "materials": sorted(m.name for m in bpy.data.materials),
        "summary": bpy.context.scene.penumbra.last_summary,
    }


class Reports:
    """Collects operator reports, standing in for ``Operator.report``."""

    def __init__(self):
        self.items = []

    def __call__(self, level, message):
        self.items.append((set(level), message))

    def errors(self):
        return [m for level, m in self.items if "ERROR" in level]
