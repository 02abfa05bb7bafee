# Cycles set up as plenoptic's path tracer renders, shared by the Blender scripts of
# bench/vs_cycles.sh and bench/gltf_vs_cycles.sh (imported inside Blender's Python; see
# bench/vs_cycles.sh for why each setting).
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
        setattr(cycles, bounces, 1024)
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
