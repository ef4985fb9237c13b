"""Penumbra: radiosity baked onto discontinuity meshes.

The package is the Blender add-on and, through ``penumbra._core``, the Python binding of
the Rust library. ``import penumbra`` needs no ``bpy``; only ``register()`` does, so the
binding is usable from plain Python too.
"""

bl_info = {
    "name": "Penumbra",
    "author": "Penumbra developers",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "location": "Properties > Render > Radiosity",
    "description": "Bake radiosity onto meshes that follow the shadow boundaries exactly",
    "category": "Render",
}

try:
    from . import _core
except ImportError as e:  # pragma: no cover - depends on the build
    raise ImportError(
        "penumbra._core (the compiled Rust module) is missing: build it with "
        "scripts/setup, or install the extension zip made by scripts/package"
    ) from e

BakeError = _core.BakeError

__all__ = ["BakeError", "register", "unregister"]


def _modules():
    # Imported here, not at the top, so that the binding works without bpy.
    from .blender import operators, props, ui

    return (props, operators, ui)


def register():
    for m in _modules():
        m.register()


def unregister():
    for m in reversed(_modules()):
        m.unregister()
