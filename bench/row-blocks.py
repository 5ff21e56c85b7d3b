#!/usr/bin/env python3
"""bench/row-blocks.py — where two renders' means part: the mean of every
block of rows (the channels' average), each image against the first, and the
reference's brightest pixels, which may be left out of every image's means.

Written for the media biases of issue 25 (bench/README.md, "The volumetric
caustic's 18%"): on a scene with a sub-pixel light or path-traced fireflies
the whole image's mean is carried by a handful of pixels, and a bias is only
seen once they are named and set apart. Reads tdpm's EXRs with
bench/exr_exact.py's reader (standard library only).

    row-blocks.py [--block ROWS] [--skip N] REF.exr TEST.exr [TEST2.exr ...]
"""
import argparse
import os
import struct
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from exr_exact import ExrError, read_exr  # noqa: E402


def luminance_plane(path):
    """-> (width, height, [channel average per pixel]), rows from the top."""
    _attrs, ch, w, h = read_exr(path)
    if not all(c in ch for c in "RGB"):
        raise ExrError(path + ": no R, G, B channels")
    r, g, b = (struct.unpack("<%df" % (w * h), ch[c]) for c in "RGB")
    return w, h, [(r[i] + g[i] + b[i]) / 3 for i in range(w * h)]


def block_mean(plane, w, y0, y1, skip):
    vals = [plane[y * w + x] for y in range(y0, y1) for x in range(w) if y * w + x not in skip]
    return sum(vals) / len(vals) if vals else float("nan")


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--block", type=int, default=8, help="rows per block (default 8)")
    ap.add_argument("--skip", type=int, default=0, help="leave out the reference's N brightest pixels (default 0)")
    ap.add_argument("images", nargs="+", help="the reference first, then the images to compare")
    a = ap.parse_args(argv)
    if len(a.images) < 2 or a.block < 1 or a.skip < 0:
        ap.error("a reference and at least one image; --block >= 1, --skip >= 0")
    try:
        planes = [luminance_plane(p) for p in a.images]
    except (OSError, ExrError) as e:
        print("row-blocks.py: %s" % e, file=sys.stderr)
        return 2
    w, h, ref = planes[0]
    for p, (wi, hi, _) in zip(a.images, planes):
        if (wi, hi) != (w, h):
            print("row-blocks.py: %s is %dx%d, the reference %dx%d" % (p, wi, hi, w, h), file=sys.stderr)
            return 2
    bright = sorted(range(w * h), key=lambda i: -ref[i])[: max(a.skip, 3)]
    print("reference's brightest pixels (x, y: value):",
          ", ".join("%d,%d: %.4g" % (i % w, i // w, ref[i]) for i in bright))
    skip = set(bright[: a.skip])
    print("%-9s %s   ratios to the reference" % ("rows", " ".join("%12s" % os.path.basename(p)[:12] for p in a.images)))
    blocks = [(y, min(y + a.block, h), "%d-%d" % (y, min(y + a.block, h) - 1)) for y in range(0, h, a.block)]
    for y0, y1, label in blocks + [(0, h, "all")]:
        means = [block_mean(pl, w, y0, y1, skip) for _, _, pl in planes]
        print("%-9s %s   %s" % (label, " ".join("%12.5g" % m for m in means),
                                 " ".join("%.4f" % (m / means[0]) if means[0] else "-" for m in means[1:])))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
