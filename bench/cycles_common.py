# Cycles set up as plenoptic's path tracer renders, shared by the Blender scripts of
# bench/vs_cycles.sh, bench/gltf_vs_cycles.sh and bench/sss_vs_cycles.sh (imported inside Blender's Python; see
# bench/vs_cycles.sh for why each setting).
import json
import math
import os
import struct
import time

import bpy


def uniform_world(scene, radiance=0.0):
    """A world of uniform grey radiance: 0 (black, no light but the scene's own emitters) or,
    for a furnace, 1."""
    world = bpy.data.worlds.new("uniform")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 1.0
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (radiance, radiance, radiance, 1.0)
    scene.world = world


def configure_cycles(scene, out_path, spp, seed, width, height, threads):
    """CPU Cycles, `threads` threads, box filter 1 px, no denoising, adaptive sampling or
    clamping, every bounce limit 1024 (Russian roulette ends paths, as in plenoptic), linear
    32-bit RGBA EXR with no view transform."""
    render = scene.render
    render.engine = "CYCLES"
    render.resolution_x, render.resolution_y = width, height
    render.resolution_percentage = 100
    render.threads_mode = "FIXED"
    render.threads = threads
    render.use_persistent_data = False
    render.film_transparent = False
    render.image_settings.file_format = "OPEN_EXR"
    render.image_settings.color_depth = "32"
    render.image_settings.color_mode = "RGBA"
    render.filepath = out_path
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    scene.view_settings.exposure = 0.0
    scene.view_settings.gamma = 1.0

    cycles = scene.cycles
    cycles.device = "CPU"
    cycles.samples = spp
    cycles.seed = seed
    cycles.use_animated_seed = False
    cycles.use_adaptive_sampling = False
    cycles.use_denoising = False
    cycles.use_preview_denoising = False
    cycles.pixel_filter_type = "BOX"
    cycles.filter_width = 1.0
    cycles.sample_clamp_direct = 0.0
    cycles.sample_clamp_indirect = 0.0
    cycles.blur_glossy = 0.0
    cycles.caustics_reflective = True
    cycles.caustics_refractive = True
    for bounces in ("max_bounces", "diffuse_bounces", "glossy_bounces", "transmission_bounces", "volume_bounces",
                    "transparent_max_bounces"):
        # CYCLES_MAX_BOUNCES: a lower limit for a depth-limited comparison (bench/sss_vs_cycles.sh MAX_DEPTH).
        setattr(cycles, bounces, int(os.environ.get("CYCLES_MAX_BOUNCES", "1024")))
    cycles.min_light_bounces = 0
    cycles.min_transparent_bounces = 0


def render_to_pfm(out_path):
    """Renders the scene to out_path (EXR) and the same RGB to out_path's .pfm (both are stored
    bottom row first); prints and returns the render call's wall time as "CYCLES_SECONDS t"."""
    start = time.perf_counter()
    bpy.ops.render.render(write_still=True)
    seconds = time.perf_counter() - start
    print(f"CYCLES_SECONDS {seconds:.4f}")
    image = bpy.data.images.load(out_path)
    pixels = image.pixels[:]
    rgb = [pixels[i + c] for i in range(0, len(pixels), 4) for c in range(3)]
    with open(os.path.splitext(out_path)[0] + ".pfm", "wb") as f:
        f.write(f"PF\n{image.size[0]} {image.size[1]}\n-1.0\n".encode())
        f.write(struct.pack(f"<{len(rgb)}f", *rgb))
    bpy.data.images.remove(image)
    return seconds


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


def import_obj(obj_path):
    """Imports an OBJ (y up, as plenoptic reads it) with its materials rebuilt from the .mtl
    (build_material). OBJ is y-up, Blender z-up: (x, y, z)_obj → (x, −z, y)_blender."""
    bpy.ops.wm.obj_import(filepath=obj_path, forward_axis="NEGATIVE_Z", up_axis="Y")
    mtls = read_mtl(mtl_path(obj_path))
    for material in bpy.data.materials:
        if material.name not in mtls:
            raise SystemExit(f"material {material.name} is not in the .mtl")
        build_material(material, mtls[material.name])


def mcguire_camera(scene):
    """The camera of McGuire's Cornell boxes: eye (0, 1, 3.5), target (0, 1, 0) in OBJ
    coordinates, 40° vertical field of view."""
    camera_data = bpy.data.cameras.new("camera")
    camera_data.sensor_fit = "VERTICAL"
    camera_data.angle_y = math.radians(40.0)
    camera = bpy.data.objects.new("camera", camera_data)
    camera.location = (0.0, -3.5, 1.0)                     # obj (0, 1, 3.5)
    camera.rotation_euler = (math.radians(90.0), 0.0, 0.0)  # looks along +y_blender = −z_obj
    scene.collection.objects.link(camera)
    scene.camera = camera


def render_object_ids(scene, out_path, seed, width, height, threads):
    """The object regions: every material replaced by a flat emission of the object's own
    colour, rendered with 16 samples and no bounces to OUT.ids.exr/.pfm, with OUT.ids.json
    (object name → that colour)."""
    names = sorted(o.name for o in scene.objects if o.type == "MESH")
    colours = {}
    for index, name in enumerate(names):
        # Well-separated colours: the index's bits spread over the channels, in steps of 0.25.
        colour = (0.25 * (1 + index % 3), 0.25 * (1 + (index // 3) % 3), 0.25 * (1 + (index // 9) % 3))
        colours[name] = colour
        material = bpy.data.materials.new(f"id_{name}")
        material.use_nodes = True
        nodes = material.node_tree.nodes
        nodes.clear()
        emission = nodes.new("ShaderNodeEmission")
        emission.inputs["Color"].default_value = (*colour, 1.0)
        emission.inputs["Strength"].default_value = 1.0
        output = nodes.new("ShaderNodeOutputMaterial")
        material.node_tree.links.new(emission.outputs[0], output.inputs["Surface"])
        obj = bpy.data.objects[name]
        for slot in obj.material_slots:
            slot.material = material
        if not obj.material_slots:
            obj.data.materials.append(material)
    ids_path = os.path.splitext(out_path)[0] + ".ids.exr"
    configure_cycles(scene, ids_path, 16, seed, width, height, threads)
    scene.cycles.max_bounces = 0
    render_to_pfm(ids_path)
    with open(os.path.splitext(out_path)[0] + ".ids.json", "w") as f:
        json.dump(colours, f, indent=1)
