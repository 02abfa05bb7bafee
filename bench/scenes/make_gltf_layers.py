#!/usr/bin/env python3
"""Writes bench/scenes/gltf-layers.gltf (standard library only): bench/scenes/gltf-materials.gltf
with glTF's layers over the diffuse bases of its walls and ceiling, for the GPU renderer's tests
of KHR_materials_clearcoat and KHR_materials_sheen (src/gpu/gpu_test.cpp).

Run from anywhere: /usr/bin/python3 bench/scenes/make_gltf_layers.py
The output is committed (self-contained, as gltf-materials.gltf is).

  walls    a clear coat (factor 0.8, roughness 0.3) and a sheen (colour 0.6 0.5 0.4,
           roughness 0.4) over the COLOR_0-tinted base of roughness 1;
  ceiling  a sheen alone (colour 0.9, roughness 0.7);
  floor    as it is (its metallic-roughness texture), the lamp as it is.
"""
import json
import os

here = os.path.dirname(os.path.abspath(__file__))
with open(os.path.join(here, "gltf-materials.gltf")) as f:
    gltf = json.load(f)
gltf["asset"]["generator"] = "bench/scenes/make_gltf_layers.py"
gltf["extensionsUsed"] = sorted(set(gltf.get("extensionsUsed", [])) | {"KHR_materials_clearcoat", "KHR_materials_sheen"})
layers = {
    "walls": {"KHR_materials_clearcoat": {"clearcoatFactor": 0.8, "clearcoatRoughnessFactor": 0.3},
              "KHR_materials_sheen": {"sheenColorFactor": [0.6, 0.5, 0.4], "sheenRoughnessFactor": 0.4}},
    "ceiling": {"KHR_materials_sheen": {"sheenColorFactor": [0.9, 0.9, 0.9], "sheenRoughnessFactor": 0.7}},
}
for material in gltf["materials"]:
    material.setdefault("extensions", {}).update(layers.get(material["name"], {}))
    if not material["extensions"]:
        del material["extensions"]
with open(os.path.join(here, "gltf-layers.gltf"), "w") as f:
    json.dump(gltf, f, separators=(",", ":"))
    f.write("\n")
