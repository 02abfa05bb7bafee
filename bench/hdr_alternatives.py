#!/usr/bin/env python3
"""Why `hdr` uses logarithmic codes: the alternative shared-exponent RGB9E5 measured on a
light field's values.

Reads the raw float32 values of an uncompressed .plf (VALS, encoding 0), packs them as
RGB9E5 (EXT_texture_shared_exponent: 9-bit mantissas, one 5-bit exponent per value), and
reports the size after zstd (level 9, like the codecs; both as packed 32-bit words and
split into byte planes) with the value errors, using the same error measures as
`plenoptic compress` (relative RMSE with a floor of 1 % of the mean; max relative error
with a floor of 0.1 % of the mean). Standard library + the `zstd` command.
Usage: hdr_alternatives.py FILE.plf
"""
import math
import struct
import subprocess
import sys


def read_values(path):
    data = open(path, "rb").read()
    sections = struct.unpack_from("<I", data, 12)[0]
    for i in range(sections):
        entry = 32 + 48 * i
        if data[entry:entry + 4] == b"VALS":
            encoding, offset, stored, _decoded = struct.unpack_from("<IQQQ", data, entry + 4)
            if encoding != 0:
                sys.exit(f"{path}: values are compressed (encoding {encoding}); use an uncompressed file")
            return struct.unpack_from(f"<{stored // 4}f", data, offset)
    sys.exit(f"{path}: no VALS section")


def zstd_size(payload):
    out = subprocess.run(["zstd", "-9", "-c", "-q"], input=payload, capture_output=True, check=True).stdout
    return len(out)


def rgb9e5(r, g, b):
    """Encode/decode one value (EXT_texture_shared_exponent, bias 15, 9 mantissa bits)."""
    N, B, EMAX = 9, 15, 31
    maxv = (2 ** N - 1) / 2 ** N * 2 ** (EMAX - B)
    rc, gc, bc = (min(max(x, 0.0), maxv) for x in (r, g, b))
    m = max(rc, gc, bc)
    e = max(-B - 1, math.floor(math.log2(m)) if m > 0 else -B - 1) + 1 + B
    denom = 2.0 ** (e - B - N)
    if math.floor(m / denom + 0.5) == 2 ** N:
        e += 1
        denom *= 2
    q = [int(math.floor(x / denom + 0.5)) for x in (rc, gc, bc)]
    word = q[0] | (q[1] << 9) | (q[2] << 18) | (e << 27)
    return word, [x * denom for x in q]


def main():
    if len(sys.argv) != 2:
        sys.exit("usage: hdr_alternatives.py FILE.plf")
    v = read_values(sys.argv[1])
    n = len(v) // 3
    raw = 12 * n
    mean = sum(v) / len(v)
    floor2, floor1 = (1e-2 * mean) ** 2, 1e-3 * mean
    words, rel2, worst = [], 0.0, 0.0
    for i in range(n):
        w, d = rgb9e5(v[3 * i], v[3 * i + 1], v[3 * i + 2])
        words.append(w)
        for c in range(3):
            o = v[3 * i + c]
            rel2 += (d[c] - o) ** 2 / (o * o + floor2)
            worst = max(worst, abs(d[c] - o) / max(abs(o), floor1))
    packed = struct.pack(f"<{n}I", *words)
    planes = b"".join(bytes(packed[p::4]) for p in range(4))
    print(f"{sys.argv[1]}: {n} values, {raw} bytes raw")
    print(f"rgb9e5 + zstd            {zstd_size(packed):>9} bytes  {raw / zstd_size(packed):6.2f}:1")
    print(f"rgb9e5 byte planes + zstd {zstd_size(planes):>8} bytes  {raw / zstd_size(planes):6.2f}:1")
    print(f"rgb9e5 error: relative RMSE {math.sqrt(rel2 / (3 * n)):.4g}, max relative {worst:.4g}")


if __name__ == "__main__":
    main()
