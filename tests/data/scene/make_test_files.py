#!/usr/bin/env python3
"""Writes the small glTF/OBJ test files of the scene module (standard library only).

Run from anywhere: python3 tests/data/scene/make_test_files.py
The outputs are committed; scene_test.cpp derives its expected values by hand from the
numbers below (see the comments there).

quad.gltf / quad.glb: the same scene, text (buffer as a data: URI, texture as checker.png)
and binary (buffer and texture inside the .glb):
  node "Parent" (TRS: translation (0,1,0), rotation 90 deg about +y)
    node "Quad"   (matrix: translate (0,0,-2) * scale (2,1,1)), mesh "quad":
        primitive 0: triangles, square [-1,1]^2 in z = 0, vertex normals (1,0,1)/sqrt2,
                     TEXCOORD_0 glTF-style ((0,0) = image top-left), material 0
        primitive 1: mode 1 (lines) -> must be skipped with a warning
    node "Camera" (translation (0,0,5)), perspective yfov 0.5 rad, aspectRatio 1.5
  node "Lamp"  (translation (0,3,0)), KHR_lights_punctual point, color (1,0.5,0.25), 683 cd
  node "Sun"   (no transform), directional, color (1,1,1), 1366 lx
  node "Spot"  (translation (1,4,0), rotation -90 deg about +x), spot, 1366 cd,
               innerConeAngle 0.2, outerConeAngle 0.4
material 0 "textured": baseColorFactor (0.5,0.5,0.5,1), metallic 0.25, roughness 0.5,
  baseColorTexture = checker.png, emissiveFactor (1,0.5,0), emissive strength 4.
checker.png: 2x2 sRGB, top row red, green; bottom row blue, white.

textured/quad.obj + textured/mat/quad.mtl + textured/mat/checker.png: a unit square in
z = 0 with map_Kd relative to the MTL's directory (not the OBJ's).
"""
import base64
import json
import math
import os
import struct
import zlib

HERE = os.path.dirname(os.path.abspath(__file__))


def png_bytes(width, height, rows):
    """8-bit RGB PNG; rows = list of lists of (r,g,b), top row first."""
    raw = b"".join(b"\x00" + bytes(c for px in row for c in px) for row in rows)

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)

    header = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b"")


CHECKER = png_bytes(2, 2, [[(255, 0, 0), (0, 255, 0)], [(0, 0, 255), (255, 255, 255)]])


def png_channels(width, height, rows, colour_type):
    """8-bit PNG of colour type 0 (grey), 4 (grey + alpha) or 6 (RGBA); rows of tuples."""
    raw = b"".join(b"\x00" + bytes(c for px in row for c in px) for row in rows)

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)

    header = struct.pack(">IIBBBBB", width, height, 8, colour_type, 0, 0, 0)
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b"")


# Alpha masks and normal maps (scene_test: surface detail).
# mask_rgba.png: 2x2 RGBA, top row (255,0,0,0) (0,255,0,64), bottom row (0,0,255,192) (255,255,255,255).
MASK_RGBA = png_channels(2, 2, [[(255, 0, 0, 0), (0, 255, 0, 64)], [(0, 0, 255, 192), (255, 255, 255, 255)]], 6)
# mask_grey.png: 2x2 grey, top row 0 255, bottom row 128 32 (coverage from the first channel).
MASK_GREY = png_channels(2, 2, [[(0,), (255,)], [(128,), (32,)]], 0)
# normal_tilt.png: 1x1 RGB (192, 128, 224): a tangent-space normal tilted towards +u.
NORMAL_TILT = png_bytes(1, 1, [[(192, 128, 224)]])


def pad4(data, fill=b"\x00"):
    return data + fill * ((4 - len(data) % 4) % 4)


def gltf_scene(binary):
    positions = [(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)]
    s = 1 / math.sqrt(2)
    normals = [(s, 0, s)] * 4
    uvs = [(0, 1), (1, 1), (1, 0), (0, 0)]  # glTF: v = 0 is the image's top row
    indices = [0, 1, 2, 0, 2, 3]
    line_indices = [0, 2]
    blob = b""
    views = []

    def add(data, target=None):
        nonlocal blob
        offset = len(blob)
        blob += pad4(data)
        view = {"buffer": 0, "byteOffset": offset, "byteLength": len(data)}
        if target:
            view["target"] = target
        views.append(view)
        return len(views) - 1

    v_pos = add(b"".join(struct.pack("<3f", *p) for p in positions), 34962)
    v_nrm = add(b"".join(struct.pack("<3f", *n) for n in normals), 34962)
    v_uv = add(b"".join(struct.pack("<2f", *t) for t in uvs), 34962)
    v_idx = add(struct.pack("<6H", *indices), 34963)
    v_line = add(struct.pack("<2H", *line_indices), 34963)
    accessors = [
        {"bufferView": v_pos, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-1, -1, 0], "max": [1, 1, 0]},
        {"bufferView": v_nrm, "componentType": 5126, "count": 4, "type": "VEC3"},
        {"bufferView": v_uv, "componentType": 5126, "count": 4, "type": "VEC2"},
        {"bufferView": v_idx, "componentType": 5123, "count": 6, "type": "SCALAR"},
        {"bufferView": v_line, "componentType": 5123, "count": 2, "type": "SCALAR"},
    ]
    if binary:
        v_img = add(CHECKER)
        image = {"bufferView": v_img, "mimeType": "image/png"}
    else:
        image = {"uri": "checker.png"}
    half = math.sqrt(0.5)
    doc = {
        "asset": {"version": "2.0", "generator": "plenoptic make_test_files.py"},
        "extensionsUsed": ["KHR_lights_punctual", "KHR_materials_emissive_strength"],
        "extensions": {"KHR_lights_punctual": {"lights": [
            {"name": "lamp", "type": "point", "color": [1, 0.5, 0.25], "intensity": 683},
            {"name": "sun", "type": "directional", "color": [1, 1, 1], "intensity": 1366},
            {"name": "spot", "type": "spot", "intensity": 1366,
             "spot": {"innerConeAngle": 0.2, "outerConeAngle": 0.4}},
        ]}},
        "scene": 0,
        "scenes": [{"nodes": [0, 3, 4, 5]}],
        "nodes": [
            {"name": "Parent", "translation": [0, 1, 0], "rotation": [0, half, 0, half], "children": [1, 2]},
            {"name": "Quad", "mesh": 0,
             "matrix": [2, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, -2, 1]},
            {"name": "Camera", "camera": 0, "translation": [0, 0, 5]},
            {"name": "Lamp", "translation": [0, 3, 0], "extensions": {"KHR_lights_punctual": {"light": 0}}},
            {"name": "Sun", "extensions": {"KHR_lights_punctual": {"light": 1}}},
            {"name": "Spot", "translation": [1, 4, 0], "rotation": [-half, 0, 0, half],
             "extensions": {"KHR_lights_punctual": {"light": 2}}},
        ],
        "cameras": [{"name": "cam", "type": "perspective",
                     "perspective": {"yfov": 0.5, "aspectRatio": 1.5, "znear": 0.01}}],
        "meshes": [{"name": "quad", "primitives": [
            {"attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2}, "indices": 3, "material": 0, "mode": 4},
            {"attributes": {"POSITION": 0}, "indices": 4, "mode": 1},
        ]}],
        "materials": [{
            "name": "textured",
            "pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1], "metallicFactor": 0.25,
                                     "roughnessFactor": 0.5, "baseColorTexture": {"index": 0}},
            "emissiveFactor": [1, 0.5, 0],
            "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 4}},
        }],
        "textures": [{"source": 0}],
        "images": [image],
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [{"byteLength": len(blob)}],
    }
    if binary:
        json_chunk = pad4(json.dumps(doc).encode(), b" ")
        bin_chunk = pad4(blob)
        body = struct.pack("<I4s", len(json_chunk), b"JSON") + json_chunk + struct.pack("<I4s", len(bin_chunk), b"BIN\x00") + bin_chunk
        return struct.pack("<4sII", b"glTF", 2, 12 + len(body)) + body
    doc["buffers"][0]["uri"] = "data:application/octet-stream;base64," + base64.b64encode(blob).decode()
    return (json.dumps(doc, indent=1) + "\n").encode()


def write(name, data):
    path = os.path.join(HERE, name)
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "wb") as f:
        f.write(data)


write("checker.png", CHECKER)
write("mask_rgba.png", MASK_RGBA)
write("mask_grey.png", MASK_GREY)
write("normal_tilt.png", NORMAL_TILT)
write("quad.gltf", gltf_scene(False))
write("quad.glb", gltf_scene(True))
write("textured/mat/checker.png", CHECKER)
write("textured/mat/quad.mtl", b"newmtl checker\nKd 1 1 1\nmap_Kd checker.png\n")
write("textured/quad.obj", b"mtllib mat/quad.mtl\n"
      b"v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
      b"vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
      b"usemtl checker\nf 1/1 2/2 3/3 4/4\n")
