#!/usr/bin/env python3
"""Writes the conformance matrix's scenes (issue 31, item 1): small JSON scenes spanning
materials x lights x geometry around one Cornell-box room, each a named case.

    python3 bench/conformance/make_scenes.py OUTDIR [CASE ...]   # writes OUTDIR/CASE.json (+ OBJs)
    python3 bench/conformance/make_scenes.py --list [CASE ...]   # prints "name<TAB>what it varies"

Standard library only. The scenes are generated, not committed: bench/conformance.sh and the
ctest tests under tests/conformance write them into their work directory. Textures and the
environment map are read from tests/data (absolute paths in the JSON files), so nothing outside
the repository is needed.

The room is the built-in Cornell box (src/scene/cornell.cpp: the measured box, millimetres,
Mitsuba 3's RGB colours, the 130 x 105 mm light 0.1 mm below the ceiling) written as OBJ files,
so that each surface has a material name of its own (floor, ceiling, backWall, leftWall = red,
rightWall = green, light, shortBlock, tallBlock) a case can replace, and so that the same box can
be scaled and mirrored by a mesh transform. Like the built-in box its quads are not welded and
it has no front wall: an open room (the case `lambert` is the built-in box in this form; the
case `builtin` is `"include_cornell": true` itself). `closed-room` is the welded, closed
variant with a front wall and the camera inside.

Every case has one camera, "main" (the built-in box's: eye (278, 273, -800) looking down +z,
39.3077 degrees vertical fov), moved by the case's transform like the meshes.
"""
import json
import os
import re
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
DATA = os.path.normpath(os.path.join(HERE, "..", "..", "tests", "data"))
CHECKER = os.path.join(DATA, "scene", "checker.png")          # 2x2 sRGB: red, green / blue, white
NORMAL_TILT = os.path.join(DATA, "scene", "normal_tilt.png")  # 1x1: a normal tilted ~34 deg towards +u
MASK = os.path.join(DATA, "scene", "mask_rgba.png")           # 2x2 alpha 0, 64 / 192, 255
ENVMAP = os.path.join(DATA, "envmaps", "venice_sunset_1k.hdr")

# The built-in box's colours (cornell.cpp).
WHITE = [0.885809, 0.698859, 0.666422]
RED = [0.570068, 0.0430135, 0.0443706]
GREEN = [0.105421, 0.37798, 0.076425]
LIGHT_RADIANCE = [18.387, 13.9873, 6.75357]
UV_PERIOD = 140.0  # mm per texture repeat (the 2x2 textures: one texel per 70 mm)

# The white surfaces a "walls" material goes on (the coloured side walls stay Lambertian).
WHITE_SURFACES = ["floor", "ceiling", "backWall", "shortBlock", "tallBlock"]


def sub(a, b):
    return [a[i] - b[i] for i in range(3)]


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def dot(a, b):
    return sum(a[i] * b[i] for i in range(3))


def oriented(quad, reference, facing=True):
    """The quad wound counter-clockwise seen from `reference` (front towards it) when facing,
    else away from it."""
    n = cross(sub(quad[1], quad[0]), sub(quad[2], quad[0]))
    centre = [sum(p[i] for p in quad) / 4.0 for i in range(3)]
    if (dot(n, sub(reference, centre)) > 0) != facing:
        quad = [quad[0], quad[3], quad[2], quad[1]]
    return quad


def planar_uv(p, normal):
    """uv by projection along the quad's dominant axis, UV_PERIOD mm per repeat; u runs along
    +x on the floor, ceiling and back wall, along +z on the side walls; v along +z or +y."""
    ax = max(range(3), key=lambda i: abs(normal[i]))
    if ax == 0:
        u, v = p[2], p[1]
    elif ax == 1:
        u, v = p[0], p[2]
    else:
        u, v = p[0], p[1]
    return (u / UV_PERIOD, v / UV_PERIOD)


class Obj:
    """A tiny OBJ writer: quads with planar uvs, grouped by material, optionally welded (one
    vertex per distinct position, so shared edges connect the surface)."""

    def __init__(self, weld=False):
        self.weld = weld
        self.v, self.vt, self.faces = [], [], []  # faces: (material, [(vi, ti), ...])
        self.index = {}

    def vertex(self, p):
        key = tuple(round(c, 6) for c in p)
        if self.weld and key in self.index:
            return self.index[key]
        self.v.append(p)
        self.index[key] = len(self.v)
        return len(self.v)

    def quad(self, material, quad):
        normal = cross(sub(quad[1], quad[0]), sub(quad[2], quad[0]))
        refs = []
        for p in quad:
            self.vt.append(planar_uv(p, normal))
            refs.append((self.vertex(p), len(self.vt)))
        self.faces.append((material, refs))

    def write(self, path, mtl="room.mtl"):
        lines = ["# written by bench/conformance/make_scenes.py", f"mtllib {mtl}"]
        lines += [f"v {p[0]:.6g} {p[1]:.6g} {p[2]:.6g}" for p in self.v]
        lines += [f"vt {t[0]:.6g} {t[1]:.6g}" for t in self.vt]
        current = None
        for material, refs in self.faces:
            if material != current:
                lines.append(f"usemtl {material}")
                current = material
            lines.append("f " + " ".join(f"{vi}/{ti}" for vi, ti in refs))
        with open(path, "w") as f:
            f.write("\n".join(lines) + "\n")


# ---- geometry (millimetres, cornell.cpp) ----------------------------------------------------
ROOM_CENTRE = [278.0, 274.4, 279.6]
FLOOR = [[552.8, 0, 0], [0, 0, 0], [0, 0, 559.2], [549.6, 0, 559.2]]
CEILING = [[556, 548.8, 0], [556, 548.8, 559.2], [0, 548.8, 559.2], [0, 548.8, 0]]
BACK = [[549.6, 0, 559.2], [0, 0, 559.2], [0, 548.8, 559.2], [556, 548.8, 559.2]]
RIGHT = [[0, 0, 559.2], [0, 0, 0], [0, 548.8, 0], [0, 548.8, 559.2]]          # x = 0, green
LEFT = [[552.8, 0, 0], [549.6, 0, 559.2], [556, 548.8, 559.2], [556, 548.8, 0]]  # red
FRONT = [[552.8, 0, 0], [0, 0, 0], [0, 548.8, 0], [556, 548.8, 0]]            # closed-room only
LIGHT_Y = 548.8 - 0.1
LIGHT = [[343, LIGHT_Y, 227], [343, LIGHT_Y, 332], [213, LIGHT_Y, 332], [213, LIGHT_Y, 227]]
SHORT_XZ = [(130, 65), (82, 225), (240, 272), (290, 114)]
TALL_XZ = [(423, 247), (265, 296), (314, 456), (472, 406)]


def room_obj(path, ceiling=True, closed=False):
    obj = Obj(weld=closed)
    surfaces = [("floor", FLOOR), ("backWall", BACK), ("rightWall", RIGHT), ("leftWall", LEFT)]
    if ceiling:
        surfaces.insert(1, ("ceiling", CEILING))
    if closed:
        surfaces.append(("frontWall", FRONT))
    for name, quad in surfaces:
        obj.quad(name, oriented(quad, ROOM_CENTRE, True))
    obj.write(path)


def light_obj(path):
    obj = Obj()
    obj.quad("light", oriented(LIGHT, [278, 0, 279.5], True))  # faces down
    obj.write(path)


def block_obj(path, material, xz, height, y0=0.0, bottom=False):
    """A block over the floor polygon xz from y0 to height, faces outwards: its sides and top,
    and with bottom=True its bottom too, welded (a closed, consistently wound surface)."""
    top = [[x, height, z] for x, z in xz]
    low = [[x, y0, z] for x, z in xz]
    centre = [sum(p[0] for p in top) / 4, (height + y0) / 2, sum(p[2] for p in top) / 4]
    obj = Obj(weld=bottom)
    faces = [top] + [[low[i], top[i], top[(i + 1) % 4], low[(i + 1) % 4]] for i in range(4)]
    if bottom:
        faces.append(low)
    for q in faces:
        obj.quad(material, oriented(q, centre, False))
    obj.write(path)


def panel_obj(path, material, quad, towards):
    """One quad (a sheet) whose front faces the point `towards`."""
    obj = Obj()
    obj.quad(material, oriented(quad, towards, True))
    obj.write(path)


def write_geometry(outdir):
    room_obj(os.path.join(outdir, "room.obj"))
    room_obj(os.path.join(outdir, "room_open_top.obj"), ceiling=False)
    room_obj(os.path.join(outdir, "room_closed.obj"), closed=True)
    light_obj(os.path.join(outdir, "light.obj"))
    block_obj(os.path.join(outdir, "short.obj"), "shortBlock", SHORT_XZ, 165)
    block_obj(os.path.join(outdir, "tall.obj"), "tallBlock", TALL_XZ, 330)
    block_obj(os.path.join(outdir, "short_closed.obj"), "shortBlock", SHORT_XZ, 165, bottom=True)
    block_obj(os.path.join(outdir, "tall_closed.obj"), "tallBlock", TALL_XZ, 330, bottom=True)
    # The glass block: the tall block closed, lifted 0.5 mm off the floor (no coplanar faces).
    block_obj(os.path.join(outdir, "tall_glass.obj"), "glass", TALL_XZ, 330.5, y0=0.5, bottom=True)
    # A horizontal sheet under the light, facing down (alpha-masked, thin glass).
    panel_obj(os.path.join(outdir, "ceiling_panel.obj"), "panel",
              [[60, 420, 60], [500, 420, 60], [500, 420, 500], [60, 420, 500]], [278, 0, 279.6])
    # A vertical sheet behind the light, its front towards the back wall: the camera and the
    # light see its back side.
    panel_obj(os.path.join(outdir, "sheet_back.obj"), "sheet",
              [[110, 40, 380], [450, 40, 380], [450, 400, 380], [110, 400, 380]], [278, 274, 1000])
    # A vertical emitting sheet beside the short block, its front away from the camera.
    panel_obj(os.path.join(outdir, "glow_panel.obj"), "glow",
              [[300, 80, 150], [500, 80, 150], [500, 300, 150], [300, 300, 150]], [400, 190, 1000])
    with open(os.path.join(outdir, "room.mtl"), "w") as f:
        # Placeholders: every case's JSON gives every material (MATERIALS below).
        for name in ["floor", "ceiling", "backWall", "rightWall", "leftWall", "frontWall", "light",
                     "shortBlock", "tallBlock", "glass", "panel", "sheet", "glow"]:
            f.write(f"newmtl {name}\nKd 0.5 0.5 0.5\nKs 0 0 0\n\n")


# ---- materials ------------------------------------------------------------------------------
def lambert(albedo, **extra):
    return {"type": "lambert", "albedo": albedo, **extra}


def base_materials():
    m = {name: lambert(WHITE) for name in ["floor", "ceiling", "backWall", "frontWall", "shortBlock", "tallBlock"]}
    m["leftWall"] = lambert(RED)
    m["rightWall"] = lambert(GREEN)
    m["light"] = lambert(WHITE, emission=LIGHT_RADIANCE)
    return m


def scaled(c, k):
    return [round(k * x, 6) for x in c]


def ggx(roughness, metal=False, **extra):
    if metal:
        return {"type": "ggx", "diffuse": 0, "f0": 0.9, "roughness": roughness, **extra}
    return {"type": "ggx", "diffuse": scaled(WHITE, 0.9), "f0": 0.04, "roughness": roughness, **extra}


def blinn_phong(exponent, **extra):
    return {"type": "blinn-phong", "diffuse": scaled(WHITE, 0.6), "specular": 0.35, "exponent": exponent, **extra}


def on_white(material):
    return {name: dict(material) for name in WHITE_SURFACES}


LIGHT_OFF = {"light": lambert(WHITE)}
POINT = {"type": "point", "position": [278, 450, 279.6], "intensity": 1.5e5}
SPHERE = {"type": "sphere", "position": [278, 420, 500], "radius": 30, "intensity": 1.5e5}
SPOT_NARROW = {"type": "spot", "position": [278, 540, 279.6], "direction": [122, -540, -159.6],
               "intensity": 2e7, "inner_angle": 3, "outer_angle": 6}
SPOT_WIDE = {"type": "spot", "position": [278, 540, 279.6], "direction": [0, -1, 0],
             "intensity": 1e6, "inner_angle": 25, "outer_angle": 40}
SUN_FRONT = {"type": "directional", "direction": [0.25, -0.45, 1.0], "irradiance": 3}
SUN_ABOVE = {"type": "directional", "direction": [0.3, -1.0, 0.4], "irradiance": 2}

STD_MESHES = ["room.obj", "light.obj", "short.obj", "tall.obj"]


def case(name, varies, materials=None, meshes=None, lights=None, environment=None, transform=None,
         camera=None, builtin=False):
    return {"name": name, "varies": varies, "materials": materials or {}, "meshes": meshes or STD_MESHES,
            "lights": lights or [], "environment": environment, "transform": transform, "camera": camera,
            "builtin": builtin}


def mirror_x():
    return [[-1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]


def uniform(s):
    return [[s, 0, 0, 0], [0, s, 0, 0], [0, 0, s, 0], [0, 0, 0, 1]]


CASES = [
    case("builtin", "the built-in box (`\"include_cornell\": true`), all Lambert, its area light", builtin=True),
    case("lambert", "the same box as OBJ files (the base of every other case)"),
    case("bp-10", "Blinn-Phong exponent 10 on the white surfaces", on_white(blinn_phong(10))),
    case("bp-100", "Blinn-Phong exponent 100 on the white surfaces", on_white(blinn_phong(100))),
    case("bp-1000", "Blinn-Phong exponent 1000 on the white surfaces", on_white(blinn_phong(1000))),
    case("ggx-d-0.05", "GGX dielectric (diffuse + f0 0.04), roughness 0.05, white surfaces", on_white(ggx(0.05))),
    case("ggx-d-0.2", "GGX dielectric, roughness 0.2", on_white(ggx(0.2))),
    case("ggx-d-0.3", "GGX dielectric, roughness 0.3", on_white(ggx(0.3))),
    case("ggx-d-0.6", "GGX dielectric, roughness 0.6", on_white(ggx(0.6))),
    case("ggx-m-0.05", "GGX metal (f0 0.9, no diffuse), roughness 0.05, white surfaces", on_white(ggx(0.05, True))),
    case("ggx-m-0.2", "GGX metal, roughness 0.2", on_white(ggx(0.2, True))),
    case("ggx-m-0.3", "GGX metal, roughness 0.3", on_white(ggx(0.3, True))),
    case("ggx-m-0.6", "GGX metal, roughness 0.6", on_white(ggx(0.6, True))),
    case("mirror-wall", "the back wall an ideal mirror (reflectance 0.9)",
         {"backWall": {"type": "mirror", "reflectance": 0.9}}),
    case("glass-smooth", "the tall block smooth solid glass (ior 1.5, closed, 0.5 mm off the floor)",
         {"glass": {"type": "dielectric", "ior": 1.5}}, ["room.obj", "light.obj", "short.obj", "tall_glass.obj"]),
    case("glass-rough", "the tall block rough glass (roughness 0.3)",
         {"glass": {"type": "dielectric", "ior": 1.5, "roughness": 0.3}},
         ["room.obj", "light.obj", "short.obj", "tall_glass.obj"]),
    case("glass-thin", "a thin glass sheet (transmittance 0.9) under the light, y = 420",
         {"panel": {"type": "dielectric", "ior": 1.5, "thin": True, "transmittance": 0.9}},
         STD_MESHES + ["ceiling_panel.obj"]),
    case("tex-lambert", "checker-textured Lambert (albedo 0.8 x checker.png) on floor, back wall, blocks",
         {n: lambert(0.8, texture=CHECKER) for n in ["floor", "backWall", "shortBlock", "tallBlock"]}),
    case("tex-ggx", "checker-textured GGX dielectric (roughness 0.3) on floor, back wall, blocks",
         {n: ggx(0.3, texture=CHECKER) for n in ["floor", "backWall", "shortBlock", "tallBlock"]}),
    case("tex-bp", "checker-textured Blinn-Phong (exponent 100) on floor, back wall, blocks",
         {n: blinn_phong(100, texture=CHECKER) for n in ["floor", "backWall", "shortBlock", "tallBlock"]}),
    case("normal-lambert", "a normal-mapped Lambert back wall (normal_tilt.png: ~34 deg towards +x)",
         {"backWall": lambert(WHITE, normal_texture=NORMAL_TILT)}),
    case("normal-ggx", "normal-mapped GGX dielectric (roughness 0.3) back wall and floor",
         {n: ggx(0.3, normal_texture=NORMAL_TILT) for n in ["backWall", "floor"]}),
    case("alpha-mask", "an alpha-masked Lambert sheet under the light (mask_rgba.png, cutoff 0.5)",
         {"panel": lambert(0.8, alpha_texture=MASK)}, STD_MESHES + ["ceiling_panel.obj"]),
    case("point", "a point light (1.5e5 W/sr at y = 450), area light off", LIGHT_OFF, lights=[POINT]),
    case("point-ggx-0.2", "the point light on GGX dielectric roughness 0.2 (issue 31's first row)",
         {**LIGHT_OFF, **on_white(ggx(0.2))}, lights=[POINT]),
    case("sphere-mirror", "a sphere light (radius 30 mm, 1.5e5 W/sr, 59 mm before the back wall), area light off, "
         "reflected in the GGX metal ceiling (roughness 0.05), seen there and through the mirror back wall (0.9)",
         {**LIGHT_OFF, "backWall": {"type": "mirror", "reflectance": 0.9}, "ceiling": ggx(0.05, True)}, lights=[SPHERE]),
    case("spot-narrow", "a narrow spot (3 deg / 6 deg) on the floor, area light off", LIGHT_OFF, lights=[SPOT_NARROW]),
    case("spot-wide", "a wide spot (25 deg / 40 deg) straight down, area light off", LIGHT_OFF, lights=[SPOT_WIDE]),
    case("directional", "a sun (3 W/m^2) through the open front, area light off", LIGHT_OFF, lights=[SUN_FRONT]),
    case("directional-ggx-0.3", "the sun on GGX dielectric roughness 0.3", {**LIGHT_OFF, **on_white(ggx(0.3))},
         lights=[SUN_FRONT]),
    case("env-const", "a constant white sky (radiance 1) through the open front, area light off", LIGHT_OFF,
         environment={"color": 1}),
    case("env-map", "venice_sunset_1k.hdr through the open front, area light off", LIGHT_OFF,
         environment={"file": ENVMAP, "scale": 1, "rotation": 0}),
    case("emissive-block", "the short block emissive (2 W/sr/m^2, one-sided), area light off",
         {**LIGHT_OFF, "shortBlock": lambert(WHITE, emission=2)}),
    case("emissive-texture", "the short block emissive x checker.png (4 W/sr/m^2 x texel, one-sided), area light off",
         {**LIGHT_OFF, "shortBlock": lambert(WHITE, emission=4, emission_texture=CHECKER)}),
    case("emissive-two-sided", "a two-sided emitting sheet seen from its back, area light off",
         {**LIGHT_OFF, "glow": lambert(0.5, emission=3, two_sided=True)}, STD_MESHES + ["glow_panel.obj"]),
    case("closed-room", "closed geometry: welded room with a front wall, closed blocks, camera inside",
         meshes=["room_closed.obj", "light.obj", "short_closed.obj", "tall_closed.obj"],
         camera={"eye": [278, 273, 20], "target": [278, 273, 559.2], "fov": 70}),
    case("open-top", "open geometry: no ceiling or light, venice sky + a sun from above (two-sided walls)",
         meshes=["room_open_top.obj", "short.obj", "tall.obj"], lights=[SUN_ABOVE],
         environment={"file": ENVMAP, "scale": 1, "rotation": 0}),
    case("sheet-back", "a Lambert sheet seen and lit from its back side (blocks removed)",
         {"sheet": lambert(0.8)}, ["room.obj", "light.obj", "sheet_back.obj"]),
    case("scale-1e-3", "the box scaled x 0.001 (the same room in metres)", transform=uniform(1e-3)),
    case("scale-1e-6", "the box scaled x 1e-6 (the same room in kilometres)", transform=uniform(1e-6)),
    case("scale-1e3", "the box scaled x 1000 (a 556 m hall in millimetres)", transform=uniform(1e3)),
    case("mirrored", "the box mirrored (scale -1, 1, 1), camera mirrored too", transform=mirror_x()),
    case("mirrored-ggx-0.2", "the mirrored box with GGX dielectric roughness 0.2", on_white(ggx(0.2)),
         transform=mirror_x()),
    case("mirrored-normal", "the mirrored box with the normal-mapped back wall",
         {"backWall": lambert(WHITE, normal_texture=NORMAL_TILT)}, transform=mirror_x()),
]

MAIN_CAMERA = {"eye": [278, 273, -800], "target": [278, 273, 0], "fov": 39.3077}


def apply(m, p, w=1.0):
    return [m[i][0] * p[0] + m[i][1] * p[1] + m[i][2] * p[2] + m[i][3] * w for i in range(3)]


def num(x):
    """Short, exact-enough JSON numbers (no 1e-06 noise)."""
    return float(f"{x:.9g}") if isinstance(x, float) else x


def scene_of(c):
    m = c["transform"]
    cam = dict(MAIN_CAMERA)
    cam.update(c["camera"] or {})
    camera = {"name": "main", "eye": cam["eye"], "target": cam["target"], "up": [0, 1, 0], "fov": cam["fov"]}
    lights = [dict(light) for light in c["lights"]]
    if m is not None:
        camera["eye"] = [num(x) for x in apply(m, camera["eye"])]
        camera["target"] = [num(x) for x in apply(m, camera["target"])]
        for light in lights:
            if "position" in light:
                light["position"] = [num(x) for x in apply(m, light["position"])]
            if "direction" in light:
                light["direction"] = [num(x) for x in apply(m, light["direction"], 0.0)]
        # Point/spot intensities would need scaling by the square of a uniform scale to light
        # the room alike; the transformed cases use the area light alone.
    if c["builtin"]:
        scene = {"include_cornell": True, "cameras": [camera]}
    else:
        materials = base_materials()
        materials.update(c["materials"])
        meshes = []
        for f in c["meshes"]:
            entry = {"file": f}
            if m is not None:
                entry["transform"] = [num(float(x)) for row in m for x in row]
            meshes.append(entry)
        # Only the materials some mesh of the case names (unused JSON materials are checked but
        # harmless; keeping them out keeps the files short).
        used = set()
        for f in c["meshes"]:
            used |= USED_MATERIALS[f]
        scene = {"meshes": meshes, "materials": {k: v for k, v in materials.items() if k in used},
                 "cameras": [camera]}
    if lights:
        scene["lights"] = lights
    if c["environment"]:
        scene["environment"] = c["environment"]
    return scene


USED_MATERIALS = {
    "room.obj": {"floor", "ceiling", "backWall", "rightWall", "leftWall"},
    "room_open_top.obj": {"floor", "backWall", "rightWall", "leftWall"},
    "room_closed.obj": {"floor", "ceiling", "backWall", "rightWall", "leftWall", "frontWall"},
    "light.obj": {"light"},
    "short.obj": {"shortBlock"}, "tall.obj": {"tallBlock"},
    "short_closed.obj": {"shortBlock"}, "tall_closed.obj": {"tallBlock"},
    "tall_glass.obj": {"glass"}, "ceiling_panel.obj": {"panel"}, "sheet_back.obj": {"sheet"},
    "glow_panel.obj": {"glow"},
}


def compact_json(value):
    """Indented JSON with every list of numbers on one line."""
    text = json.dumps(value, indent=1)
    return re.sub(r"\[\s*([-0-9.e+,\s]*?)\s*\]", lambda m: "[" + re.sub(r"\s*,\s*", ", ", m.group(1)) + "]", text)


def main(argv):
    listing = bool(argv) and argv[0] == "--list"
    if listing:
        argv = argv[1:]
    elif not argv or argv[0].startswith("-"):
        sys.exit(__doc__)
    outdir, wanted = (None, argv) if listing else (argv[0], argv[1:])
    names = [c["name"] for c in CASES]
    for w in wanted:
        if w not in names:
            sys.exit(f"make_scenes.py: unknown case '{w}' (cases: {' '.join(names)})")
    selected = [c for c in CASES if not wanted or c["name"] in wanted]
    if listing:
        for c in selected:
            print(f"{c['name']}\t{c['varies']}")
        return
    os.makedirs(outdir, exist_ok=True)
    write_geometry(outdir)
    for c in selected:
        with open(os.path.join(outdir, c["name"] + ".json"), "w") as f:
            f.write(compact_json(scene_of(c)) + "\n")


if __name__ == "__main__":
    main(sys.argv[1:])
