#!/usr/bin/env python3
"""Which model of a gather direction's hit makes a .plv's entry blocks smallest?

Reads a sample of the entry blocks of a version-5 .plv (as bench/plv_streams.py does) (fractions at 4 bits: the default; the
layout is plv_file.h's "Compact entries") and estimates the bytes per entry of a few predictors
of each hit's tixel index, the residual streams kept apart and each compressed with zstd at
level 1 (what the bake writes):

  stored      the frames as the file holds them (version 5)
  previous    the tixel's previous hit (version 5's deltas), streams split
  2-D         left + up − upper-left in the tixel's m × m grid of gather cells, streams split
  choice:K    the nearest of K candidates, the choice written beside the residual: the
              previous hit, the cells above, above-left and above-right (K = 4), and the same
              cell of the block's previous tixel (5), and of the one before (6), and the
              previous tixel's cells left and right of it (8: the best measured; docs/design.md, Visibility field)

Each hit costs an op byte (the choice and the residual's width: 1, 2 or 4 bytes), the residual
(zigzag, its bytes in separate streams, the 1-byte residuals apart from the wider ones' low
bytes), and the fraction byte (qu | qv << 4). The fractions
stay as they are: predicted from the neighbouring cells they are as random as stored (see
docs/design.md, Visibility field). Needs python3-zstandard and NumPy.

Usage: /usr/bin/python3 bench/plv_model.py FILE.plv [BLOCKS]   (BLOCKS sampled evenly; default 8)
"""
import sys

import numpy as np
import zstandard

from plv_streams import sampled_blocks, tixel_encodings  # the version-5 block reader, beside this script

ESCAPE = 0x3fffffff
NONE = -(1 << 40)


def zsize(data):
    return len(zstandard.ZstdCompressor(level=1).compress(bytes(data)))


def decode_block(raw, count, n):
    """Index (NONE: nothing hit), flags and both 4-bit fraction levels of every entry."""
    idx = np.full((count, n), NONE, np.int64)
    flags, qu, qv = (np.zeros((count, n), np.int64) for _ in range(3))
    for t, enc in enumerate(tixel_encodings(raw, count)):
        tags = enc[1:1 + (n + 3) // 4]
        p, prev = 1 + len(tags), 0
        for k in range(n):
            tag = (tags[k // 4] >> (2 * (k % 4))) & 3
            if tag == 0:
                continue
            if tag in (1, 2):
                v = int.from_bytes(enc[p:p + 1 + tag], "little", signed=True)
                p += 1 + tag
                q, d, f = v & 0xff, v >> 8, 0
            else:
                v = s = 0
                while True:
                    b = enc[p]
                    p += 1
                    v |= (b & 0x7f) << s
                    s += 7
                    if not b & 0x80:
                        break
                f, z = v & 3, v >> 2
                d = (z >> 1) ^ -(z & 1)
                q = enc[p]
                p += 1
            i = prev + d
            if i != ESCAPE:
                prev = i
                idx[t, k] = i
            flags[t, k], qu[t, k], qv[t, k] = f, q & 15, q >> 4
    return idx, flags, qu, qv


def shifted(a, m, dr, dc):
    """a (tixels × m × m) moved down dr rows and right dc columns, NONE where nothing comes in."""
    out = np.full_like(a, NONE)
    if dc >= 0:
        out[:, dr:, dc:] = a[:, :m - dr, :m - dc]
    else:
        out[:, dr:, :m + dc] = a[:, :m - dr, -dc:]
    return out


def model_bytes(idx, flags, qu, qv, m, model):
    t_count, n = idx.shape
    hit = idx != NONE
    previous = np.zeros((t_count, n), np.int64)
    last = np.zeros(t_count, np.int64)
    for k in range(n):
        previous[:, k] = last
        last = np.where(hit[:, k], idx[:, k], last)
    grid, prev = idx.reshape(t_count, m, m), previous.reshape(t_count, m, m)
    up, left, upleft, upright = (shifted(grid, m, *s) for s in ((1, 0), (0, 1), (1, 1), (1, -1)))
    before = [np.full_like(grid, NONE) for _ in range(2)]
    before[0][1:], before[1][2:] = grid[:-1], grid[:-2]
    if model == "previous":
        cands = [prev]
    elif model == "2-D":
        cands = [np.where((left != NONE) & (up != NONE) & (upleft != NONE), left + up - upleft,
                          np.where(left != NONE, left, np.where(up != NONE, up, prev)))]
    else:
        k = int(model.split(":")[1])
        cands = [prev, up, upright, upleft, before[0], before[1], shifted(before[0], m, 0, 1),
                 shifted(before[0], m, 0, -1)][:k]
    c = np.stack([np.where(x != NONE, x, prev) for x in cands])
    d_all = grid[None] - c
    choice = np.argmin(np.abs(d_all), axis=0)
    d = np.take_along_axis(d_all, choice[None], 0)[0].reshape(t_count, n)
    z = np.where(d >= 0, 2 * d, -2 * d - 1)
    plain = hit & (flags == 0)
    width = np.where(z < 256, 0, np.where(z < 65536, 1, 2))
    ops = np.where(plain, 1 + choice.reshape(t_count, n) * 3 + width, np.where(hit | (flags != 0), 255, 0))
    zp, wp = z[plain], width[plain]
    # The 1-byte residuals apart from the low bytes of the wider ones (these are near uniform).
    streams = [ops.astype(np.uint8), zp[wp == 0].astype(np.uint8), zp[wp > 0].astype(np.uint8),
               (zp >> 8)[wp >= 1].astype(np.uint8),
               (zp >> 16)[wp == 2].astype(np.uint8), (zp >> 24)[wp == 2].astype(np.uint8),
               ((idx & 0xffffffff) | flags << 30)[ops == 255].astype("<u4"),
               (qu | qv << 4)[ops != 0].astype(np.uint8)]
    return sum(zsize(s.tobytes()) for s in streams)


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    path = sys.argv[1]
    sample = int(sys.argv[2]) if len(sys.argv) > 2 else 8
    models = ("previous", "2-D", "choice:4", "choice:5", "choice:6", "choice:8")
    totals = dict.fromkeys(("stored",) + models, 0)
    entries = 0
    for grid, tixels, blocks, stored, raw, count in sampled_blocks(path, sample):
        entries += count * grid * grid
        totals["stored"] += stored
        decoded = decode_block(raw, count, grid * grid)
        for model in models:
            totals[model] += model_bytes(*decoded, grid, model)
    print(f"{path}: {tixels} tixels x {grid * grid} directions, {sample} of {blocks} blocks sampled ({entries} entries)")
    for key, value in totals.items():
        print(f"{key:10s} {value / entries:6.3f} bytes per entry  {value / totals['stored']:.3f}")


if __name__ == "__main__":
    main()
