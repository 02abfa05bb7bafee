# Renders a glTF scene with Blender's own glTF importer and Cycles (called by
# bench/gltf_vs_cycles.sh; see there for what is compared and why):
#   blender --background --factory-startup --python gltf_vs_cycles_blender.py -- \
#       SCENE.gltf OUT.exr SPP SEED WIDTH HEIGHT THREADS [VARIANT [SKY]]
# VARIANT "principled" (default): the materials as the importer made them (Principled BSDF);
# "gltf-brdf": each Principled BSDF replaced by glTF 2.0's reference BRDF (appendix B) built
# from Cycles' own nodes with the same inputs: mix(dielectric, metal, metallic), dielectric =
# mix(Lambertian diffuse of base colour, white GGX glossy, Fresnel of IOR 1.5 (F0 0.04)),
# metal = GGX glossy of base colour (F0 = base colour, no Schlick tint towards white), glossy
# roughness r (α = r² in both), plus the Principled node's emission; and sRGB textures decoded
# to linear floats before Cycles filters them (glTF decodes sRGB before filtering, as GPUs and
# plenoptic do; Cycles interpolates 8-bit sRGB texels before decoding them, which darkens a
# magnified high-contrast texture). The difference between
# the two variants is what the Principled BSDF (Burley diffuse with its retro-reflection, its
# specular and metal Fresnel) adds to glTF's BRDF.
# SKY (default 0): the world's uniform radiance (1 for the furnace scene).
# Writes OUT.exr and OUT.pfm (linear RGB), OUT.ids.pfm (each object drawn in a flat colour of its own, 16 samples, to find the object
# regions) and OUT.ids.json (object name -> that colour), and prints the material set-up the
# importer made, for the differences the script explains.
import os
import sys

import numpy

numpy.bool = bool  # Blender 3.4's glTF importer still uses numpy.bool, gone in NumPy 1.24
import bpy  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from cycles_common import configure_cycles, render_object_ids, render_to_pfm, uniform_world  # noqa: E402

arguments = sys.argv[sys.argv.index("--") + 1:]
scene_path, out_path, spp, seed, width, height, threads = arguments[:7]
spp, seed, width, height, threads = int(spp), int(seed), int(width), int(height), int(threads)
variant = arguments[7] if len(arguments) > 7 else "principled"
sky = float(arguments[8]) if len(arguments) > 8 else 0.0
if variant not in ("principled", "gltf-brdf"):
    raise SystemExit(f"unknown variant {variant!r} (principled or gltf-brdf)")


def source(node, name):
    """What feeds a Principled input: the linked socket, else its constant value."""
    socket = node.inputs[name]
    return socket.links[0].from_socket if socket.is_linked else socket.default_value


def feed(tree, value, socket):
    if isinstance(value, bpy.types.NodeSocket):
        tree.links.new(value, socket)
    else:
        socket.default_value = value


def decode_srgb_textures(material):
    """Each sRGB image of the material replaced by its linear float decoding."""
    for node in material.node_tree.nodes:
        if node.type != "TEX_IMAGE" or node.image is None or node.image.colorspace_settings.name != "sRGB":
            continue
        encoded = numpy.array(node.image.pixels[:], dtype=numpy.float64).reshape(-1, 4)
        rgb = encoded[:, :3]
        encoded[:, :3] = numpy.where(rgb <= 0.04045, rgb / 12.92, ((rgb + 0.055) / 1.055) ** 2.4)
        linear = bpy.data.images.new(node.image.name + "_linear", *node.image.size, alpha=True, float_buffer=True)
        linear.colorspace_settings.name = "Linear"
        linear.pixels[:] = encoded.ravel().tolist()
        node.image = linear


def replace_by_gltf_brdf(material, principled):
    """glTF 2.0's reference BRDF from Cycles nodes, fed what fed the Principled BSDF."""
    tree = material.node_tree
    base, metallic, roughness = (source(principled, n) for n in ("Base Color", "Metallic", "Roughness"))
    emission, strength = source(principled, "Emission"), source(principled, "Emission Strength")
    output = next(n for n in tree.nodes if n.type == "OUTPUT_MATERIAL")
    diffuse = tree.nodes.new("ShaderNodeBsdfDiffuse")
    feed(tree, base, diffuse.inputs["Color"])
    diffuse.inputs["Roughness"].default_value = 0.0  # Lambertian
    specular = tree.nodes.new("ShaderNodeBsdfGlossy")
    specular.distribution = "GGX"
    specular.inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
    feed(tree, roughness, specular.inputs["Roughness"])
    fresnel = tree.nodes.new("ShaderNodeFresnel")
    fresnel.inputs["IOR"].default_value = 1.5
    dielectric = tree.nodes.new("ShaderNodeMixShader")
    tree.links.new(fresnel.outputs[0], dielectric.inputs["Fac"])
    tree.links.new(diffuse.outputs[0], dielectric.inputs[1])
    tree.links.new(specular.outputs[0], dielectric.inputs[2])
    metal = tree.nodes.new("ShaderNodeBsdfGlossy")
    metal.distribution = "GGX"
    feed(tree, base, metal.inputs["Color"])
    feed(tree, roughness, metal.inputs["Roughness"])
    mix = tree.nodes.new("ShaderNodeMixShader")
    feed(tree, metallic, mix.inputs["Fac"])
    tree.links.new(dielectric.outputs[0], mix.inputs[1])
    tree.links.new(metal.outputs[0], mix.inputs[2])
    glow = tree.nodes.new("ShaderNodeEmission")
    feed(tree, emission, glow.inputs["Color"])
    feed(tree, strength, glow.inputs["Strength"])
    total = tree.nodes.new("ShaderNodeAddShader")
    tree.links.new(mix.outputs[0], total.inputs[0])
    tree.links.new(glow.outputs[0], total.inputs[1])
    tree.links.new(total.outputs[0], output.inputs["Surface"])

bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene
bpy.ops.import_scene.gltf(filepath=scene_path)
cameras = [o for o in scene.objects if o.type == "CAMERA"]
if not cameras:
    raise SystemExit(f"{scene_path}: no camera")
scene.camera = cameras[0]
uniform_world(scene, sky)
configure_cycles(scene, out_path, spp, seed, width, height, threads)
print(f"CAMERA {cameras[0].name} sensor_fit {cameras[0].data.sensor_fit} angle_y {cameras[0].data.angle_y:.5f} "
      f"angle_x {cameras[0].data.angle_x:.5f}")
for material in bpy.data.materials:
    if not material.use_nodes:
        continue
    for node in material.node_tree.nodes:
        if node.type == "BSDF_PRINCIPLED":
            if variant == "gltf-brdf":
                replace_by_gltf_brdf(material, node)
                decode_srgb_textures(material)
                print(f"MATERIAL {material.name}: replaced by the glTF reference BRDF")
                break
            print(f"MATERIAL {material.name}: Principled distribution {node.distribution}, specular "
                  f"{node.inputs['Specular'].default_value:.3f}, linked inputs "
                  f"{sorted(i.name for i in node.inputs if i.is_linked)}")
render_to_pfm(out_path)

render_object_ids(scene, out_path, seed, width, height, threads)
