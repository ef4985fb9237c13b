"""Optional preview of a lightmap on the original objects.

With Lighting Only the lightmap holds E/π, so the preview multiplies each Principled BSDF's
Base Color by it; otherwise the lightmap holds the full outgoing radiance and is shown as
the BSDF's emission (strength 1).

Each previewed object gets its own copies of its materials, linked to the object
(``slot.link = 'OBJECT'``), so that objects sharing a material each show their own lightmap
while the user's materials and meshes stay as they were. ``hide`` (turning the preview off,
or the next preview) links the slots back as they were and deletes the copies. The nodes
added are named ``Penumbra Lightmap …``.
"""

from .export import LIGHTMAP_UV

PREFIX = "Penumbra Lightmap"
# On a preview copy: the slot link and object-level material it stands in for.
_LINK = "penumbra_preview_link"
_WAS = "penumbra_preview_was"


def show(obj, image, lighting_only):
    """Shows ``image`` on ``obj`` through object-linked copies of its materials that have a
    Principled BSDF (an earlier preview of ``obj`` is taken out first); returns the number
    of materials previewed."""
    hide(obj)
    for slot in obj.material_slots:
        mat = slot.material
        if mat is None or mat.node_tree is None:
            continue
        if not any(n.type == "BSDF_PRINCIPLED" for n in mat.node_tree.nodes):
            continue
        copy = mat.copy()
        copy.name = "%s (%s %s)" % (mat.name, PREFIX, obj.name)
        copy[_LINK] = slot.link
        if slot.link == "OBJECT":
            copy[_WAS] = mat
        slot.link = "OBJECT"
        slot.material = copy
    return apply(obj, image, lighting_only)


def hide(obj):
    """Takes ``obj``'s preview out: slots linked back as they were, copies deleted."""
    import bpy

    copies = []
    for slot in obj.material_slots:
        mat = slot.link == "OBJECT" and slot.material
        if not mat or _LINK not in mat:
            continue
        if mat[_LINK] == "OBJECT":
            slot.material = mat.get(_WAS)
        else:
            slot.link = "DATA"
        copies.append(mat)
    for mat in copies:
        if mat.name in bpy.data.materials:
            bpy.data.materials.remove(mat)
    return len(copies)


def hide_all(objects):
    """``hide`` on every object; returns the number of materials restored."""
    return sum(hide(obj) for obj in objects if obj.type == "MESH")


def apply(obj, image, lighting_only):
    """Adds the preview nodes to every material of ``obj`` that has a Principled BSDF, in
    place (``show`` and the glTF export call it on copies); returns the number of materials
    changed."""
    changed = 0
    for slot in obj.material_slots:
        mat = slot.material
        if mat is None or mat.node_tree is None:
            continue
        tree = mat.node_tree
        bsdfs = [n for n in tree.nodes if n.type == "BSDF_PRINCIPLED"]
        if not bsdfs:
            continue
        _remove_old(tree)
        uv = tree.nodes.new("ShaderNodeUVMap")
        uv.name = uv.label = PREFIX + " UV"
        uv.uv_map = LIGHTMAP_UV
        tex = tree.nodes.new("ShaderNodeTexImage")
        tex.name = tex.label = PREFIX + " Image"
        tex.image = image
        tex.extension = "EXTEND"
        x, y = bsdfs[0].location
        uv.location = (x - 700, y + 300)
        tex.location = (x - 500, y + 300)
        tree.links.new(uv.outputs["UV"], tex.inputs["Vector"])
        for bsdf in bsdfs:
            if lighting_only:
                _multiply_base(tree, bsdf, tex)
            else:
                emit = bsdf.inputs.get("Emission Color") or bsdf.inputs.get("Emission")
                tree.links.new(tex.outputs["Color"], emit)
                strength = bsdf.inputs.get("Emission Strength")
                if strength is not None and not strength.is_linked:
                    strength.default_value = 1.0
        changed += 1
    return changed


def _multiply_base(tree, bsdf, tex):
    base = bsdf.inputs["Base Color"]
    mul = tree.nodes.new("ShaderNodeMixRGB")
    mul.name = mul.label = PREFIX + " Multiply"
    mul.blend_type = "MULTIPLY"
    mul.inputs["Fac"].default_value = 1.0
    mul.location = (bsdf.location[0] - 250, bsdf.location[1] + 100)
    if base.is_linked:
        tree.links.new(base.links[0].from_socket, mul.inputs["Color1"])
    else:
        mul.inputs["Color1"].default_value = base.default_value
    tree.links.new(tex.outputs["Color"], mul.inputs["Color2"])
    tree.links.new(mul.outputs["Color"], base)


def _remove_old(tree):
    """Takes out an earlier preview, reconnecting what its Multiply node sat between."""
    for node in list(tree.nodes):
        if not node.name.startswith(PREFIX):
            continue
        if node.name.endswith("Multiply"):
            source = node.inputs["Color1"].links[0].from_socket if node.inputs["Color1"].is_linked else None
            for link in list(node.outputs["Color"].links):
                target = link.to_socket
                tree.links.remove(link)
                if source is not None:
                    tree.links.new(source, target)
                else:
                    target.default_value = node.inputs["Color1"].default_value
        tree.nodes.remove(node)
