"""Helpers of `scripts/bench`: the speed-against-error benchmark of Penumbra beside Cycles.

Modules, in pipeline order:
  probes       probe points on every receiver polygon (pure numpy)
  blender      scene JSON / bake JSON -> bpy objects (Cycles scene, baked scene, camera)
  cycles_job   one Cycles bake or render in its own process (own time and peak memory)
  penumbra_job one `penumbra bake` process, and its colours interpolated at the probes
  errors       error against the two-seed Cycles reference, its own noise subtracted
  report       tables, plots and the markdown
  main         the suite
"""
