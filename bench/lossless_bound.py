#!/usr/bin/env python3
"""How far can a bit-exact codec compress a light field's values? (issue: light-field compression)

Reads a .plf stored raw (`--compress none`) and, for its diffuse charts (one irradiance per
tixel, the whole of the built-in Cornell box), estimates from the data itself:

  * the Monte-Carlo noise of the bake: the median over tixels of |L(i-1) - 2 L(i) + L(i+1)| / L(i)
    / sqrt(6) along rows (a second difference cancels any linear gradient; for independent noise
    of relative standard deviation s its magnitude is about sqrt(6)·s);
  * the cost of the residuals that `lossless` codes — IEEE bits mapped to ordered integers,
    JPEG-LS median prediction, green and blue relative to red — under an ideal coder of
    their magnitude classes: per residual, the entropy of its bit length (measured over all
    residuals of the channel) plus the bits below its leading one, which for noise are
    uniformly random and cannot be compressed by any coder;
  * the ratio that cost implies (32 bits per stored channel / estimated bits).

Lossless coding cannot beat the entropy of the noise the bake leaves in the low bits of every
float: with relative noise s, about log2(s · 2^23 · sqrt(2·pi·e)) bits per channel are random.

Usage: bench/lossless_bound.py FILE.plf   (pure Python, no third-party modules)
"""
import math
import struct
import sys
from collections import Counter


def read_plf(path):
    data = open(path, "rb").read()
    if data[:8] != b"PLF\0\r\n\x1a\n":
        sys.exit(f"{path}: not a .plf file")
    (count,) = struct.unpack_from("<I", data, 12)
    sections = {}
    for k in range(count):
        at = 32 + 48 * k
        name = data[at:at + 4].decode()
        encoding, offset, stored, _decoded = struct.unpack_from("<IQQQ", data, at + 4)
        sections[name] = (encoding, offset, stored)
    encoding, offset, stored = sections["VALS"]
    if encoding != 0:
        sys.exit(f"{path}: values are compressed; bake or compress with --compress/--mode none first")
    values = struct.unpack_from(f"<{stored // 4}f", data, offset)
    raw_bits = struct.unpack_from(f"<{stored // 4}I", data, offset)
    _, offset, _ = sections["CHRT"]
    (chart_count,) = struct.unpack_from("<Q", data, offset)
    charts = []
    for k in range(chart_count):
        at = offset + 8 + 85 * k  # u32 material, u8 kind, 4 × vec3, f32 size, u32 resU, resV, dirRes, u64 firstTixel, firstValue
        res_u, res_v, dir_res = struct.unpack_from("<III", data, at + 5 + 48 + 4)
        (first_value,) = struct.unpack_from("<Q", data, at + 5 + 48 + 16 + 8)
        charts.append((res_u, res_v, dir_res, first_value))
    return values, raw_bits, charts


def ordered(bits):
    return (~bits) & 0xFFFFFFFF if bits & 0x80000000 else bits | 0x80000000


def med(a, b, c):
    lo, hi = min(a, b), max(a, b)
    if c >= hi:
        return lo
    if c <= lo:
        return hi
    return a + b - c


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    values, raw_bits, charts = read_plf(sys.argv[1])
    residuals = [[], [], []]
    noise = []
    for res_u, res_v, dir_res, first in charts:
        if dir_res != 1:
            continue
        def at(i, j, ch):
            return ordered(raw_bits[3 * (first + j * res_u + i) + ch])
        for j in range(res_v):
            for i in range(res_u):
                e = []
                for ch in range(3):
                    if j == 0:
                        p = at(i - 1, 0, ch) if i > 0 else 0
                    elif i == 0:
                        p = at(0, j - 1, ch)
                    else:
                        p = med(at(i - 1, j, ch), at(i, j - 1, ch), at(i - 1, j - 1, ch))
                    e.append(at(i, j, ch) - p)
                residuals[0].append(e[0])
                residuals[1].append(e[1] - e[0])
                residuals[2].append(e[2] - e[0])
                if 0 < i < res_u - 1:
                    lum = [sum(values[3 * (first + j * res_u + x) + ch] for ch in range(3)) for x in (i - 1, i, i + 1)]
                    if lum[1] > 0:
                        noise.append(abs(lum[0] - 2 * lum[1] + lum[2]) / lum[1] / math.sqrt(6))
    n = len(residuals[0])
    if n == 0:
        sys.exit("no diffuse charts")
    total_bits = 0.0
    per_channel = []
    for channel in residuals:
        lengths = [(2 * r if r >= 0 else -2 * r - 1).bit_length() for r in channel]
        counts = Counter(lengths)
        entropy = -sum(c / n * math.log2(c / n) for c in counts.values())
        bits = entropy * n + sum(max(k - 1, 0) for k in lengths)
        per_channel.append(bits / n)
        total_bits += bits
    noise.sort()
    s = noise[len(noise) // 2]
    print(f"diffuse values: {n}")
    print(f"bake noise (relative, median): {100 * s:.2f} %  -> about {math.log2(s * 2**23 * math.sqrt(2 * math.pi * math.e)):.1f} random bits per channel")
    print(f"residual cost, ideal coder (bits per channel): red {per_channel[0]:.2f}, green-red {per_channel[1]:.2f}, blue-red {per_channel[2]:.2f}")
    print(f"best lossless ratio this implies: {96 * n / total_bits:.2f}:1 (2:1 needs 16 bits per channel)")


if __name__ == "__main__":
    main()
