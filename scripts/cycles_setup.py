"""The Cycles set-up shared by every comparison against Cycles (the tests' references in
tests/cycles_ref.py and the benchmark's Cycles jobs in scripts/bench_lib): one place that says
what an unbiased, reproducible CPU bake is, and what a Lambertian material is in Cycles.
"""
from __future__ import annotations

import os


def reset_scene(samples: int, seed: int, adaptive: bool = False, bounces: int | None = None,
                threads: int | None = None):
    """An empty factory scene for Cycles: CPU, the given samples and seed, no denoising, no
    clamping, no world (so no background light). ``bounces`` sets the total and diffuse
    bounces (Cycles' defaults when None); ``threads`` defaults to min(2, cores)."""
    import bpy

    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.engine = "CYCLES"
    cy = scene.cycles
    cy.device = "CPU"
    cy.samples = samples
    cy.seed = seed
    cy.use_adaptive_sampling = adaptive
    cy.use_denoising = False
    cy.sample_clamp_direct = 0.0
    cy.sample_clamp_indirect = 0.0
    if bounces is not None:
        cy.max_bounces = bounces
        cy.diffuse_bounces = bounces
    scene.world = None
    scene.render.threads_mode = "FIXED"
    scene.render.threads = threads or max(1, min(2, os.cpu_count() or 1))
    return scene


def lambert_material(name: str, albedo=(1.0, 1.0, 1.0), emission=None):
    """A Diffuse BSDF (roughness 0, Lambertian) of linear colour ``albedo``, plus an Emission
    of radiance ``emission`` when it is given and not black."""
    import bpy

    mat = bpy.data.materials.new(name)
    if bpy.app.version < (5, 0, 0):  # node trees are always on from Blender 5
        mat.use_nodes = True
    nt = mat.node_tree
    nt.nodes.clear()
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    bsdf = nt.nodes.new("ShaderNodeBsdfDiffuse")
    bsdf.inputs["Color"].default_value = (*albedo, 1.0)
    bsdf.inputs["Roughness"].default_value = 0.0
    shader = bsdf.outputs["BSDF"]
    if emission is not None and max(emission) > 0:
        em = nt.nodes.new("ShaderNodeEmission")
        em.inputs["Color"].default_value = (*emission, 1.0)
        em.inputs["Strength"].default_value = 1.0
        add = nt.nodes.new("ShaderNodeAddShader")
        nt.links.new(shader, add.inputs[0])
        nt.links.new(em.outputs["Emission"], add.inputs[1])
        shader = add.outputs["Shader"]
    nt.links.new(shader, out.inputs["Surface"])
    return mat


def lambertian_room(samples: int, seed: int):
    """The demo room (scripts/room.py) in a fresh Cycles scene with 64 diffuse bounces and
    no others, its materials replaced by pure Lambertian ones of the same colour (what
    Penumbra models). Returns (scene, meshes, light)."""
    import bpy

    import room

    scene = reset_scene(samples, seed, bounces=64)
    cy = scene.cycles
    cy.glossy_bounces = cy.transmission_bounces = cy.volume_bounces = cy.transparent_max_bounces = 0
    meshes, light = room.build_room(scene)
    made = {}
    for o in meshes:
        for slot in o.material_slots:
            m = slot.material
            if m.name not in made:
                made[m.name] = lambert_material(m.name + " Lambert", tuple(m.diffuse_color)[:3])
            slot.material = made[m.name]
    bpy.context.view_layer.update()
    return scene, meshes, light
