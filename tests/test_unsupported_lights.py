"""A light the bake cannot model (here: shadowless) is left out with one warning, and the
rest of the bake goes on (issue 14); before, it stopped the whole bake."""

import bpy
import numpy as np

import cycles_ref as cr
from test_scope_cycles import _build


def _floor_peak():
    col = bpy.data.objects["Floor_baked"].data.color_attributes[0].data
    c = np.empty(len(col) * 4, dtype=np.float32)
    col.foreach_get("color", c)
    return float(c.reshape(-1, 4)[:, 0].max())


def test_shadowless_light_is_skipped_with_one_warning():
    _build(1)
    for o in bpy.context.scene.objects:
        o.select_set(o.name == "Floor")
    settings = bpy.context.scene.penumbra
    settings.scope = "SELECTED"
    settings.use_indirect = False
    assert bpy.ops.penumbra.bake() == {"FINISHED"}
    alone = _floor_peak()
    assert "warning" not in settings.last_summary

    extra = cr.add_light("POINT", location=(0.5, 0.5, 1.0), name="NoShadow", energy=500.0)
    extra.data.use_shadow = False
    assert bpy.ops.penumbra.bake() == {"FINISHED"}
    assert "1 warning" in settings.last_summary
    # The shadowless light added nothing; the lamp's light is all there.
    assert abs(_floor_peak() - alone) <= 1e-6 * alone
