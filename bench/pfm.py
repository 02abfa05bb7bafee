"""Colour PFM reading for the bench scripts (pure Python, no third-party modules)."""
import struct
import sys


def read_pfm(path):
    """Colour PFM ('PF'): header lines, then float32 rows bottom to top. Returns the flat
    tuple of r, g, b values (row order as stored; irrelevant for image-wide sums)."""
    return read_pfm_sized(path)[2]


def read_pfm_sized(path):
    """read_pfm's (width, height, values): the rows bottom to top, as stored."""
    with open(path, "rb") as f:
        data = f.read()
    parts, pos = [], 0
    while len(parts) < 4:  # "PF", width, height, scale (whitespace-separated)
        while data[pos:pos + 1].isspace():
            pos += 1
        start = pos
        while not data[pos:pos + 1].isspace():
            pos += 1
        parts.append(data[start:pos].decode())
    pos += 1  # the single whitespace byte after the scale
    if parts[0] != "PF":
        sys.exit(f"{path}: not a colour PFM")
    w, h, scale = int(parts[1]), int(parts[2]), float(parts[3])
    fmt = ("<" if scale < 0 else ">") + "f" * (3 * w * h)
    if len(data) - pos < 12 * w * h:
        sys.exit(f"{path}: truncated ({len(data) - pos} bytes of pixels, {12 * w * h} expected)")
    return w, h, struct.unpack(fmt, data[pos:pos + 12 * w * h])
