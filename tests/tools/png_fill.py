#!/usr/bin/env python3
"""png_fill.py FILE.png X0 Y0 X1 Y1 [colour] — print the width, height and the
share of non-white pixels in the rectangle [X0,X1) × [Y0,Y1) of an 8-bit
RGB/RGBA PNG, decoded here with zlib alone (no imaging library needed).
With "colour", only coloured pixels count (channels differing by more than
60: a plot's curves, not its grey grid or black text), and a fourth figure
is the share of the rectangle's columns that hold any (how far the curves
reach across a plot, which a legend alone does not)."""
import struct, sys, zlib


def decode(path):
    data = open(path, "rb").read()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", "not a PNG"
    pos, idat, w = 8, b"", 0
    while pos < len(data):
        n, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + n]
        if kind == b"IHDR":
            w, h, depth, ctype = struct.unpack(">IIBB", body[:10])
            assert depth == 8 and ctype in (2, 6), (depth, ctype)
            bpp = 3 if ctype == 2 else 4
        elif kind == b"IDAT":
            idat += body
        pos += 12 + n
    raw, stride = zlib.decompress(idat), w * bpp
    rows, prev = [], bytearray(stride)
    for y in range(h):
        f, line = raw[y * (stride + 1)], bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - bpp] if i >= bpp else 0
            b, c = prev[i], prev[i - bpp] if i >= bpp else 0
            if f == 1: line[i] = (line[i] + a) & 255
            elif f == 2: line[i] = (line[i] + b) & 255
            elif f == 3: line[i] = (line[i] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append(line)
        prev = line
    return w, h, bpp, rows


w, h, bpp, rows = decode(sys.argv[1])
x0, y0, x1, y1 = (int(v) for v in sys.argv[2:6])
colour = sys.argv[6:7] == ["colour"]
filled = total = 0
columns = set()
for y in range(y0, y1):
    r = rows[y]
    for x in range(x0, x1):
        total += 1
        px = r[x * bpp:x * bpp + 3]
        ink = max(px) - min(px) > 60 if colour else sum(px) < 3 * 245
        filled += ink
        if ink:
            columns.add(x)
print(w, h, f"{filled / total:.4f}" + (f" {len(columns) / (x1 - x0):.4f}" if colour else ""))
