#!/usr/bin/env python3
"""Writes bench/scenes/gltf-materials.gltf (standard library only): a glTF box of what the glTF
loader reads per texel, for the light field vs path tracer figures of docs/benchmarks.md.

Run from anywhere: /usr/bin/python3 bench/scenes/make_gltf_materials.py
The output is committed (self-contained: buffers and textures as data: URIs).

A 4 x 3 x 4 room (y up, open nowhere), lit by an emissive 1 x 1 ceiling panel (20 W/sr/m^2):
  floor   GGX: baseColorTexture = an 8 x 8 checker (0.2 / 0.8), KHR_texture_transform scale 3,
          rotation 0.3 rad, sampler MIRRORED_REPEAT; metallicRoughnessTexture = a 16 x 1 ramp
          along x (roughness 0.25 -> 1, metalness 0 -> 0.6) read through TEXCOORD_1 (= x / 4);
  walls   Lambert-like (roughness 1, metallic 0), white base colour times COLOR_0: a red to
          green gradient along the walls' x and blue-grey at the top;
  ceiling grey (0.7, roughness 1); camera "main" at the front looking in.
"""
import json
import math
import os

from gltf_writer import MIRRORED_REPEAT, CLAMP_TO_EDGE, Buffer, data_uri, png

buf = Buffer()
W, H, D = 4.0, 3.0, 4.0
meshes = []


def mesh(name, material, attributes_indices):
    attributes, indices = attributes_indices
    meshes.append({"name": name, "primitives": [{"attributes": attributes, "indices": indices, "material": material}]})


def wall_colour(p):
    s = p[0] / W if abs(p[2]) < 1e-6 or abs(p[2] - D) < 1e-6 else p[2] / D
    top = p[1] / H
    return (round((1 - s) * 0.9 * (1 - top) + 0.5 * top, 4), round(s * 0.9 * (1 - top) + 0.55 * top, 4),
            round(0.15 * (1 - top) + 0.7 * top, 4))


mesh("floor", 0, buf.quad([(0, 0, D), (W, 0, D), (W, 0, 0), (0, 0, 0)], (0, 1, 0), uv1=lambda p: (p[0] / W, 0.5)))
mesh("ceiling", 2, buf.quad([(0, H, 0), (W, H, 0), (W, H, D), (0, H, D)], (0, -1, 0)))
mesh("back", 1, buf.quad([(0, 0, 0), (W, 0, 0), (W, H, 0), (0, H, 0)], (0, 0, 1), colors=wall_colour, n=6))
mesh("left", 1, buf.quad([(0, 0, D), (0, 0, 0), (0, H, 0), (0, H, D)], (1, 0, 0), colors=wall_colour, n=6))
mesh("right", 1, buf.quad([(W, 0, 0), (W, 0, D), (W, H, D), (W, H, 0)], (-1, 0, 0), colors=wall_colour, n=6))
mesh("front", 1, buf.quad([(W, 0, D), (0, 0, D), (0, H, D), (W, H, D)], (0, 0, -1), colors=wall_colour, n=6))
c = 0.5
mesh("lamp", 3, buf.quad([(W / 2 - c, H - 0.001, D / 2 - c), (W / 2 + c, H - 0.001, D / 2 - c),
                      (W / 2 + c, H - 0.001, D / 2 + c), (W / 2 - c, H - 0.001, D / 2 + c)], (0, -1, 0)))

checker = []
for y in range(8):
    for x in range(8):
        checker += [204, 204, 204] if (x + y) % 2 else [51, 51, 51]
ramp = []
for x in range(16):
    ramp += [0, round(255 * (0.25 + 0.75 * x / 15)), round(255 * 0.6 * x / 15)]

gltf = {
    "asset": {"version": "2.0", "generator": "bench/scenes/make_gltf_materials.py"},
    "extensionsUsed": ["KHR_texture_transform"],
    "buffers": [],
    "bufferViews": buf.views, "accessors": buf.accessors,
    "images": [{"uri": data_uri("image/png", png(8, 8, checker))}, {"uri": data_uri("image/png", png(16, 1, ramp))}],
    "samplers": [{"wrapS": MIRRORED_REPEAT, "wrapT": MIRRORED_REPEAT}, {"wrapS": CLAMP_TO_EDGE, "wrapT": CLAMP_TO_EDGE}],
    "textures": [{"source": 0, "sampler": 0}, {"source": 1, "sampler": 1}],
    "materials": [
        {"name": "floor", "pbrMetallicRoughness": {
            "baseColorFactor": [1, 1, 1, 1], "metallicFactor": 1, "roughnessFactor": 1,
            "baseColorTexture": {"index": 0, "extensions": {"KHR_texture_transform": {"scale": [3, 3], "rotation": 0.3}}},
            "metallicRoughnessTexture": {"index": 1, "texCoord": 1}}},
        {"name": "walls", "pbrMetallicRoughness": {"baseColorFactor": [0.9, 0.9, 0.9, 1], "metallicFactor": 0,
                                                   "roughnessFactor": 1}},
        {"name": "ceiling", "pbrMetallicRoughness": {"baseColorFactor": [0.7, 0.7, 0.7, 1], "metallicFactor": 0,
                                                     "roughnessFactor": 1}},
        {"name": "lamp", "pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1], "metallicFactor": 0,
                                                  "roughnessFactor": 1},
         "emissiveFactor": [1, 1, 1], "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 20}}},
    ],
    "meshes": meshes,
    "cameras": [{"type": "perspective", "perspective": {"yfov": 0.9, "aspectRatio": 1.3333, "znear": 0.01}}],
    "nodes": [{"mesh": i} for i in range(len(meshes))] + [
        {"name": "main", "camera": 0, "translation": [W / 2, 1.6, D - 0.05],
         "rotation": [-math.sin(0.15 / 2), 0, 0, math.cos(0.15 / 2)]}],
    "scenes": [{"nodes": list(range(len(meshes) + 1))}],
}
gltf["extensionsUsed"].append("KHR_materials_emissive_strength")
gltf["buffers"].append(buf.gltf_buffer())
path = os.path.join(os.path.dirname(os.path.abspath(__file__)), "gltf-materials.gltf")
with open(path, "w") as f:
    json.dump(gltf, f, separators=(",", ":"))
print("wrote", path, os.path.getsize(path), "bytes")
