#!/usr/bin/env python3
"""Writes the subsurface test scene of bench/sss_vs_cycles.sh beside this script:

  sss-cornell.obj, .mtl  McGuire's CornellBox-Original walls and light (public domain, Guedis
                         Cardenas and Morgan McGuire, 2011; tests/data/cornell-mcguire) with a
                         sphere (`sphere`, an icosphere of 1280 flat triangles, radius 0.35)
                         and a thin upright slab (`slab`, 0.7 × 0.9 × 0.06, turned 25° about
                         the vertical), both closed and wound outwards; in the .mtl they are
                         plain grey Lambertian stand-ins.
  sss-cornell.json       the OBJ with `sphere` and `slab` made subsurface and the camera of
                         bench/vs_cycles.sh (eye (0, 1, 3.5), target (0, 1, 0), 40° vertical).
  sss-furnace.obj, .json the sphere and the slab alone under a white sky of radiance 1.

The Blender script (bench/sss_vs_cycles_blender.py) reads the same JSON for the subsurface
parameters, so the two renderers cannot disagree on them. Usage: make_sss_cornell.py
"""
import json
import math
import os

HERE = os.path.dirname(os.path.abspath(__file__))

# Subsurface parameters (albedo A, radius d in scene units, per channel): a wax-like sphere whose
# red light travels furthest, and a thin slab, as thick as a fraction of its radius, that glows.
SUBSURFACE = {
    "sphere": {"type": "subsurface", "albedo": [0.85, 0.6, 0.35], "radius": [0.3, 0.15, 0.08]},
    "slab": {"type": "subsurface", "albedo": [0.7, 0.8, 0.9], "radius": [0.1, 0.1, 0.1]},
}

WALLS = [  # McGuire's CornellBox-Original: name, quad
    ("floor", [(-1.01, 0.00, 0.99), (1.00, 0.00, 0.99), (1.00, 0.00, -1.04), (-0.99, 0.00, -1.04)]),
    ("ceiling", [(-1.02, 1.99, 0.99), (-1.02, 1.99, -1.04), (1.00, 1.99, -1.04), (1.00, 1.99, 0.99)]),
    ("backWall", [(-0.99, 0.00, -1.04), (1.00, 0.00, -1.04), (1.00, 1.99, -1.04), (-1.02, 1.99, -1.04)]),
    ("rightWall", [(1.00, 0.00, -1.04), (1.00, 0.00, 0.99), (1.00, 1.99, 0.99), (1.00, 1.99, -1.04)]),
    ("leftWall", [(-1.01, 0.00, 0.99), (-0.99, 0.00, -1.04), (-1.02, 1.99, -1.04), (-1.02, 1.99, 0.99)]),
    ("light", [(-0.24, 1.98, 0.16), (-0.24, 1.98, -0.22), (0.23, 1.98, -0.22), (0.23, 1.98, 0.16)]),
]
MTL = {  # McGuire's values (Kd; the light's Ke)
    "floor": "Kd 0.725 0.71 0.68", "ceiling": "Kd 0.725 0.71 0.68", "backWall": "Kd 0.725 0.71 0.68",
    "rightWall": "Kd 0.14 0.45 0.091", "leftWall": "Kd 0.63 0.065 0.05", "light": "Kd 0.78 0.78 0.78\nKe 17 12 4",
    "sphere": "Kd 0.5 0.5 0.5", "slab": "Kd 0.5 0.5 0.5",
}


def icosphere(centre, radius, subdivisions):
    t = (1.0 + math.sqrt(5.0)) / 2.0
    verts = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t), (0, -1, -t), (0, 1, -t),
             (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    verts = [tuple(c / math.sqrt(sum(x * x for x in v)) for c in v) for v in verts]
    faces = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4), (11, 10, 2),
             (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9), (4, 9, 5), (2, 4, 11),
             (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    for _ in range(subdivisions):
        midpoints, refined = {}, []

        def middle(a, b):
            key = (min(a, b), max(a, b))
            if key not in midpoints:
                m = [(verts[a][k] + verts[b][k]) / 2.0 for k in range(3)]
                n = math.sqrt(sum(x * x for x in m))
                verts.append(tuple(x / n for x in m))
                midpoints[key] = len(verts) - 1
            return midpoints[key]

        for a, b, c in faces:
            ab, bc, ca = middle(a, b), middle(b, c), middle(c, a)
            refined += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        faces = refined
    points = [tuple(centre[k] + radius * v[k] for k in range(3)) for v in verts]
    return points, faces  # wound outwards (counter-clockwise seen from outside)


def box(centre, size, degrees):
    """An upright box turned `degrees` about +y, faces wound outwards."""
    c, s = math.cos(math.radians(degrees)), math.sin(math.radians(degrees))
    points = []
    for i in range(8):
        x, y, z = ((i >> k & 1) - 0.5 for k in range(3))
        x, y, z = x * size[0], y * size[1], z * size[2]
        points.append((centre[0] + c * x + s * z, centre[1] + y, centre[2] - s * x + c * z))
    faces = []
    for a, b, cc, d in [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]:
        faces += [(a, b, cc), (a, cc, d)]
    return points, faces


def write_obj(path, header, objects):
    """An OBJ of `objects` (name, points, faces; each its own object and material) after `header`."""
    lines = list(header)
    base = 1
    for name, points, faces in objects:
        lines += [f"o {name}", f"usemtl {name}"]
        lines += [f"v {x:.6f} {y:.6f} {z:.6f}" for x, y, z in points]
        lines += [f"f {a + base} {b + base} {c + base}" for a, b, c in faces]
        base += len(points)
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")


def main():
    objects = [(name, quad, [(0, 1, 2), (0, 2, 3)]) for name, quad in WALLS]
    objects.append(("sphere", *icosphere((-0.42, 0.36, 0.25), 0.35, 3)))
    objects.append(("slab", *box((0.42, 0.46, -0.3), (0.7, 0.9, 0.06), -25.0)))
    # The box, and the furnace: the two objects alone under a white sky of radiance 1, where
    # each pixel is one walk's albedo (no transport between objects).
    for stem, kept, extra in (("sss-cornell", objects, {}),
                              ("sss-furnace", objects[-2:], {"environment": {"color": 1}})):
        write_obj(os.path.join(HERE, stem + ".obj"),
                  ["# Written by bench/scenes/make_sss_cornell.py: McGuire's CornellBox-Original walls",
                   f"# (public domain) with a subsurface sphere and slab ({stem}.json)", "mtllib sss-cornell.mtl"],
                  kept)
        scene = {
            "meshes": [{"file": stem + ".obj"}],
            "materials": SUBSURFACE,
            "cameras": [{"name": "main", "eye": [0, 1, 3.5], "target": [0, 1, 0], "up": [0, 1, 0], "fov": 40}],
            **extra,
        }
        with open(os.path.join(HERE, stem + ".json"), "w") as f:
            f.write("{\n" + ",\n".join(f' "{key}": {json.dumps(value)}' for key, value in scene.items()) + "\n}\n")
    with open(os.path.join(HERE, "sss-cornell.mtl"), "w") as f:
        f.write("# Written by bench/scenes/make_sss_cornell.py\n")
        for name, body in MTL.items():
            f.write(f"\nnewmtl {name}\n{body}\n")


if __name__ == "__main__":
    main()
