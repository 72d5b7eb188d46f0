#!/usr/bin/python3
"""Regenerate the binary files of the bad-input corpus (standard library only).

Run from anywhere:  /usr/bin/python3 tests/bad_input/tools/make_binaries.py
Output is deterministic; the files it writes are committed, so this only needs
to be run again if it is changed.
"""
import os
import struct
import zlib

HERE = os.path.dirname(os.path.abspath(__file__))
CORPUS = os.path.dirname(HERE)


def put(rel, data):
    with open(os.path.join(CORPUS, rel), "wb") as f:
        f.write(data)


def garbage(n, seed):
    """n deterministic pseudo-random bytes (xorshift32); byte 0 is NUL so the
    first line is unmistakably binary."""
    x = seed & 0xFFFFFFFF
    out = bytearray()
    while len(out) < n:
        x ^= (x << 13) & 0xFFFFFFFF
        x ^= x >> 17
        x ^= (x << 5) & 0xFFFFFFFF
        out.append(x & 0xFF)
    out[0] = 0
    return bytes(out)


def png_rgb(w, h, pixel):
    """A valid 8-bit RGB PNG; pixel(x, y) -> (r, g, b)."""
    def chunk(tag, body):
        return (struct.pack(">I", len(body)) + tag + body
                + struct.pack(">I", zlib.crc32(tag + body) & 0xFFFFFFFF))
    raw = b"".join(b"\x00" + bytes(c for x in range(w) for c in pixel(x, y))
                   for y in range(h))
    return (b"\x89PNG\r\n\x1a\n"
            + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))
            + chunk(b"IDAT", zlib.compress(raw, 9))
            + chunk(b"IEND", b""))


def exr_rgb(w, h, value):
    """A valid scanline OpenEXR file: channels B, G, R as 32-bit float, no
    compression, increasing y; value(x, y) -> (r, g, b)."""
    def attr(name, typ, body):
        return name + b"\0" + typ + b"\0" + struct.pack("<i", len(body)) + body
    chlist = b"".join(c + b"\0" + struct.pack("<iB3xii", 2, 0, 1, 1)
                      for c in (b"B", b"G", b"R")) + b"\0"
    box = struct.pack("<iiii", 0, 0, w - 1, h - 1)
    header = (struct.pack("<ii", 20000630, 2)
              + attr(b"channels", b"chlist", chlist)
              + attr(b"compression", b"compression", b"\0")
              + attr(b"dataWindow", b"box2i", box)
              + attr(b"displayWindow", b"box2i", box)
              + attr(b"lineOrder", b"lineOrder", b"\0")
              + attr(b"pixelAspectRatio", b"float", struct.pack("<f", 1.0))
              + attr(b"screenWindowCenter", b"v2f", struct.pack("<ff", 0, 0))
              + attr(b"screenWindowWidth", b"float", struct.pack("<f", 1.0))
              + b"\0")
    blocks = []
    for y in range(h):
        px = [value(x, y) for x in range(w)]
        data = b"".join(struct.pack("<%df" % w, *[p[c] for p in px])
                        for c in (2, 1, 0))          # B, G, R
        blocks.append(struct.pack("<ii", y, len(data)) + data)
    offset = len(header) + 8 * h
    table = b""
    for b in blocks:
        table += struct.pack("<Q", offset)
        offset += len(b)
    return header + table + b"".join(blocks)


def main():
    put("garbage.obj", garbage(2048, 0x0B1EC7))
    put("mtl_garbage.mtl", garbage(2048, 0x6A7E71A1))

    # A 16x16 noisy texture (noise keeps the IDAT well over 100 bytes).
    noise = garbage(16 * 16 * 3 + 1, 0x7E87)[1:]
    valid = png_rgb(16, 16, lambda x, y: noise[3 * (16 * y + x):3 * (16 * y + x) + 3])
    put("good/checker.png", valid)
    put("tex_truncated.png", valid[:100])
    put("tex_text.png", b"This is a text file pretending to be a PNG image.\n")
    # JPEG start-of-image and APP0 markers, then nonsense.
    put("tex_bad.jpg", b"\xff\xd8\xff\xe0\x00\x10JFIF\x00" + b"not really a jpeg\n" * 3)

    put("exr_4x4.exr", exr_rgb(4, 4, lambda x, y: (0.25 * x, 0.25 * y, 0.5)))
    put("exr_3x2.exr", exr_rgb(3, 2, lambda x, y: (0.5, 0.5, 0.5)))
    put("exr_truncated.exr", exr_rgb(4, 4, lambda x, y: (1.0, 1.0, 1.0))[:60])
    put("exr_not_exr.exr", b"This is a text file, not an OpenEXR image.\n")


if __name__ == "__main__":
    main()
