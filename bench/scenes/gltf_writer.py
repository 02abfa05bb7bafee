"""A minimal glTF 2.0 writer for the bench scenes (standard library only): 8-bit PNG images, one
binary buffer of accessors, quads and UV spheres, everything embedded as data: URIs so that
the written .gltf is one self-contained file.

Used by make_gltf_materials.py and make_gltf_check.py.
"""
import base64
import math
import struct
import zlib

FLOAT, UNSIGNED_SHORT = 5126, 5123
REPEAT, CLAMP_TO_EDGE, MIRRORED_REPEAT = 10497, 33071, 33648


def png(width, height, rgb):
    """An 8-bit RGB PNG of rows top to bottom; rgb is a flat list of width·height·3 bytes."""
    raw = b"".join(b"\0" + bytes(rgb[y * width * 3:(y + 1) * width * 3]) for y in range(height))

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xffffffff)

    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0))
            + chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b""))


def data_uri(mime, data):
    return "data:%s;base64,%s" % (mime, base64.b64encode(data).decode())


class Buffer:
    """One glTF buffer and the buffer views and accessors into it."""

    def __init__(self):
        self.data = bytearray()
        self.views = []
        self.accessors = []

    def add(self, values, fmt, ctype, count, kind, minmax=False):
        """Appends values (tuples packed with struct format fmt, or scalars) 4-byte aligned and
        returns the new accessor's index; minmax adds the VEC3 min/max POSITION needs."""
        while len(self.data) % 4:
            self.data.append(0)
        offset = len(self.data)
        for v in values:
            self.data.extend(struct.pack("<" + fmt, *v) if isinstance(v, tuple) else struct.pack("<" + fmt, v))
        self.views.append({"buffer": 0, "byteOffset": offset, "byteLength": len(self.data) - offset})
        accessor = {"bufferView": len(self.views) - 1, "componentType": ctype, "count": count, "type": kind}
        if minmax:
            accessor["min"] = [min(v[i] for v in values) for i in range(3)]
            accessor["max"] = [max(v[i] for v in values) for i in range(3)]
        self.accessors.append(accessor)
        return len(self.accessors) - 1

    def primitive(self, positions, normals, uvs, indices, uv1s=None, colors=None):
        """The attributes and indices accessors of one indexed triangle primitive."""
        attributes = {"POSITION": self.add(positions, "3f", FLOAT, len(positions), "VEC3", minmax=True),
                      "NORMAL": self.add(normals, "3f", FLOAT, len(normals), "VEC3"),
                      "TEXCOORD_0": self.add(uvs, "2f", FLOAT, len(uvs), "VEC2")}
        if uv1s:
            attributes["TEXCOORD_1"] = self.add(uv1s, "2f", FLOAT, len(uv1s), "VEC2")
        if colors:
            attributes["COLOR_0"] = self.add(colors, "3f", FLOAT, len(colors), "VEC3")
        return attributes, self.add(indices, "H", UNSIGNED_SHORT, len(indices), "SCALAR")

    def quad(self, corners, normal, uv1=None, colors=None, n=1):
        """A quad split into n × n cells (so that vertex colours can vary), corners counter-clockwise
        seen from the front: p0 + s (p1 − p0) + t (p3 − p0), uv = (s, 1 − t); uv1 and colors map a
        position to its TEXCOORD_1 and COLOR_0."""
        p0, p1, _, p3 = corners
        pos, uvs, idx = [], [], []
        for j in range(n + 1):
            for i in range(n + 1):
                s, t = i / n, j / n
                pos.append(tuple(p0[k] + s * (p1[k] - p0[k]) + t * (p3[k] - p0[k]) for k in range(3)))
                uvs.append((s, 1 - t))
        for j in range(n):
            for i in range(n):
                a = j * (n + 1) + i
                idx += [a, a + 1, a + n + 2, a, a + n + 2, a + n + 1]
        return self.primitive(pos, [normal] * len(pos), uvs, idx, uv1s=[uv1(p) for p in pos] if uv1 else None,
                              colors=[colors(p) for p in pos] if colors else None)

    def sphere(self, centre, radius, segments=48, rings=24):
        """A UV sphere: u = longitude / 2π (from +x towards −z), v = polar angle / π from the top
        (+y); the seam's vertices are repeated so that u runs 0 → 1 without wrapping."""
        pos, nrm, uvs, idx = [], [], [], []
        for j in range(rings + 1):
            theta = math.pi * j / rings
            for i in range(segments + 1):
                phi = 2 * math.pi * i / segments
                n = (math.sin(theta) * math.cos(phi), math.cos(theta), -math.sin(theta) * math.sin(phi))
                pos.append(tuple(centre[k] + radius * n[k] for k in range(3)))
                nrm.append(n)
                uvs.append((i / segments, j / rings))
        for j in range(rings):
            for i in range(segments):
                a, b = j * (segments + 1) + i, (j + 1) * (segments + 1) + i
                if j > 0:
                    idx += [a, b, a + 1]
                if j < rings - 1:
                    idx += [a + 1, b, b + 1]
        return self.primitive(pos, nrm, uvs, idx)

    def gltf_buffer(self):
        return {"byteLength": len(self.data), "uri": data_uri("application/octet-stream", bytes(self.data))}
