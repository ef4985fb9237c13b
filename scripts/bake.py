"""Headless bake of a .blend file.

    blender -b scene.blend --python scripts/bake.py -- --output baked.blend [--all] [--quality high] [--gltf baked.glb]
    blender -b scene.blend --python scripts/bake.py -- --output baked.blend --lightmap 512 [--margin 16] [--gltf lit.glb]
    python scripts/bake.py scene.blend --output baked.blend [...]        (bpy module)

Bakes the meshes selected in the file (every visible mesh with --all) with the selected
lights (every visible light when none is selected), and writes the result. With
--lightmap the light goes into an image per object on its "Lightmap" UV map instead of new
objects (both with --both); --gltf then writes the original objects with the lightmap as
their emissive texture on that UV map. Exits non-zero with a one-line reason on any failure.
"""

import argparse
import importlib
import json
import os
import sys
import traceback

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)


class Failure(Exception):
    pass


def parse_args(argv):
    p = argparse.ArgumentParser(prog="bake.py", description="Bake radiosity of a .blend file with Penumbra.")
    p.add_argument("blend", nargs="?", help="scene to bake (with the bpy module; optional inside blender)")
    p.add_argument("--output", "-o", required=True, help="where to write the baked .blend")
    p.add_argument("--all", action="store_true", help="bake every visible mesh, not only the selected ones")
    p.add_argument("--quality", choices=("draft", "medium", "high"), help="element size preset")
    p.add_argument("--gltf", help="also write the baked objects as glTF binary (.glb)")
    p.add_argument("--no-indirect", action="store_true", help="direct light only")
    p.add_argument("--hide-originals", action="store_true", help="hide the source objects in the output")
    p.add_argument("--lightmap", type=int, metavar="RES", help="bake RES×RES lightmap images instead of new objects")
    p.add_argument("--margin", type=int, help="lightmap margin in texels (default 16)")
    p.add_argument("--both", action="store_true", help="with --lightmap, make the new objects too")
    return p.parse_args(argv)


def _script_argv():
    # Inside blender, our arguments follow "--"; as a plain script, they are all ours.
    if "--" in sys.argv:
        return sys.argv[sys.argv.index("--") + 1 :]
    return sys.argv[1:]


def _ensure_numpy():
    try:
        import numpy  # noqa: F401

        return
    except ImportError:
        pass
    # Debian's blender uses the system Python, which may lack numpy; the project's venv has
    # one built for the same CPython version.
    v = "python%d.%d" % sys.version_info[:2]
    site = os.path.join(ROOT, ".venv", "lib", v, "site-packages")
    if os.path.isdir(site):
        sys.path.append(site)
    try:
        import numpy  # noqa: F401,F811
    except ImportError:
        raise Failure("numpy is missing in Blender's Python (on Debian: apt-get install python3-numpy)")


def ensure_addon():
    """Registers the add-on from this checkout unless Blender already has it enabled, and
    returns its package name: "penumbra" as a legacy add-on or from this checkout,
    "bl_ext.<repo>.penumbra" when installed as an extension (Blender 4.2+)."""
    import bpy

    if hasattr(bpy.types.Scene, "penumbra") and hasattr(bpy.ops.penumbra, "bake"):
        # Regression: importing "penumbra.…" failed when the add-on ran as an extension.
        # The operator lives in <package>.blender.operators.
        module = bpy.types.PENUMBRA_OT_bake.__module__
        return module[: -len(".blender.operators")] if module.endswith(".blender.operators") else module.rpartition(".")[0]
    _ensure_numpy()
    addon = os.path.join(ROOT, "addon")
    if addon not in sys.path:
        sys.path.insert(0, addon)
    import penumbra

    penumbra.register()
    return "penumbra"


def export_gltf(objects, path):
    """Writes ``objects`` as .glb with their active colour attribute as COLOR_0."""
    import bpy

    view_layer = bpy.context.view_layer
    for o in view_layer.objects:
        o.select_set(False)
    for o in objects:
        o.select_set(True)
    op = bpy.ops.export_scene.gltf
    known = op.get_rna_type().properties.keys()
    wanted = {
        "filepath": path,
        "export_format": "GLB",
        "use_selection": True,
        "export_vertex_color": "ACTIVE",  # Blender >= 4.2
        "export_colors": True,  # Blender < 4.2
        "export_yup": True,
    }
    op(**{k: v for k, v in wanted.items() if k in known})


def run(args):
    import bpy

    if args.blend:
        path = os.path.abspath(args.blend)
        if not os.path.isfile(path):
            raise Failure("no such file: %s" % args.blend)
        try:
            bpy.ops.wm.open_mainfile(filepath=path)
        except RuntimeError as e:
            raise Failure("could not read %s: %s" % (args.blend, str(e).strip()))
    elif not bpy.data.filepath:
        raise Failure("no .blend file open: give one (blender -b scene.blend --python ...) or as first argument")
    source = bpy.data.filepath

    package = ensure_addon()
    context = bpy.context
    settings = context.scene.penumbra
    if args.lightmap is not None:
        settings.output = "BOTH" if args.both else "LIGHTMAP"
        settings.lightmap_resolution = args.lightmap
    if args.margin is not None:
        settings.lightmap_margin = args.margin
    if args.quality:
        settings.quality = args.quality.upper()
    if args.no_indirect:
        settings.use_indirect = False
    settings.hide_originals = args.hide_originals

    mesh_types = {"MESH", "CURVE", "SURFACE", "FONT", "META"}
    if args.all:
        meshes = [o for o in context.view_layer.objects if o.type in mesh_types and o.visible_get()]
        for o in context.view_layer.objects:
            o.select_set(o in meshes)
    else:
        meshes = [o for o in context.selected_objects if o.type in mesh_types]
    if not meshes:
        raise Failure(
            "nothing to bake in %s: %s" % (source, "no visible mesh" if args.all else "no mesh selected (pass --all?)")
        )

    try:
        outcome = bpy.ops.penumbra.bake()
    except RuntimeError as e:  # the operator's ERROR report
        raise Failure(str(e).strip().replace("Error: ", "", 1))
    if outcome != {"FINISHED"}:
        raise Failure("the bake did not finish (%s)" % ", ".join(sorted(outcome)))
    print(settings.last_summary)

    output = os.path.abspath(args.output)
    os.makedirs(os.path.dirname(output), exist_ok=True)
    bpy.ops.wm.save_as_mainfile(filepath=output, check_existing=False)
    print("Penumbra: wrote", output)
    if args.gltf:
        # Only what this bake made: older bakes in the collection stay out of the file.
        outputs = json.loads(settings.last_outputs or "{}")
        gltf = os.path.abspath(args.gltf)
        os.makedirs(os.path.dirname(gltf), exist_ok=True)
        if settings.output == "MESH":
            objects = [bpy.data.objects[n] for n in outputs.get("objects", [])]
            gltf_out = importlib.import_module(package + ".blender.gltf_out")
            with gltf_out.unlit_vertex_colours(objects):
                export_gltf(objects, gltf)
        else:
            gltf_out = importlib.import_module(package + ".blender.gltf_out")
            sources = [bpy.data.objects[n[: -len(gltf_out.IMAGE_SUFFIX)]] for n in outputs.get("images", [])]
            with gltf_out.lightmapped(sources, [bpy.data.images[n] for n in outputs.get("images", [])]):
                export_gltf(sources, gltf)
        print("Penumbra: wrote", gltf)


def _exit(code):
    # os._exit, because inside blender an exception or SystemExit from a --python script can
    # end in exit code 0.
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(code)


def main():
    try:
        args = parse_args(_script_argv())
    except SystemExit as e:
        _exit(e.code if isinstance(e.code, int) else 2)
    try:
        import bpy  # noqa: F401
    except ImportError:
        print("bake.py: error: needs Blender's bpy (run inside blender, or with the bpy module installed)", file=sys.stderr)
        _exit(2)
    try:
        run(args)
    except Failure as e:
        print("bake.py: error: %s" % e, file=sys.stderr)
        _exit(1)
    except Exception:
        traceback.print_exc()
        _exit(1)


if __name__ == "__main__":
    main()
