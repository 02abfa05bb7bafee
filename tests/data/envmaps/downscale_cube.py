#!/usr/bin/env python3
"""Makes tests/data/envmaps/pisa-cube/ from the Pisa cube faces as distributed with the three.js
examples (six 256 x 256 Radiance .hdr faces, 1.3 MB): each face is box-filtered 4 x 4 -> 64 x 64
in its own pixel grid (no resampling across faces, no change of orientation: face px stays px,
row 0 stays the top row) and written as flat (uncompressed) 32-bit RGBE. Pure Python, no
dependencies, so that the result does not depend on plenoptic's own reader, writer or face
orientation table (which the tests check against these files).

    python3 tests/data/envmaps/downscale_cube.py SOURCE_DIR tests/data/envmaps/pisa-cube

SOURCE_DIR: the directory holding the six 256 x 256 {px,nx,py,ny,pz,nz}.hdr faces (three.js:
examples/textures/cube/pisaHDR/). Only this maintenance script needs them; the tests read the
committed 64 x 64 result.
"""
import math
import os
import sys

FACTOR = 4
FACES = ["px", "nx", "py", "ny", "pz", "nz"]


def read_hdr(path):
    """Returns (width, height, rows) with rows[y][x] = (r, g, b) floats; row 0 is the top."""
    data = open(path, "rb").read()
    pos = 0
    lines = []
    while True:  # header lines up to the empty line, then the resolution line
        end = data.index(b"\n", pos)
        line = data[pos:end].decode("ascii", "replace")
        pos = end + 1
        if line == "":
            break
        lines.append(line)
    if not lines[0].startswith("#?"):
        sys.exit(f"{path}: not a Radiance file")
    if "FORMAT=32-bit_rle_rgbe" not in lines:
        sys.exit(f"{path}: expected FORMAT=32-bit_rle_rgbe")
    end = data.index(b"\n", pos)
    resolution = data[pos:end].decode("ascii").split()
    pos = end + 1
    if resolution[0] != "-Y" or resolution[2] != "+X":
        sys.exit(f"{path}: only '-Y H +X W' is handled (got {' '.join(resolution)})")
    height, width = int(resolution[1]), int(resolution[3])
    rows = []
    for _ in range(height):
        if data[pos] == 2 and data[pos + 1] == 2 and (data[pos + 2] << 8 | data[pos + 3]) == width:
            pos += 4  # new-style run-length encoding: the four channels one after the other
            channels = []
            for _c in range(4):
                values = []
                while len(values) < width:
                    count = data[pos]
                    pos += 1
                    if count > 128:
                        values.extend([data[pos]] * (count - 128))
                        pos += 1
                    else:
                        values.extend(data[pos:pos + count])
                        pos += count
                channels.append(values)
            rgbe = list(zip(*channels))
        else:  # flat
            rgbe = [tuple(data[pos + 4 * x:pos + 4 * x + 4]) for x in range(width)]
            pos += 4 * width
        rows.append([decode(p) for p in rgbe])
    return width, height, rows


def decode(p):
    r, g, b, e = p
    if e == 0:
        return (0.0, 0.0, 0.0)
    scale = math.ldexp(1.0, e - 136)  # (mantissa + 0.5) / 256 * 2^(e - 128)
    return ((r + 0.5) * scale, (g + 0.5) * scale, (b + 0.5) * scale)


def encode(rgb):
    m = max(rgb)
    if m < 1e-32:
        return bytes((0, 0, 0, 0))
    mantissa, exponent = math.frexp(m)  # m = mantissa * 2^exponent, mantissa in [0.5, 1)
    scale = mantissa * 256.0 / m
    return bytes([min(255, int(c * scale)) for c in rgb] + [exponent + 128])


def write_hdr(path, width, height, rows):
    with open(path, "wb") as f:
        f.write(b"#?RADIANCE\n# Pisa cube face, box-filtered 4x4 by downscale_cube.py\n")
        f.write(b"FORMAT=32-bit_rle_rgbe\n\n")
        f.write(f"-Y {height} +X {width}\n".encode("ascii"))
        for row in rows:
            f.write(b"".join(encode(p) for p in row))


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    source, target = sys.argv[1], sys.argv[2]
    os.makedirs(target, exist_ok=True)
    for face in FACES:
        width, height, rows = read_hdr(os.path.join(source, face + ".hdr"))
        if width % FACTOR or height % FACTOR:
            sys.exit(f"{face}: {width}x{height} is not a multiple of {FACTOR}")
        small = []
        for y in range(height // FACTOR):
            out = []
            for x in range(width // FACTOR):
                total = [0.0, 0.0, 0.0]
                for dy in range(FACTOR):
                    for dx in range(FACTOR):
                        p = rows[FACTOR * y + dy][FACTOR * x + dx]
                        for c in range(3):
                            total[c] += p[c]
                out.append(tuple(t / (FACTOR * FACTOR) for t in total))
            small.append(out)
        write_hdr(os.path.join(target, face + ".hdr"), width // FACTOR, height // FACTOR, small)
        print(f"{face}: {width}x{height} -> {width // FACTOR}x{height // FACTOR}")


if __name__ == "__main__":
    main()
