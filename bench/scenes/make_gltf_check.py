#!/usr/bin/env python3
"""Writes bench/scenes/gltf-check.gltf and gltf-furnace.gltf/.json (standard library only): the
glTF scenes that bench/gltf_vs_cycles.sh renders with plenoptic and with Blender's own glTF
importer and Cycles, one object per region compared, covering what the glTF loader reads per
texel (the furnace: the same BRDFs, untextured, alone under a white sky; see the end).

Run from anywhere: /usr/bin/python3 bench/scenes/make_gltf_check.py
The output is committed (self-contained: buffers and textures as data: URIs).

A closed 5 × 3 × 5 m room (y up), lit by an emissive 1.2 × 1.2 m ceiling lamp (radiance 12):
  floor         GGX dielectric, roughness 0.5: baseColorTexture an 8 × 8 grey checker (0.25 / 0.75)
                with KHR_texture_transform scale 4, rotation 0.5 rad, offset (0.1, 0.2), REPEAT;
  back wall     roughness 1, baseColorTexture a 4 × 1 stripe texture (cream / teal) with
                KHR_texture_transform scale 3, rotation π/4, sampler MIRRORED_REPEAT;
  side walls    grey-white 0.8, roughness 1; the front wall and ceiling 0.7;
  rough sphere  base colour (0.8, 0.3, 0.2), metallicRoughnessTexture a 64 × 1 ramp along u
                (longitude): roughness 0.2 → 1, metalness 0;
  metal sphere  base colour (0.95, 0.75, 0.35), metallicRoughnessTexture a 1 × 64 ramp along v
                (top to bottom): metalness 0 → 1, roughness 0.35;
  cube          0.8 m, white base colour × COLOR_0 (its vertex colour follows the position);
  panel         an emissive-textured 1.2 × 0.6 m panel on the back wall above the cube: emissiveTexture a 4 × 1
                stripe texture (white / orange / black / blue), emissiveFactor 1,
                KHR_materials_emissive_strength 3; base colour black;
camera "main" (yfov 0.8, 4:3) at the front looking in and slightly down.
"""
import json
import math
import os

from gltf_writer import MIRRORED_REPEAT, REPEAT, CLAMP_TO_EDGE, Buffer, data_uri, png

W, H, D = 5.0, 3.0, 5.0
buf = Buffer()
meshes = []


def mesh(name, material, attributes_indices):
    attributes, indices = attributes_indices
    meshes.append({"name": name, "primitives": [{"attributes": attributes, "indices": indices, "material": material}]})


def cube(centre, size):
    """Six faces with their own vertices (flat normals), COLOR_0 from the position."""
    positions, normals, uvs, colors, indices = [], [], [], [], []
    h = size / 2
    for axis in range(3):
        for sign in (1, -1):
            n = [0.0, 0.0, 0.0]
            n[axis] = float(sign)
            u_axis, v_axis = (axis + 1) % 3, (axis + 2) % 3
            if sign < 0:
                u_axis, v_axis = v_axis, u_axis
            base = len(positions)
            for s, t in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
                p = [0.0, 0.0, 0.0]
                p[axis] = sign * h
                p[u_axis] = s * h
                p[v_axis] = t * h
                positions.append(tuple(centre[k] + p[k] for k in range(3)))
                normals.append(tuple(n))
                uvs.append(((s + 1) / 2, (1 - t) / 2))
                colors.append((round(0.2 + 0.7 * (p[0] / size + 0.5), 4), round(0.2 + 0.7 * (p[1] / size + 0.5), 4),
                               round(0.9 - 0.7 * (p[2] / size + 0.5), 4)))
            indices += [base, base + 1, base + 2, base, base + 2, base + 3]
    return buf.primitive(positions, normals, uvs, indices, colors=colors)


mesh("floor", 0, buf.quad([(0, 0, D), (W, 0, D), (W, 0, 0), (0, 0, 0)], (0, 1, 0)))
mesh("ceiling", 3, buf.quad([(0, H, 0), (W, H, 0), (W, H, D), (0, H, D)], (0, -1, 0)))
mesh("back", 1, buf.quad([(0, 0, 0), (W, 0, 0), (W, H, 0), (0, H, 0)], (0, 0, 1)))
mesh("left", 2, buf.quad([(0, 0, D), (0, 0, 0), (0, H, 0), (0, H, D)], (1, 0, 0)))
mesh("right", 2, buf.quad([(W, 0, 0), (W, 0, D), (W, H, D), (W, H, 0)], (-1, 0, 0)))
mesh("front", 3, buf.quad([(W, 0, D), (0, 0, D), (0, H, D), (W, H, D)], (0, 0, -1)))
c = 0.6
mesh("lamp", 4, buf.quad([(W / 2 - c, H - 0.001, D / 2 - c), (W / 2 + c, H - 0.001, D / 2 - c),
                          (W / 2 + c, H - 0.001, D / 2 + c), (W / 2 - c, H - 0.001, D / 2 + c)], (0, -1, 0)))
mesh("rough_sphere", 5, buf.sphere((1.3, 0.6, 2.0), 0.6))
mesh("metal_sphere", 6, buf.sphere((3.7, 0.6, 2.0), 0.6))
mesh("cube", 7, cube((2.5, 0.4, 1.1), 0.8))
mesh("panel", 8, buf.quad([(1.9, 1.9, 0.01), (3.1, 1.9, 0.01), (3.1, 2.5, 0.01), (1.9, 2.5, 0.01)], (0, 0, 1)))

checker = []
for y in range(8):
    for x in range(8):
        checker += [191, 191, 191] if (x + y) % 2 else [64, 64, 64]
stripes = [235, 225, 200, 40, 140, 150] * 2                    # cream, teal, cream, teal
glow = [255, 255, 255, 255, 140, 30, 0, 0, 0, 60, 90, 255]      # white, orange, black, blue
roughness_ramp = []
for x in range(64):
    roughness_ramp += [0, round(255 * (0.2 + 0.8 * x / 63)), 0]  # G = roughness, B = metalness
metal_ramp = []
for y in range(64):
    metal_ramp += [0, 255, round(255 * y / 63)]                 # roughness = factor 0.35 × 1


def lambert_like(name, rgb):
    return {"name": name, "pbrMetallicRoughness": {"baseColorFactor": [*rgb, 1], "metallicFactor": 0,
                                                   "roughnessFactor": 1}}


gltf = {
    "asset": {"version": "2.0", "generator": "bench/scenes/make_gltf_check.py"},
    "extensionsUsed": ["KHR_texture_transform", "KHR_materials_emissive_strength"],
    "buffers": [],
    "bufferViews": buf.views, "accessors": buf.accessors,
    "images": [{"uri": data_uri("image/png", png(8, 8, checker))},
               {"uri": data_uri("image/png", png(4, 1, stripes))},
               {"uri": data_uri("image/png", png(4, 1, glow))},
               {"uri": data_uri("image/png", png(64, 1, roughness_ramp))},
               {"uri": data_uri("image/png", png(1, 64, metal_ramp))}],
    "samplers": [{"wrapS": REPEAT, "wrapT": REPEAT},
                 {"wrapS": MIRRORED_REPEAT, "wrapT": MIRRORED_REPEAT},
                 {"wrapS": CLAMP_TO_EDGE, "wrapT": CLAMP_TO_EDGE}],
    "textures": [{"source": 0, "sampler": 0}, {"source": 1, "sampler": 1}, {"source": 2, "sampler": 2},
                 {"source": 3, "sampler": 2}, {"source": 4, "sampler": 2}],
    "materials": [
        {"name": "floor", "pbrMetallicRoughness": {
            "baseColorFactor": [1, 1, 1, 1], "metallicFactor": 0, "roughnessFactor": 0.5,
            "baseColorTexture": {"index": 0, "extensions": {"KHR_texture_transform": {
                "scale": [4, 4], "rotation": 0.5, "offset": [0.1, 0.2]}}}}},
        {"name": "back", "pbrMetallicRoughness": {
            "baseColorFactor": [1, 1, 1, 1], "metallicFactor": 0, "roughnessFactor": 1,
            "baseColorTexture": {"index": 1, "extensions": {"KHR_texture_transform": {
                "scale": [3, 3], "rotation": math.pi / 4}}}}},
        lambert_like("sides", (0.8, 0.8, 0.8)),
        lambert_like("ceiling", (0.7, 0.7, 0.7)),
        {"name": "lamp", "pbrMetallicRoughness": {"baseColorFactor": [0, 0, 0, 1], "metallicFactor": 0,
                                                  "roughnessFactor": 1},
         "emissiveFactor": [1, 1, 1], "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 12}}},
        {"name": "rough_sphere", "pbrMetallicRoughness": {
            "baseColorFactor": [0.8, 0.3, 0.2, 1], "metallicFactor": 1, "roughnessFactor": 1,
            "metallicRoughnessTexture": {"index": 3}}},
        {"name": "metal_sphere", "pbrMetallicRoughness": {
            "baseColorFactor": [0.95, 0.75, 0.35, 1], "metallicFactor": 1, "roughnessFactor": 0.35,
            "metallicRoughnessTexture": {"index": 4}}},
        lambert_like("cube", (1, 1, 1)),
        {"name": "panel", "pbrMetallicRoughness": {"baseColorFactor": [0, 0, 0, 1], "metallicFactor": 0,
                                                   "roughnessFactor": 1},
         "emissiveTexture": {"index": 2}, "emissiveFactor": [1, 1, 1],
         "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 3}}},
    ],
    "meshes": meshes,
    "cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "aspectRatio": 4 / 3, "znear": 0.01}}],
    "nodes": [{"mesh": i, "name": m["name"]} for i, m in enumerate(meshes)] + [
        {"name": "main", "camera": 0, "translation": [W / 2, 1.7, D - 0.05],
         "rotation": [-math.sin(0.2 / 2), 0, 0, math.cos(0.2 / 2)]}],
    "scenes": [{"nodes": list(range(len(meshes) + 1))}],
}
gltf["buffers"].append(buf.gltf_buffer())
path = os.path.join(os.path.dirname(os.path.abspath(__file__)), "gltf-check.gltf")
with open(path, "w") as f:
    json.dump(gltf, f, separators=(",", ":"))
print("wrote", path, os.path.getsize(path), "bytes")

# The furnace: the check scene's untextured BRDFs (and the metal sphere's half-way point of its
# metalness ramp) on four spheres in a uniform white sky
# (gltf-furnace.json adds the sky, radiance 1, for plenoptic; bench/gltf_vs_cycles.sh gives
# Cycles the same world), no other geometry, so each sphere's pixels show its directional
# albedo at the viewing angle: the single-bounce difference between the BRDF models.
buf = Buffer()
meshes = []
mesh("wall_brdf", 0, buf.sphere((-1.95, 0, 0), 0.55))
mesh("floor_brdf", 1, buf.sphere((-0.65, 0, 0), 0.55))
mesh("half_metal_brdf", 2, buf.sphere((0.65, 0, 0), 0.55))
mesh("metal_brdf", 3, buf.sphere((1.95, 0, 0), 0.55))
furnace = {
    "asset": {"version": "2.0", "generator": "bench/scenes/make_gltf_check.py"},
    "buffers": [buf.gltf_buffer()], "bufferViews": buf.views, "accessors": buf.accessors,
    "materials": [
        lambert_like("wall_brdf", (0.8, 0.8, 0.8)),
        {"name": "floor_brdf", "pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1], "metallicFactor": 0,
                                                        "roughnessFactor": 0.5}},
        {"name": "half_metal_brdf", "pbrMetallicRoughness": {"baseColorFactor": [0.95, 0.75, 0.35, 1],
                                                             "metallicFactor": 0.5, "roughnessFactor": 0.35}},
        {"name": "metal_brdf", "pbrMetallicRoughness": {"baseColorFactor": [0.95, 0.75, 0.35, 1], "metallicFactor": 1,
                                                        "roughnessFactor": 0.35}}],
    "meshes": meshes,
    "cameras": [{"type": "perspective", "perspective": {"yfov": 0.5, "aspectRatio": 4 / 3, "znear": 0.01}}],
    "nodes": [{"mesh": i, "name": m["name"]} for i, m in enumerate(meshes)] + [
        {"name": "main", "camera": 0, "translation": [0, 0, 7.5]}],
    "scenes": [{"nodes": list(range(len(meshes) + 1))}],
}
path = os.path.join(os.path.dirname(os.path.abspath(__file__)), "gltf-furnace.gltf")
with open(path, "w") as f:
    json.dump(furnace, f, separators=(",", ":"))
with open(os.path.splitext(path)[0] + ".json", "w") as f:
    json.dump({"meshes": [{"file": "gltf-furnace.gltf"}], "environment": {"color": 1}}, f, indent=1)
    f.write("\n")
print("wrote", path, "and its .json")
