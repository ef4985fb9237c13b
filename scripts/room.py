"""The demo scene, after the seed paper's Fig. 11: a room with a table and a chair under a
square area light. Built from bpy.data only, so the same code runs in the bpy module
(Blender 5) and in Debian's Blender 3.4.
"""

import bpy

ROOM = (4.0, 4.0, 2.5)  # x, y extent (centred on the origin) and height


def _material(name, color):
    mat = bpy.data.materials.get(name) or bpy.data.materials.new(name)
    mat.diffuse_color = (color[0], color[1], color[2], 1.0)
    if bpy.app.version < (5, 0, 0):  # node trees are always on from Blender 5
        mat.use_nodes = True
    bsdf = next((n for n in mat.node_tree.nodes if n.type == "BSDF_PRINCIPLED"), None)
    if bsdf is not None:
        bsdf.inputs["Base Color"].default_value = (color[0], color[1], color[2], 1.0)
    return mat


def _object(name, verts, faces, material, collection):
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(verts, [], faces)
    mesh.update()
    mesh.materials.append(material)
    obj = bpy.data.objects.new(name, mesh)
    collection.objects.link(obj)
    return obj


def _quad(name, corners, material, collection):
    """One quad; ``corners`` counter-clockwise seen from the side it faces."""
    return _object(name, corners, [(0, 1, 2, 3)], material, collection)


def _box_parts(lo, hi, base=0):
    (x0, y0, z0), (x1, y1, z1) = lo, hi
    verts = [(x0, y0, z0), (x1, y0, z0), (x1, y1, z0), (x0, y1, z0),
             (x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)]
    # Outward-facing, counter-clockwise seen from outside.
    faces = [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7)]
    return verts, [tuple(base + i for i in f) for f in faces]


def _boxes(name, boxes, material, collection):
    verts, faces = [], []
    for lo, hi in boxes:
        v, f = _box_parts(lo, hi, len(verts))
        verts += v
        faces += f
    return _object(name, verts, faces, material, collection)


def build_room(scene=None, light_power=80.0):
    """Adds the room to ``scene`` (default: the context scene); returns (meshes, light)."""
    scene = scene or bpy.context.scene
    coll = bpy.data.collections.new("Room")
    scene.collection.children.link(coll)
    hx, hy, h = ROOM[0] / 2, ROOM[1] / 2, ROOM[2]

    white = _material("Room White", (0.75, 0.75, 0.75))
    red = _material("Room Red", (0.7, 0.12, 0.1))
    green = _material("Room Green", (0.12, 0.55, 0.15))
    wood = _material("Table Wood", (0.55, 0.35, 0.18))
    blue = _material("Chair Blue", (0.15, 0.25, 0.6))

    meshes = [
        _quad("Floor", [(-hx, -hy, 0), (hx, -hy, 0), (hx, hy, 0), (-hx, hy, 0)], white, coll),
        _quad("Ceiling", [(-hx, -hy, h), (-hx, hy, h), (hx, hy, h), (hx, -hy, h)], white, coll),
        _quad("Wall Left", [(-hx, -hy, 0), (-hx, hy, 0), (-hx, hy, h), (-hx, -hy, h)], red, coll),
        _quad("Wall Right", [(hx, -hy, 0), (hx, -hy, h), (hx, hy, h), (hx, hy, 0)], green, coll),
        _quad("Wall Back", [(-hx, hy, 0), (hx, hy, 0), (hx, hy, h), (-hx, hy, h)], white, coll),
        _quad("Wall Front", [(-hx, -hy, 0), (-hx, -hy, h), (hx, -hy, h), (hx, -hy, 0)], white, coll),
    ]
    leg = 0.06
    top = ((-0.7, -0.45, 0.72), (0.7, 0.45, 0.78))
    legs = [((x, y, 0.0), (x + leg, y + leg, 0.72)) for x in (-0.66, 0.6) for y in (-0.41, 0.35)]
    meshes.append(_boxes("Table", [top] + legs, wood, coll))
    cx, cy = 0.2, -0.95
    seat = ((cx - 0.22, cy - 0.22, 0.42), (cx + 0.22, cy + 0.22, 0.46))
    back = ((cx - 0.22, cy - 0.26, 0.46), (cx + 0.22, cy - 0.22, 0.95))
    chair_legs = [((x, y, 0.0), (x + 0.04, y + 0.04, 0.42)) for x in (cx - 0.22, cx + 0.18) for y in (cy - 0.22, cy + 0.18)]
    meshes.append(_boxes("Chair", [seat, back] + chair_legs, blue, coll))

    data = bpy.data.lights.new("Ceiling Light", "AREA")
    data.shape = "SQUARE"
    data.size = 0.8
    data.energy = light_power
    light = bpy.data.objects.new("Ceiling Light", data)
    light.location = (0.0, 0.0, h - 0.02)  # Blender's area light shines down its -Z
    coll.objects.link(light)
    return meshes, light


def add_camera(scene=None):
    from mathutils import Vector

    scene = scene or bpy.context.scene
    cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    cam.location = (1.55, -1.85, 1.75)
    direction = Vector((0.0, 0.1, 0.55)) - cam.location
    cam.rotation_euler = direction.to_track_quat("-Z", "Y").to_euler()
    cam.data.lens = 20
    scene.collection.objects.link(cam)
    scene.camera = cam
    return cam


def select_only(view_layer, objects):
    for o in view_layer.objects:
        o.select_set(False)
    for o in objects:
        o.select_set(True)
    if objects:
        view_layer.objects.active = objects[0]
