#!/usr/bin/env python3
"""bench/exr_exact.py — exact comparison of two tdpm EXR files, every channel.

Used by bench/bitmatch. Reads the scanline OpenEXR files tdpm writes
(image/exr.cpp: one part, FLOAT channels, ZIP or no compression) with the
standard library alone, so it needs neither numpy nor the OpenEXR bindings.
Pixels compare as bits (MSE 0 and bit for bit are the same test here, and
bits also catch -0 and NaN payloads); the per-channel MSE and largest
difference are computed only to say by how much a channel differs.

Metadata: every attribute must match except the wall-clock ones
(IGNORED_ATTRIBUTES). An attribute present in one file only is reported as a
note, not a failure (a refactor may add metadata on purpose: say so in the
commit), a value that changed is a failure.

    exr_exact.py BASE.exr HEAD.exr      exit 0: identical, 1: differ, 2: unreadable
"""
import struct
import sys
import zlib
from itertools import accumulate

IGNORED_ATTRIBUTES = {"tdpm/render_seconds", "tdpm/progressive_seconds", "tdpm/progressive/scalar/seconds"}
LINES_PER_CHUNK = {0: 1, 1: 1, 2: 1, 3: 16}  # NONE, RLE, ZIPS, ZIP (what tdpm may write)
PIXEL_BYTES = {0: 4, 1: 2, 2: 4}  # UINT, HALF, FLOAT


class ExrError(Exception):
    pass


def _cstring(buf, at):
    end = buf.index(b"\0", at)
    return buf[at:end].decode("latin-1"), end + 1


def _channels(value):
    out, at = [], 0
    while value[at] != 0:
        name, at = _cstring(value, at)
        ptype, _plinear, xs, ys = struct.unpack_from("<iB3xii", value, at)
        at += 16
        if xs != 1 or ys != 1:
            raise ExrError("subsampled channel " + name)
        out.append((name, ptype))
    return out


def _unzip(data, raw_size):
    if len(data) == raw_size:  # OpenEXR stores a chunk raw when zlib does not shrink it
        return data
    t = zlib.decompress(data)
    t = bytes(accumulate(t, lambda a, b: (a + b - 128) & 0xFF))  # undo the byte predictor
    half = (len(t) + 1) // 2
    out = bytearray(len(t))
    out[0::2] = t[:half]  # undo the even/odd split
    out[1::2] = t[half:]
    return bytes(out)


def read_exr(path):
    """-> (attributes {name: (type, bytes)}, channels {name: bytes}, width, height)."""
    with open(path, "rb") as f:
        buf = f.read()
    if buf[:4] != b"\x76\x2f\x31\x01":
        raise ExrError("not an OpenEXR file")
    flags = struct.unpack_from("<I", buf, 4)[0] >> 8
    if flags & (0x2 | 0x8 | 0x10):
        raise ExrError("tiled, deep or multi-part files are not read here")
    attrs, at = {}, 8
    while buf[at] != 0:
        name, at = _cstring(buf, at)
        typ, at = _cstring(buf, at)
        size = struct.unpack_from("<i", buf, at)[0]
        attrs[name] = (typ, buf[at + 4:at + 4 + size])
        at += 4 + size
    at += 1
    xmin, ymin, xmax, ymax = struct.unpack("<iiii", attrs["dataWindow"][1])
    width, height = xmax - xmin + 1, ymax - ymin + 1
    compression = attrs["compression"][1][0]
    if compression not in (0, 3):
        raise ExrError("compression %d is not read here (tdpm writes ZIP)" % compression)
    lines = LINES_PER_CHUNK[compression]
    chans = sorted(_channels(attrs["channels"][1]))
    chunks = (height + lines - 1) // lines
    offsets = struct.unpack_from("<%dQ" % chunks, buf, at)
    planes = {name: bytearray() for name, _ in chans}
    for off in offsets:
        y, size = struct.unpack_from("<ii", buf, off)
        n = min(lines, ymax + 1 - y)
        row_bytes = sum(PIXEL_BYTES[p] * width for _, p in chans)
        raw = _unzip(buf[off + 8:off + 8 + size], row_bytes * n) if compression == 3 else buf[off + 8:off + 8 + size]
        p = 0
        for _ in range(n):
            for name, ptype in chans:
                k = PIXEL_BYTES[ptype] * width
                planes[name] += raw[p:p + k]
                p += k
    return attrs, {k: bytes(v) for k, v in planes.items()}, width, height


def _floats(b):
    return struct.unpack("<%df" % (len(b) // 4), b)


def compare(base_path, head_path):
    """-> (ok, lines of text)."""
    a_attrs, a_ch, aw, ah = read_exr(base_path)
    b_attrs, b_ch, bw, bh = read_exr(head_path)
    ok, notes = True, []
    if (aw, ah) != (bw, bh):
        return False, ["size %dx%d vs %dx%d" % (aw, ah, bw, bh)]
    for name in sorted(set(a_ch) | set(b_ch)):
        if name not in a_ch or name not in b_ch:
            ok = False
            notes.append("channel %s only in %s" % (name, "base" if name in a_ch else "head"))
        elif a_ch[name] != b_ch[name]:
            ok = False
            x, y = _floats(a_ch[name]), _floats(b_ch[name])
            d = [(p - q) for p, q in zip(x, y)]
            mse = sum(v * v for v in d) / len(d)
            worst = max(abs(v) for v in d)
            n = len(d)
            bad = sum(1 for p, q in zip(struct.unpack("<%dI" % n, a_ch[name]), struct.unpack("<%dI" % n, b_ch[name]))
                      if p != q)
            notes.append("channel %s differs: MSE %.6g, max |diff| %.6g (%d of %d values differ)"
                         % (name, mse, worst, bad, len(d)))
    for name in sorted(set(a_attrs) | set(b_attrs)):
        if name in IGNORED_ATTRIBUTES:
            continue
        if name not in a_attrs or name not in b_attrs:
            which = "base" if name in a_attrs else "head"
            val = (a_attrs.get(name) or b_attrs.get(name))[1]
            notes.append("note: attribute %s only in %s (%r)" % (name, which, val.decode("latin-1", "replace")))
        elif a_attrs[name] != b_attrs[name]:
            ok = False
            notes.append("attribute %s differs: %r vs %r" % (name, a_attrs[name][1], b_attrs[name][1]))
    return ok, notes


def main(argv):
    if len(argv) != 3:
        sys.stderr.write(__doc__)
        return 2
    try:
        ok, notes = compare(argv[1], argv[2])
    except (OSError, ExrError, KeyError, struct.error, zlib.error, ValueError) as e:
        print("cannot compare %s and %s: %s" % (argv[1], argv[2], e))
        return 2
    for n in notes:
        print(n)
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv))
