#!/usr/bin/env python3
"""Which model of a gather direction's hit makes a .plv's entry blocks smallest?

Reads a sample of the entry blocks of a version-5 .plv (as bench/plv_streams.py does; fractions
at 4 bits, the default of the builds that wrote version 5; the layout is plv_file.h's "Compact
entries") and estimates the bytes per entry of a few predictors
of each hit's tixel index, the residual streams kept apart and each compressed with zstd at
level 1 (what the bake writes):

  stored      the frames as the file holds them (version 5)
  tixel-major the same format written again at the fraction precision BITS
  cell-major  the same format with the block's entries taken cell by cell across its tixels
  cell-split  cell-major with the tags, deltas and fractions as sections of one frame
  previous    the tixel's previous hit (version 5's deltas), streams split (the layout of
              version 6, which plenoptic writes now)
  2-D         left + up − upper-left in the tixel's m × m grid of gather cells, streams split
  same-cell   the same cell of the block's previous tixel (the tixel's previous hit where
              that saw nothing): one fixed predictor, as a block stored cell by cell would use
  choice:K    the nearest of K candidates, the choice written beside the residual: the
              previous hit, the cells above, above-left and above-right (K = 4), and the same
              cell of the block's previous tixel (5), and of the one before (6), and the
              previous tixel's cells left and right of it (8: the best measured; docs/design.md, Visibility field)

Each hit costs an op byte (the choice and the residual's width: 1, 2 or 4 bytes), the residual
(zigzag, its bytes in separate streams, the 1-byte residuals apart from the wider ones' low
bytes), and the fraction byte (qu | qv << BITS). The fractions
stay as they are: predicted from the neighbouring cells they are as random as stored (see
docs/design.md, Visibility field). Needs python3-zstandard and NumPy.

With BITS (1–4), the fraction levels are re-quantised from the stored 4 bits to BITS
(round(q·(2^BITS − 1)/15), what a bake at that precision would keep) before they are stored.

Usage: /usr/bin/python3 bench/plv_model.py FILE.plv [BLOCKS] [BITS]   (BLOCKS sampled evenly;
default 8; BITS default 4)
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


def model_bytes(idx, flags, qu, qv, m, model, bits):
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
    elif model == "same-cell":
        cands = [before[0]]
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
               (qu | qv << bits)[ops != 0].astype(np.uint8)]
    return sum(zsize(s.tobytes()) for s in streams)


def split_form_bytes(idx, flags, qu, qv, bits):
    """The block in cell order (as stored_form_bytes "cell") with its sections apart in one
    zstd frame: the tags, then the hits' deltas (1 or 2 bytes, the general form's varint),
    then every entry's fraction levels (qu | qv << bits: a byte while bits ≤ 4)."""
    idx, flags, qu, qv = (a.T.reshape(-1) for a in (idx, flags, qu, qv))
    n = idx.size
    tags, deltas, fractions, prev = bytearray((n + 3) // 4), bytearray(), bytearray(), 0
    for k, (i, f, u, v) in enumerate(zip(idx.tolist(), flags.tolist(), qu.tolist(), qv.tolist())):
        if i == NONE and f == 0:
            continue
        target = ESCAPE if i == NONE else i
        d = target - prev
        if i != NONE and f == 0 and -128 <= d < 128:
            tag = 1
            deltas += (d & 0xff).to_bytes(1, "little")
        elif i != NONE and f == 0 and -32768 <= d < 32768:
            tag = 2
            deltas += (d & 0xffff).to_bytes(2, "little")
        else:
            tag = 3
            z = ((2 * d if d >= 0 else -2 * d - 1) << 2) | f
            while True:
                deltas.append((z & 0x7f) | (0x80 if z > 0x7f else 0))
                z >>= 7
                if not deltas[-1] & 0x80:
                    break
        fractions.append(u | v << bits)
        tags[k // 4] |= tag << (2 * (k % 4))
        if i != NONE:
            prev = i
    return zsize(tags + deltas + fractions)


def stored_form_bytes(idx, flags, qu, qv, bits, order):
    """The block as the stored format would hold it (one zstd frame of the compact encoding,
    bits per fraction as given) with its entries taken in `order`: "tixel" (as stored: each
    tixel's N entries, the delta from the tixel's previous hit) or "cell" (each gather cell's
    entries of the block's tixels one after another, as one sequence: the delta from the
    previous tixel's hit in that cell, or the last hit before)."""
    if order == "cell":
        idx, flags, qu, qv = (a.T.reshape(1, -1) for a in (idx, flags, qu, qv))
    near = (2 * bits + 4 + 7) // 8
    out = bytearray()
    for t in range(idx.shape[0]):
        n = idx.shape[1]
        tags, payload, prev = bytearray((n + 3) // 4), bytearray(), 0
        for k, (i, f, u, v) in enumerate(zip(idx[t].tolist(), flags[t].tolist(), qu[t].tolist(), qv[t].tolist())):
            q = u | v << bits
            if i == NONE and f == 0:
                continue
            target = ESCAPE if i == NONE else i
            d = target - prev
            tag = 3
            if i != NONE and f == 0:
                for tag, length in ((1, near), (2, near + 1)):
                    width = 8 * length - 2 * bits
                    if -(1 << (width - 1)) <= d < (1 << (width - 1)):
                        payload += ((d << 2 * bits | q) & ((1 << 8 * length) - 1)).to_bytes(length, "little")
                        break
                else:
                    tag = 3
            if tag == 3:
                z = ((2 * d if d >= 0 else -2 * d - 1) << 2) | f
                while True:
                    payload.append((z & 0x7f) | (0x80 if z > 0x7f else 0))
                    z >>= 7
                    if not payload[-1] & 0x80:
                        break
                payload += q.to_bytes((2 * bits + 7) // 8, "little")
            tags[k // 4] |= tag << (2 * (k % 4))
            if i != NONE:
                prev = i
        out += bytes([bits]) + tags + payload
    return zsize(out)


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    path = sys.argv[1]
    sample = int(sys.argv[2]) if len(sys.argv) > 2 else 8
    bits = int(sys.argv[3]) if len(sys.argv) > 3 else 4
    if not 1 <= bits <= 4:
        sys.exit(f"{sys.argv[0]}: BITS must be 1 to 4 (the stored fractions have 4), not {bits}")
    models = ("previous", "2-D", "same-cell", "choice:4", "choice:5", "choice:6", "choice:8")
    totals = dict.fromkeys(("stored",) + models + ("tixel-major", "cell-major", "cell-split"), 0)
    entries = 0
    for grid, tixels, blocks, stored, raw, count in sampled_blocks(path, sample):
        entries += count * grid * grid
        totals["stored"] += stored
        idx, flags, qu, qv = decode_block(raw, count, grid * grid)
        qu, qv = ((2 * q * ((1 << bits) - 1) + 15) // 30 for q in (qu, qv))  # round(q·(2^bits − 1)/15)
        for model in models:
            totals[model] += model_bytes(idx, flags, qu, qv, grid, model, bits)
        for order in ("tixel", "cell"):
            totals[f"{order}-major"] += stored_form_bytes(idx, flags, qu, qv, bits, order)
        totals["cell-split"] += split_form_bytes(idx, flags, qu, qv, bits)
    print(f"{path}: {tixels} tixels x {grid * grid} directions, {sample} of {blocks} blocks sampled ({entries} entries), "
          f"fractions at {bits} bits for the models")
    for key, value in totals.items():
        print(f"{key:10s} {value / entries:6.3f} bytes per entry  {value / totals['stored']:.3f}")


if __name__ == "__main__":
    main()
