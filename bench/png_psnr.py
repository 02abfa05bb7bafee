#!/usr/bin/env python3
"""PSNR (dB) of 8-bit PNG A against PNG B over all RGB samples, peak 255.

Standard library only (zlib): decodes 8-bit greyscale, RGB and RGBA PNGs (non-interlaced),
which is what `plenoptic render -o X.png` writes. Usage: png_psnr.py A.png B.png
"""
import math
import struct
import sys
import zlib


def read_png(path):
    with open(path, "rb") as f:
        data = f.read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        sys.exit(f"{path}: not a PNG file")
    pos, idat, width = 8, b"", None
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            width, height, depth, colour, _, _, interlace = struct.unpack(">IIBBBBB", body)
            if depth != 8 or interlace != 0 or colour not in (0, 2, 6):
                sys.exit(f"{path}: only 8-bit non-interlaced grey/RGB/RGBA PNGs are supported")
            channels = {0: 1, 2: 3, 6: 4}[colour]
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    raw = zlib.decompress(idat)
    stride = width * channels
    rows, previous = [], bytearray(stride)
    for y in range(height):
        filter_type = raw[y * (stride + 1)]
        line = bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - channels] if i >= channels else 0
            b = previous[i]
            c = previous[i - channels] if i >= channels else 0
            if filter_type == 1:
                line[i] = (line[i] + a) & 255
            elif filter_type == 2:
                line[i] = (line[i] + b) & 255
            elif filter_type == 3:
                line[i] = (line[i] + (a + b) // 2) & 255
            elif filter_type == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else (b if pb <= pc else c))) & 255
        rows.append(line)
        previous = line
    rgb = []
    for line in rows:
        for x in range(width):
            px = line[x * channels:(x + 1) * channels]
            rgb.extend(px[:3] if channels >= 3 else px * 3)
    return width, height, rgb


def main():
    if len(sys.argv) != 3:
        sys.exit("usage: png_psnr.py A.png B.png")
    wa, ha, a = read_png(sys.argv[1])
    wb, hb, b = read_png(sys.argv[2])
    if (wa, ha) != (wb, hb):
        sys.exit(f"size mismatch: {wa}x{ha} against {wb}x{hb}")
    mse = sum((x - y) ** 2 for x, y in zip(a, b)) / len(a)
    print("inf" if mse == 0 else f"{10 * math.log10(255 * 255 / mse):.2f}")


if __name__ == "__main__":
    main()
