"""The add-on's bpy-free layer: what a Blender scene means in the scene JSON's terms
(materials → albedo and emission, Blender lights → the core's lights, settings → the
settings dict, polygon corner order). It reads Blender data through its attributes only
and never imports ``bpy``, so it is tested without Blender (after glTF-Blender-IO's
``io/`` and ``blender/`` split)."""
