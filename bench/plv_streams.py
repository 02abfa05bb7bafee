#!/usr/bin/env python3
"""How much smaller would a .plv be with its entry blocks split into byte streams?

Reads a sample of the entry blocks of a .plv (format version 5, fractions kept to 4 bits: the
default then; version 6 stores the blocks split into streams, docs/design.md "The .plv's bytes"), decompresses each (the `zstd` command), and compresses it again two ways at zstd
levels 1 (what the bake writes), 3 and 6: whole, as the .plv stores it, and split into separate
streams — the tixels' sizes, their precision bytes, the 2-bit tags, the fraction bytes, the
near and far hits' deltas, and the general form's varints — each compressed on its own. Prints
the bytes of each against the stored frames', and each stream's share (layout: plv_file.h,
"Compact entries"; the figures: docs/design.md, Visibility field).

Usage: bench/plv_streams.py FILE.plv [BLOCKS]   (BLOCKS sampled evenly; default 8)
"""
import os
import struct
import subprocess
import sys

HEADER = struct.Struct("<8sIIQQQQQ")


def zstd(data, level):
    return len(subprocess.run(["zstd", "-q", "-c", f"-{level}"], input=bytes(data), capture_output=True,
                              check=True).stdout)


def sampled_blocks(path, sample):
    """Yields (grid side, tixels in the file, blocks in the file, stored frame bytes, content,
    tixels in the block) for `sample` entry blocks of a version-5 .plv, evenly spaced."""
    size = os.path.getsize(path)
    with open(path, "rb") as f:
        magic, version, grid, _, tixels, _, _, _ = HEADER.unpack(f.read(HEADER.size))
        if magic != b"PLVIS\0\r\n" or version != 5:
            sys.exit(f"{path}: not a version-5 .plv (these scripts study the format before version 6, "
                     "whose blocks are already split into streams: bake the field with a build before it)")
        per_block = struct.unpack("<Q", f.read(8))[0]
        blocks = (tixels + per_block - 1) // per_block
        f.seek(size - 2 * (blocks + 1) * 8)
        frame_sizes = struct.unpack(f"<{blocks + 1}Q", f.read((blocks + 1) * 8))
        offsets = [HEADER.size + 8]
        for s in frame_sizes:
            offsets.append(offsets[-1] + s)
        for b in sorted({i * blocks // sample for i in range(sample)}):
            f.seek(offsets[b])
            frame = f.read(frame_sizes[b])
            raw = subprocess.run(["zstd", "-d", "-q", "-c"], input=frame, capture_output=True, check=True).stdout
            yield grid, tixels, blocks, frame_sizes[b], raw, min(tixels, (b + 1) * per_block) - b * per_block


def tixel_encodings(raw, count):
    """Each of a block's `count` tixels' encodings, from its content (sizes first); exits on one
    whose fractions are not 4 bits (what these scripts read)."""
    sizes = struct.unpack(f"<{count}I", raw[:4 * count])
    at = 4 * count
    for size in sizes:
        enc = raw[at:at + size]
        at += size
        if enc[0] != 4:
            sys.exit(f"a tixel has {enc[0]} bits per fraction (this script reads 4)")
        yield enc


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    path = sys.argv[1]
    sample = int(sys.argv[2]) if len(sys.argv) > 2 else 8
    totals = {}

    def add(key, value):
        totals[key] = totals.get(key, 0) + value

    for grid, tixels, blocks, stored, raw, count in sampled_blocks(path, sample):
        n = grid * grid
        streams = {k: bytearray() for k in ("sizes", "bits", "tags", "fractions", "deltas", "general")}
        streams["sizes"] += raw[:4 * count]
        for enc in tixel_encodings(raw, count):
            streams["bits"].append(enc[0])
            tags = enc[1:1 + (n + 3) // 4]
            streams["tags"] += tags
            p = 1 + len(tags)
            for k in range(n):
                tag = (tags[k // 4] >> (2 * (k % 4))) & 3
                if tag == 1 or tag == 2:  # near, far: the fraction byte, then 1 or 2 bytes of delta
                    streams["fractions"].append(enc[p])
                    streams["deltas"] += enc[p + 1:p + 1 + tag]
                    p += 1 + tag
                elif tag == 3:  # general: a varint, then the fraction byte
                    q = p
                    while enc[p] & 0x80:
                        p += 1
                    p += 1
                    streams["general"] += enc[q:p]
                    streams["fractions"].append(enc[p])
                    p += 1
        add("stored frames", stored)
        for level in (1, 3, 6):
            add(f"whole, zstd -{level}", zstd(raw, level))
            add(f"split, zstd -{level}", sum(zstd(s, level) for s in streams.values()))
        for name, s in streams.items():
            add(f"  stream {name}, zstd -3", zstd(s, 3))
    stored = totals["stored frames"]
    n = grid * grid
    print(f"{path}: {tixels} tixels x {n} directions, {sample} of {blocks} blocks sampled")
    for key, value in totals.items():
        print(f"{key:32s} {value:12d} bytes  {value / stored:.3f}")


if __name__ == "__main__":
    main()
