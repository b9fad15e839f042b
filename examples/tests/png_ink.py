#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Counts the inked pixels of a PNG screenshot (8-bit RGB or RGBA, not interlaced, as
Chromium writes them): pixels that are not near-white, and how many distinct colours they
have. Exit 0 when there are at least MIN_PIXELS of them in at least MIN_COLOURS colours.
Usage: png_ink.py SHOT.png MIN_PIXELS MIN_COLOURS"""
import struct
import sys
import zlib


def pixels(path):
    data = open(path, "rb").read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        raise SystemExit(f"{path}: not a PNG file")
    pos, idat, width, height, channels = 8, b"", 0, 0, 0
    while pos < len(data):
        (length,) = struct.unpack(">I", data[pos:pos + 4])
        kind, body = data[pos + 4:pos + 8], data[pos + 8:pos + 8 + length]
        pos += 12 + length
        if kind == b"IHDR":
            width, height, depth, colour, _, _, interlace = struct.unpack(">IIBBBBB", body)
            if depth != 8 or colour not in (2, 6) or interlace:
                raise SystemExit(f"{path}: only 8-bit RGB/RGBA, non-interlaced PNG is read")
            channels = 3 if colour == 2 else 4
        elif kind == b"IDAT":
            idat += body
    raw = zlib.decompress(idat)
    stride = width * channels
    prev = bytearray(stride)
    for y in range(height):
        filt = raw[y * (stride + 1)]
        line = bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - channels] if i >= channels else 0
            b = prev[i]
            c = prev[i - channels] if i >= channels else 0
            if filt == 1:
                line[i] = (line[i] + a) & 255
            elif filt == 2:
                line[i] = (line[i] + b) & 255
            elif filt == 3:
                line[i] = (line[i] + (a + b) // 2) & 255
            elif filt == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                pred = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
                line[i] = (line[i] + pred) & 255
        prev = line
        for x in range(width):
            yield tuple(line[x * channels:x * channels + 3])


def main():
    path, min_pixels, min_colours = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
    inked = [p for p in pixels(path) if sum(p) < 600]  # not white, nor the #ddd border
    colours = {(r // 32, g // 32, b // 32) for r, g, b in inked}
    print(f"{path}: {len(inked)} inked pixels in {len(colours)} colours")
    if len(inked) < min_pixels or len(colours) < min_colours:
        sys.exit(1)


main()
