"""The "Bake Radiosity" operator. With a UI it is modal: the bake runs on the Rust thread
while a timer polls its progress, so Blender stays responsive and ESC cancels. Without a
UI (``blender -b``, the bpy module) it bakes synchronously. Either way the scene changes
only when a bake succeeds, in one undo step.
"""

import json
import time

import bpy

from .. import _core
from . import lightmap_preview, lightmaps
from .export import ExportError, _sources, export_scene
from .import_ import import_bake

# Words of the core's stage names ("shadow volumes", "discontinuity loops", "meshing", ...)
# in pipeline order, for one overall progress bar.
STAGES = ("validate", "shadow", "loop", "mesh", "direct", "indirect", "output")


def prepare(context, report):
    """The exported scene, or None after reporting why there is nothing sane to bake.

    For lightmaps, the objects get their "Lightmap" UV map first (made only where missing;
    ``export.uv_maps`` remembers those, to take them out again if the bake does not finish)
    and the UVs are checked before any time goes into the bake."""
    settings = context.scene.penumbra
    uv_maps = lightmaps.UvMaps()
    try:
        if settings.output != "MESH":
            uv_maps = lightmaps.ensure_uv_maps(_sources(list(context.selected_objects)), settings.lightmap_resolution)
        export = export_scene(context, settings)
        if settings.output != "MESH":
            lightmaps.check_uvs(export.scene["meshes"], settings.lightmap_resolution, settings.lightmap_margin)
        export.uv_maps = uv_maps
        # What the bake was started for: settings changed while it runs do not apply to it.
        export.output = settings.output
        export.lightmap = (int(settings.lightmap_resolution), int(settings.lightmap_margin))
        return export
    except (ExportError, _core.BakeError) as e:
        uv_maps.undo()
        report({"ERROR"}, ("Penumbra: %s" % e) if isinstance(e, _core.BakeError) else str(e))
        return None
    except Exception as e:  # noqa: BLE001 - a report, never a traceback; nothing changed
        uv_maps.undo()
        report({"ERROR"}, "Penumbra: could not read the scene: %s: %s" % (type(e).__name__, e))
        return None


def abandon(export):
    """A bake that did not finish leaves the scene as it was."""
    uv_maps = getattr(export, "uv_maps", None)
    if uv_maps is not None:
        uv_maps.undo()


def finish(context, export, result, seconds, report):
    """Turns a finished bake into objects and reports a one-line summary."""
    sources = []
    for obj in export.sources:
        try:
            sources.append(bpy.data.objects.get(obj.name))
        except ReferenceError:  # deleted while the bake ran
            sources.append(None)
    kept = [i for i, s in enumerate(sources) if s is not None]
    pairs = [(result["meshes"][i], sources[i]) for i in kept]
    settings = context.scene.penumbra
    output = getattr(export, "output", "MESH")
    resolution, margin = getattr(export, "lightmap", (0, 0))
    maps = []
    if output != "MESH":
        # Every lightmap is computed before anything is created: an error changes nothing.
        try:
            maps = lightmaps.compute(
                [export.scene["meshes"][i] for i in kept],
                [m for m, _ in pairs],
                resolution,
                margin,
            )
        except _core.BakeError as e:
            abandon(export)
            report({"ERROR"}, "Penumbra: %s" % e)
            return {"CANCELLED"}
    created = []
    if output != "LIGHTMAP":
        created = import_bake(
            context, {"meshes": [m for m, _ in pairs]}, [s for _, s in pairs], settings.hide_originals
        )
    images = lightmaps.store(maps)
    if settings.lightmap_preview:
        for (_, source), image in zip(pairs, images):
            lightmap_preview.show(source, image, settings.lighting_only)

    stats = result["stats"]
    elements = stats.get("N_e") or sum(len(m["triangles"]) for m in result["meshes"])
    vertices = stats.get("N_v") or sum(len(m["positions"]) for m in result["meshes"])
    n = len(created) if output != "LIGHTMAP" else len(images)
    summary = "Penumbra: baked %d object%s, %d elements, %d vertices in %.2f s" % (
        n,
        "" if n == 1 else "s",
        elements,
        vertices,
        seconds,
    )
    if images:
        r = resolution
        summary += ", %d lightmap%s %d×%d" % (len(images), "" if len(images) == 1 else "s", r, r)
    warnings = list(export.warnings) + list(result["warnings"])
    if warnings:
        summary += " (%d warning%s, see console)" % (len(warnings), "" if len(warnings) == 1 else "s")
        for w in warnings:
            print("Penumbra warning:", w)
    settings.last_summary = summary
    settings.last_stats = json.dumps(dict(stats, seconds=seconds))
    settings.last_outputs = json.dumps({"objects": [o.name for o in created], "images": [i.name for i in images]})
    report({"INFO"}, summary)
    return {"FINISHED"}


def bake_blocking(context, report):
    """The whole bake on the calling thread (GIL released while the core runs)."""
    export = prepare(context, report)
    if export is None:
        return {"CANCELLED"}
    t0 = time.perf_counter()
    try:
        result = _core.bake(export.scene)
    except _core.BakeError as e:
        abandon(export)
        report({"ERROR"}, "Penumbra: %s" % e)
        return {"CANCELLED"}
    return finish(context, export, result, time.perf_counter() - t0, report)


def has_ui(context):
    """False in ``blender -b`` and in the bpy module: there the bake runs synchronously."""
    return not bpy.app.background and context.window is not None


def overall_fraction(stage, fraction):
    """Progress of the whole bake in [0, 1]; 0 for a stage this add-on does not know."""
    name = stage.lower()
    # "indirect" contains "direct": look for it first.
    keys = sorted(STAGES, key=lambda k: k != "indirect")
    for key in keys:
        if key in name:
            return (STAGES.index(key) + fraction) / len(STAGES)
    return 0.0


class PENUMBRA_OT_bake(bpy.types.Operator):
    """Bake direct and indirect light of the selected meshes onto new meshes that follow the shadow boundaries"""

    bl_idname = "penumbra.bake"
    bl_label = "Bake Radiosity"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        return context.scene is not None

    def execute(self, context):
        return bake_blocking(context, self.report)

    def invoke(self, context, event):
        if not has_ui(context):
            return self.execute(context)
        self._export = prepare(context, self.report)
        if self._export is None:
            return {"CANCELLED"}
        try:
            self._job = _core.start_bake(self._export.scene)
        except _core.BakeError as e:
            abandon(self._export)
            self.report({"ERROR"}, "Penumbra: %s" % e)
            return {"CANCELLED"}
        self._t0 = time.perf_counter()
        self._shown = 0.0
        wm = context.window_manager
        self._timer = wm.event_timer_add(0.1, window=context.window)
        wm.progress_begin(0, 1000)
        wm.modal_handler_add(self)
        return {"RUNNING_MODAL"}

    def modal(self, context, event):
        if event.type == "ESC" and event.value == "PRESS":
            self._job.cancel()
            self._end(context)
            abandon(self._export)
            self.report({"WARNING"}, "Penumbra: bake cancelled, nothing changed")
            return {"CANCELLED"}
        if event.type != "TIMER":
            return {"PASS_THROUGH"}
        stage, fraction = self._job.progress()
        # Never backwards, even past a stage this add-on does not know.
        self._shown = max(self._shown, overall_fraction(stage, fraction))
        context.window_manager.progress_update(int(1000 * self._shown))
        context.workspace.status_text_set(
            "Penumbra: %s %d%%  (Esc to cancel)" % (stage, int(round(100 * fraction)))
        )
        if not self._job.done():
            return {"RUNNING_MODAL"}
        self._end(context)
        try:
            result = self._job.result()
        except _core.BakeError as e:
            abandon(self._export)
            self.report({"ERROR"}, "Penumbra: %s" % e)
            return {"CANCELLED"}
        return finish(context, self._export, result, time.perf_counter() - self._t0, self.report)

    def _end(self, context):
        wm = context.window_manager
        wm.event_timer_remove(self._timer)
        wm.progress_end()
        context.workspace.status_text_set(None)


def register():
    bpy.utils.register_class(PENUMBRA_OT_bake)


def unregister():
    bpy.utils.unregister_class(PENUMBRA_OT_bake)
