# Renders a plenoptic JSON scene of one OBJ file with subsurface materials in Cycles (called by
# bench/sss_vs_cycles.sh; see there for the settings and why):
#   blender --background --factory-startup --python sss_vs_cycles_blender.py -- \
#       SCENE.json OUT.exr SPP SEED WIDTH HEIGHT THREADS
# The OBJ's materials are rebuilt from its .mtl as bench/vs_cycles.sh does (cycles_common.py
# import_obj); each material the JSON makes subsurface becomes a Subsurface Scattering node,
# method Random Walk (Fixed Radius), scale 1, with the colour and radius that give Cycles the
# same medium as plenoptic (cycles_inputs below). The camera is
# McGuire's (cycles_common.py mcguire_camera), which the JSON scene repeats; the world is black,
# or the JSON's grey environment colour. Writes OUT.exr,
# OUT.pfm and the object regions OUT.ids.pfm / OUT.ids.json (cycles_common.py render_object_ids).
import json
import math
import os
import sys

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from cycles_common import (configure_cycles, import_obj, mcguire_camera, render_object_ids,  # noqa: E402
                           render_to_pfm, uniform_world)

scene_path, out_path, spp, seed, width, height, threads = sys.argv[sys.argv.index("--") + 1:][:7]
spp, seed, width, height, threads = int(spp), int(seed), int(width), int(height), int(threads)


def channels(value):
    return list(value) if isinstance(value, list) else [value] * 3


def plenoptic_medium(albedo, radius):
    """plenoptic's medium for one channel (src/bsdf/lobe.cpp subsurfaceMedium, Chiang et al.
    2016): single-scattering albedo α and mean free path 1/σt = d·s."""
    alpha = 1.0 - math.exp(albedo * (-5.09406 + albedo * (2.61188 - albedo * 4.31805)))
    return alpha, radius * (1.9 - albedo + 3.5 * (albedo - 0.8) ** 2)


def cycles_alpha(albedo):
    """Blender 3.4 Cycles' own albedo → α fit for an isotropic phase function
    (kernel/integrator/subsurface_random_walk.h subsurface_random_walk_remap at g = 0)."""
    blend = albedo ** 0.25
    a, b, c = 1.8260523782, 4.98511194385 + 0.127355959438, 1.09686102424
    d, e, f = 0.496310210422, 4.23190299701 + 0.00310603949088, 2.40602999408
    alpha = (1.0 - blend) * a * math.atan(b * albedo) ** c + blend * d * math.atan(e * albedo) ** f
    return min(max(alpha, 0.0), 0.999999)


def cycles_inputs(albedo, radius):
    """The Subsurface Scattering node's colour and radius that give Cycles 3.4 plenoptic's
    medium. Cycles' Random Walk (Fixed Radius) no longer uses Chiang's mapping: α comes from its
    own fit (cycles_alpha, increasing in the albedo: inverted here by bisection), and the mean
    free path is the radius × 1/(4π) (kernel/closure/bssrdf.h bssrdf_setup_radius: "so it gives
    similar looking result to older Cubic, Gaussian and Burley models"), so the same numbers
    would give a different medium. Cycles divides the colour out of the walk's weight, so only
    its α matters."""
    alpha, free_path = plenoptic_medium(albedo, radius)
    lo, hi = 0.0, 1.0
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if cycles_alpha(mid) < alpha else (lo, mid)
    return 0.5 * (lo + hi), free_path * 4.0 * math.pi


def build_subsurface(material, parameters):
    """Random Walk (Fixed Radius) with plenoptic's boundary: Cycles' Subsurface Scattering node
    (not the Principled BSDF's subsurface, whose entry and exit carry Disney's diffuse Fresnel
    factors 1 − F/2, and whose roughness adds a retro-reflection lobe), set to plenoptic's
    medium (cycles_inputs)."""
    converted = [cycles_inputs(a, d) for a, d in zip(channels(parameters.get("albedo", 0.8)),
                                                      channels(parameters["radius"]))]
    colour, radius = [c for c, _ in converted], [r for _, r in converted]
    material.use_nodes = True
    nodes, links = material.node_tree.nodes, material.node_tree.links
    nodes.clear()
    sss = nodes.new("ShaderNodeSubsurfaceScattering")
    sss.falloff = "RANDOM_WALK_FIXED_RADIUS"
    sss.inputs["Color"].default_value = (*colour, 1.0)
    sss.inputs["Scale"].default_value = 1.0
    sss.inputs["Radius"].default_value = radius
    sss.inputs["Anisotropy"].default_value = 0.0  # isotropic phase function
    output = nodes.new("ShaderNodeOutputMaterial")
    links.new(sss.outputs[0], output.inputs["Surface"])
    print(f"MATERIAL {material.name}: random walk (fixed radius), plenoptic albedo "
          f"{channels(parameters.get('albedo', 0.8))} radius {channels(parameters['radius'])} -> Cycles colour "
          f"{[round(c, 5) for c in colour]} radius {[round(r, 5) for r in radius]}")


description = json.load(open(scene_path))
if len(description["meshes"]) != 1:
    raise SystemExit(f"{scene_path}: expected one OBJ file in meshes")
bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene
import_obj(os.path.join(os.path.dirname(scene_path), description["meshes"][0]["file"]))
for name, parameters in description.get("materials", {}).items():
    if parameters.get("type") != "subsurface":
        raise SystemExit(f"{scene_path}: material {name}: only subsurface overrides are supported")
    build_subsurface(bpy.data.materials[name], parameters)
uniform_world(scene, float(description.get("environment", {}).get("color", 0.0)))
mcguire_camera(scene)
configure_cycles(scene, out_path, spp, seed, width, height, threads)
render_to_pfm(out_path)
render_object_ids(scene, out_path, seed, width, height, threads)
