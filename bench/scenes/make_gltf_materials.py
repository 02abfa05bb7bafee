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
import base64
import json
import math
import os
import struct
import zlib


def png(width, height, rgb):
    """An 8-bit RGB PNG of rows top to bottom."""
    raw = b"".join(b"\0" + bytes(rgb[y * width * 3:(y + 1) * width * 3]) for y in range(height))
    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xffffffff)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0))
            + chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b""))


def data_uri(mime, data):
    return "data:%s;base64,%s" % (mime, base64.b64encode(data).decode())


buffer = bytearray()
views, accessors = [], []


def add(values, fmt, ctype, count, kind, target=None, minmax=False):
    while len(buffer) % 4:
        buffer.append(0)
    offset = len(buffer)
    for v in values:
        buffer.extend(struct.pack("<" + fmt, *v) if isinstance(v, tuple) else struct.pack("<" + fmt, v))
    views.append({"buffer": 0, "byteOffset": offset, "byteLength": len(buffer) - offset})
    accessor = {"bufferView": len(views) - 1, "componentType": ctype, "count": count, "type": kind}
    if minmax:
        accessor["min"] = [min(v[i] for v in values) for i in range(3)]
        accessor["max"] = [max(v[i] for v in values) for i in range(3)]
    accessors.append(accessor)
    return len(accessors) - 1


def quad(corners, normal, uv1=None, colors=None, n=1):
    """A quad split into n x n cells (so that vertex colours vary), corners counter-clockwise
    seen from the front: p0 + s (p1 - p0) + t (p3 - p0)."""
    p0, p1, _, p3 = corners
    pos, uvs, uv1s, cols, idx = [], [], [], [], []
    for j in range(n + 1):
        for i in range(n + 1):
            s, t = i / n, j / n
            p = tuple(p0[k] + s * (p1[k] - p0[k]) + t * (p3[k] - p0[k]) for k in range(3))
            pos.append(p)
            uvs.append((s, 1 - t))
            if uv1:
                uv1s.append(uv1(p))
            if colors:
                cols.append(colors(p))
    for j in range(n):
        for i in range(n):
            a = j * (n + 1) + i
            idx += [a, a + 1, a + n + 2, a, a + n + 2, a + n + 1]
    attributes = {"POSITION": add(pos, "3f", 5126, len(pos), "VEC3", minmax=True),
                  "NORMAL": add([normal] * len(pos), "3f", 5126, len(pos), "VEC3"),
                  "TEXCOORD_0": add(uvs, "2f", 5126, len(uvs), "VEC2")}
    if uv1:
        attributes["TEXCOORD_1"] = add(uv1s, "2f", 5126, len(uv1s), "VEC2")
    if colors:
        attributes["COLOR_0"] = add(cols, "3f", 5126, len(cols), "VEC3")
    return attributes, add(idx, "H", 5123, len(idx), "SCALAR")


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


mesh("floor", 0, quad([(0, 0, D), (W, 0, D), (W, 0, 0), (0, 0, 0)], (0, 1, 0), uv1=lambda p: (p[0] / W, 0.5)))
mesh("ceiling", 2, quad([(0, H, 0), (W, H, 0), (W, H, D), (0, H, D)], (0, -1, 0)))
mesh("back", 1, quad([(0, 0, 0), (W, 0, 0), (W, H, 0), (0, H, 0)], (0, 0, 1), colors=wall_colour, n=6))
mesh("left", 1, quad([(0, 0, D), (0, 0, 0), (0, H, 0), (0, H, D)], (1, 0, 0), colors=wall_colour, n=6))
mesh("right", 1, quad([(W, 0, 0), (W, 0, D), (W, H, D), (W, H, 0)], (-1, 0, 0), colors=wall_colour, n=6))
mesh("front", 1, quad([(W, 0, D), (0, 0, D), (0, H, D), (W, H, D)], (0, 0, -1), colors=wall_colour, n=6))
c = 0.5
mesh("lamp", 3, quad([(W / 2 - c, H - 0.001, D / 2 - c), (W / 2 + c, H - 0.001, D / 2 - c),
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
    "bufferViews": views, "accessors": accessors,
    "images": [{"uri": data_uri("image/png", png(8, 8, checker))}, {"uri": data_uri("image/png", png(16, 1, ramp))}],
    "samplers": [{"wrapS": 33648, "wrapT": 33648}, {"wrapS": 33071, "wrapT": 33071}],
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
gltf["buffers"].append({"byteLength": len(buffer), "uri": data_uri("application/octet-stream", bytes(buffer))})
path = os.path.join(os.path.dirname(os.path.abspath(__file__)), "gltf-materials.gltf")
with open(path, "w") as f:
    json.dump(gltf, f, separators=(",", ":"))
print("wrote", path, os.path.getsize(path), "bytes")
