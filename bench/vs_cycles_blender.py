# Renders an OBJ scene with Cycles as plenoptic's path tracer would (called by
# bench/vs_cycles.sh; see there for the settings and why):
#   blender --background --factory-startup --python vs_cycles_blender.py -- \
#       SCENE.obj OUT.exr SPP SEED SIZE THREADS
# Writes OUT.exr (linear 32-bit RGBA) and OUT.pfm (the same RGB), prints "CYCLES_SECONDS t"
# (the render call's wall time).
import math
import os
import sys

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from cycles_common import configure_cycles, render_to_pfm, uniform_world  # noqa: E402

obj_path, out_path, spp, seed, size, threads = sys.argv[sys.argv.index("--") + 1:][:6]
spp, seed, size, threads = int(spp), int(seed), int(size), int(threads)


def read_mtl(path):
    """name → {keyword: [floats]} for Kd, Ks, Ke, Ns."""
    materials, current = {}, None
    for line in open(path):
        parts = line.split("#")[0].split()
        if not parts:
            continue
        if parts[0] == "newmtl":
            current = materials.setdefault(parts[1], {})
        elif current is not None and parts[0] in ("Kd", "Ks", "Ke", "Ns"):
            current[parts[0]] = [float(x) for x in parts[1:]]
    return materials


def mtl_path(obj):
    for line in open(obj):
        parts = line.split()
        if parts and parts[0] == "mtllib":
            return os.path.join(os.path.dirname(obj), parts[1])
    raise SystemExit(f"{obj}: no mtllib")


def build_material(material, mtl):
    kd = mtl.get("Kd", [0.0, 0.0, 0.0])
    ks = mtl.get("Ks", [0.0, 0.0, 0.0])
    ke = mtl.get("Ke", [0.0, 0.0, 0.0])
    ns = mtl.get("Ns", [0.0])[0]
    if max(ks) > 0.0:  # plenoptic's OBJ loader: Kd + Ks ≤ 1 per channel
        for c in range(3):
            total = kd[c] + ks[c]
            if total > 1.0:
                kd[c], ks[c] = kd[c] / total, ks[c] / total
    material.use_nodes = True
    nodes, links = material.node_tree.nodes, material.node_tree.links
    nodes.clear()
    output = nodes.new("ShaderNodeOutputMaterial")
    diffuse = nodes.new("ShaderNodeBsdfDiffuse")
    diffuse.inputs["Color"].default_value = (*kd, 1.0)
    diffuse.inputs["Roughness"].default_value = 0.0  # Lambertian
    shader = diffuse.outputs[0]
    if max(ks) > 0.0:
        glossy = nodes.new("ShaderNodeBsdfGlossy")
        glossy.distribution = "GGX"
        glossy.inputs["Color"].default_value = (*ks, 1.0)
        glossy.inputs["Roughness"].default_value = (2.0 / (ns + 2.0)) ** 0.25
        add = nodes.new("ShaderNodeAddShader")
        links.new(shader, add.inputs[0])
        links.new(glossy.outputs[0], add.inputs[1])
        shader = add.outputs[0]
    if max(ke) > 0.0:
        emission = nodes.new("ShaderNodeEmission")
        emission.inputs["Color"].default_value = (*ke, 1.0)
        emission.inputs["Strength"].default_value = 1.0  # radiance = colour × strength
        geometry = nodes.new("ShaderNodeNewGeometry")
        one_sided = nodes.new("ShaderNodeMixShader")  # front: emission; back: nothing (black)
        links.new(geometry.outputs["Backfacing"], one_sided.inputs["Fac"])
        links.new(emission.outputs[0], one_sided.inputs[1])
        add = nodes.new("ShaderNodeAddShader")
        links.new(shader, add.inputs[0])
        links.new(one_sided.outputs[0], add.inputs[1])
        shader = add.outputs[0]
    links.new(shader, output.inputs["Surface"])


bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene
# OBJ is y-up, Blender z-up: (x, y, z)_obj → (x, −z, y)_blender.
bpy.ops.wm.obj_import(filepath=obj_path, forward_axis="NEGATIVE_Z", up_axis="Y")
mtls = read_mtl(mtl_path(obj_path))
for material in bpy.data.materials:
    if material.name not in mtls:
        raise SystemExit(f"material {material.name} is not in the .mtl")
    build_material(material, mtls[material.name])

uniform_world(scene)

camera_data = bpy.data.cameras.new("camera")
camera_data.sensor_fit = "VERTICAL"
camera_data.angle_y = math.radians(40.0)
camera = bpy.data.objects.new("camera", camera_data)
camera.location = (0.0, -3.5, 1.0)                     # obj (0, 1, 3.5)
camera.rotation_euler = (math.radians(90.0), 0.0, 0.0)  # looks along +y_blender = −z_obj
scene.collection.objects.link(camera)
scene.camera = camera

configure_cycles(scene, out_path, spp, seed, size, size, threads)
render_to_pfm(out_path)
