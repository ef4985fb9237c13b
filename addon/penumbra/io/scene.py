"""The scene dict for ``penumbra._core`` from plain arrays: the pieces of the export that need
no Blender (corner order, light polygon areas, the settings), and the names the add-on
gives to what it makes."""

import numpy as np

# Element edge lengths as fractions of the scene's bounding-box diagonal: (outside penumbra,
# inside penumbra). Medium's outside size is the core's own default; its penumbra size is
# finer than the core's (element_size/2).
QUALITY_FRACTIONS = {
    "DRAFT": (1.0 / 12.0, 1.0 / 40.0),
    "MEDIUM": (1.0 / 25.0, 1.0 / 125.0),
    "HIGH": (1.0 / 50.0, 1.0 / 400.0),
}

# Relative error of the baked direct light that each preset refines to (the core's
# ``tolerance``). The sizes above are then bounds: elements start at the first, and are split
# where the light needs it, down to 1/16 of the second.
QUALITY_TOLERANCE = {
    "DRAFT": 0.03,
    "MEDIUM": 0.01,
    "HIGH": 0.003,
}


# Custom property of a baked object: the name of the object it was baked from.
SOURCE_KEY = "penumbra_source"

# The UV map lightmaps are baked onto (created by the add-on with Lightmap Pack when missing).
LIGHTMAP_UV = "Lightmap"

# Object types that evaluate to a mesh.
MESH_TYPES = {"MESH", "CURVE", "SURFACE", "FONT", "META"}


class ExportError(Exception):
    """Bad input found before the bake: the message names the object and the field."""


def loop_order(starts, counts, mirrored):
    """Loop indices polygon after polygon. A mirroring transform turns counter-clockwise
    into clockwise, so then each polygon's loops are reversed to keep its front."""
    total = int(counts.sum())
    offsets = np.concatenate(([0], np.cumsum(counts)[:-1])) if len(counts) else counts
    within = np.arange(total) - np.repeat(offsets, counts)
    if mirrored:
        within = np.repeat(counts, counts) - 1 - within
    return np.repeat(starts, counts) + within


def polygon_area(p):
    """Area of the planar polygon ``p`` ((n, 3) array); 0 for fewer than 3 or non-finite points."""
    if len(p) < 3 or not np.isfinite(p).all():
        return 0.0
    return 0.5 * float(np.linalg.norm(np.cross(p - p[0], np.roll(p, -1, axis=0) - p[0]).sum(axis=0)))


def settings_dict(settings, meshes):
    """The scene JSON's settings from the add-on's (``scene.penumbra``, read by attribute):
    element sizes from the quality preset as fractions of the diagonal of what is baked,
    the meshes (a light far off must not make every element coarse)."""
    pts = [np.asarray(m["positions"], dtype=np.float64).reshape(-1, 3)
           for m in meshes if len(m["positions"])]
    allp = np.concatenate(pts) if pts else np.zeros((1, 3))
    diag = float(np.linalg.norm(allp.max(axis=0) - allp.min(axis=0))) or 1.0
    if settings.use_custom_size:
        element, penumbra = settings.element_size, settings.penumbra_element_size
    else:
        coarse, fine = QUALITY_FRACTIONS[settings.quality]
        element, penumbra = coarse * diag, fine * diag
    out = {
        "element_size": float(element),
        "penumbra_element_size": float(min(penumbra, element)),
        "tolerance": float(QUALITY_TOLERANCE[settings.quality]),
        "indirect": bool(settings.use_indirect),
        "convergence": float(settings.convergence),
        "indirect_solver": str(settings.indirect_solver).lower(),
        "lighting_only": bool(settings.lighting_only),
    }
    # 0 leaves the core's default (half of the machine's memory).
    gb = float(getattr(settings, "max_memory_gb", 0.0))
    if gb > 0.0:
        out["max_memory"] = int(gb * (1 << 30))
    return out
