# Renders an OBJ scene with Cycles as plenoptic's path tracer would (called by
# bench/vs_cycles.sh; see there for the settings and why):
#   blender --background --factory-startup --python vs_cycles_blender.py -- \
#       SCENE.obj OUT.exr SPP SEED SIZE THREADS
# Writes OUT.exr (linear 32-bit RGBA) and OUT.pfm (the same RGB), prints "CYCLES_SECONDS t"
# (the render call's wall time).
import os
import sys

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from cycles_common import configure_cycles, import_obj, mcguire_camera, render_to_pfm, uniform_world  # noqa: E402

obj_path, out_path, spp, seed, size, threads = sys.argv[sys.argv.index("--") + 1:][:6]
spp, seed, size, threads = int(spp), int(seed), int(size), int(threads)


bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene
import_obj(obj_path)
uniform_world(scene)
mcguire_camera(scene)
configure_cycles(scene, out_path, spp, seed, size, size, threads)
render_to_pfm(out_path)
