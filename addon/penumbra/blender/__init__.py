"""The add-on's Blender layer: gathering the selection with ``foreach_get`` (``export``),
making objects, images and glTF files from a bake (``import_``, ``lightmaps``,
``lightmap_preview``, ``gltf_out``), and the operator, settings and panel (``operators``,
``props``, ``ui``). The meaning of materials, lights and settings lives in ``io``."""
