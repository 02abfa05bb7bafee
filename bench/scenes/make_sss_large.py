#!/usr/bin/env python3
"""Writes a scene with a large subsurface object into OUTDIR (not committed: 0.65 MB of OBJ):

  sss-large.obj, .mtl, .json   McGuire's CornellBox-Original walls and light (as
                               make_sss_cornell.py) around one marble-like sphere of radius 0.75
                               (an icosphere of 20 480 flat triangles) standing on the floor.

What docs/benchmarks.md ("Subsurface scattering in the light field") measures the operator's
cost on. Usage: make_sss_large.py OUTDIR
"""
import json
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from make_sss_cornell import MTL, WALLS, icosphere, write_obj  # noqa: E402

MARBLE = {"type": "subsurface", "albedo": [0.83, 0.79, 0.75], "radius": [0.2, 0.15, 0.1]}


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    out = sys.argv[1]
    os.makedirs(out, exist_ok=True)
    objects = [(name, quad, [(0, 1, 2), (0, 2, 3)]) for name, quad in WALLS]
    objects.append(("marble", *icosphere((0.0, 0.76, -0.1), 0.75, 5)))
    write_obj(os.path.join(out, "sss-large.obj"), ["# Written by bench/scenes/make_sss_large.py", "mtllib sss-large.mtl"],
              objects)
    with open(os.path.join(out, "sss-large.mtl"), "w") as f:
        for name, body in {**MTL, "marble": "Kd 0.5 0.5 0.5"}.items():
            f.write(f"newmtl {name}\n{body}\n\n")
    scene = {
        "meshes": [{"file": "sss-large.obj"}],
        "materials": {"marble": MARBLE},
        "cameras": [{"name": "main", "eye": [0, 1, 3.5], "target": [0, 1, 0], "up": [0, 1, 0], "fov": 40}],
    }
    with open(os.path.join(out, "sss-large.json"), "w") as f:
        json.dump(scene, f, indent=1)
        f.write("\n")


if __name__ == "__main__":
    main()
