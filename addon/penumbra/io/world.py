"""Blender's world → the scene JSON's ``settings.world``: the radiance of a uniform world.

Cycles lights a bake with the world as with any light (its Diffuse bake's direct pass holds
it), so a grey world over a floor adds ``albedo · L`` where nothing hides the sky. The core
takes one uniform radiance ``L`` per channel (``direct/world.rs``); this reads it from the
world's node tree the way Cycles sees it: the Background node feeding the active World
Output, ``L = Color · Strength``. A textured world (an Environment or Image Texture on the
colour) is taken as its image's mean colour, with one warning; anything else the Background
does not hold (a sky texture, mixes of shaders) is a warning and the socket's own colour.
A world without nodes (before Blender 5) lights with its plain ``color``.
"""
from __future__ import annotations

import numpy as np

from .materials import _float, _follow, _image_mean, _rgb


def world_radiance(world, warnings: list | None = None):
    """``[r, g, b]`` radiance of ``world`` (a ``bpy.types.World`` or None), or None when the
    world is absent or black."""
    if warnings is None:
        warnings = []
    warn = warnings.append
    if world is None:
        return None
    where = f'World "{world.name}"'
    nt = getattr(world, "node_tree", None)
    # Blender 5 always uses the node tree (`use_nodes` is deprecated there and reading it
    # warns); before 5, a world with nodes off lights with its plain colour.
    if nt is None or (_before_blender_5() and not world.use_nodes):
        col = np.array(world.color[:3], dtype=np.float64)
        return _positive(col)
    outputs = [n for n in nt.nodes if n.bl_idname == "ShaderNodeOutputWorld"]
    out = next((n for n in outputs if getattr(n, "is_active_output", False)), None)
    out = out or (outputs[0] if outputs else None)
    if out is None:
        return None
    src = _follow(out.inputs["Surface"])
    if src is None:
        return None
    node, _ = src
    if node.bl_idname != "ShaderNodeBackground":
        warn(f"{where}: the surface is '{node.name}' ({node.bl_idname}), not a Background; "
             "the world gives no light in this bake")
        return None
    color_sock = node.inputs["Color"]
    feed = _follow(color_sock)
    if feed is not None and feed[0].bl_idname == "ShaderNodeTexEnvironment" and feed[0].image is not None:
        warn(f"{where}: a textured world is baked as its image's mean colour")
        col = _image_mean(feed[0].image, warn)
    else:
        if feed is not None and feed[0].bl_idname == "ShaderNodeTexImage":
            warn(f"{where}: a textured world is baked as its image's mean colour")
        col = _rgb(color_sock, warn, where)
    strength = _float(node.inputs["Strength"], warn, where)
    return _positive(col * strength)


def _before_blender_5() -> bool:
    try:
        import bpy
    except ImportError:  # outside Blender (unit tests of this module): a modern world
        return False
    return bpy.app.version < (5, 0, 0)


def _positive(col):
    col = np.nan_to_num(np.asarray(col, dtype=np.float64), nan=0.0, posinf=0.0, neginf=0.0)
    col = np.maximum(col, 0.0)
    return [float(x) for x in col] if col.max() > 0.0 else None
