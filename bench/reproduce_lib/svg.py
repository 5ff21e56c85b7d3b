"""bench/reproduce_lib/svg.py — the figures of bench/reproduce as standalone
SVG: the montage (reference and methods side by side), the log-log plot of
error against run time with the reference's own error as its floor, and the
luminance profile of every method over the reference along one row (from
the CSVs `tdpm compare --csv` writes); PNG copies by rsvg-convert."""
import base64
import csv
import math
import os
import shutil
import struct
import subprocess

from reproduce_lib.config import COLORS, CONSISTENT, METHODS, PROGRESSIVE
from reproduce_lib.report import fmt


def esc(s):
    return str(s).replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")


def png_size(path):
    with open(path, "rb") as f:
        head = f.read(24)
    return struct.unpack(">II", head[16:24])


def write_montage(items, path, title, crop=None, scale=1.0):
    """items: [(png path, label)] side by side, labels underneath; a standalone SVG.
    crop: (x, y, w, h) in pixels of each image; scale: display scale of the crop."""
    items = [(p, l) for p, l in items if os.path.exists(p)]
    if not items:
        return None
    iw, ih = png_size(items[0][0])
    cx, cy, cw, ch = crop or (0, 0, iw, ih)
    w, h = int(round(cw * scale)), int(round(ch * scale))
    pad, lab = 6, 22
    W = len(items) * (w + pad) + pad
    H = h + 2 * pad + lab + 24
    out = [f'<svg xmlns="http://www.w3.org/2000/svg" xmlns:xlink="http://www.w3.org/1999/xlink" '
           f'width="{W}" height="{H}" viewBox="0 0 {W} {H}">',
           f'<rect width="{W}" height="{H}" fill="white"/>',
           f'<text x="{pad}" y="18" font-family="sans-serif" font-size="13">{esc(title)}</text>']
    for i, (p, label) in enumerate(items):
        with open(p, "rb") as f:
            b64 = base64.b64encode(f.read()).decode()
        x = pad + i * (w + pad)
        out.append(f'<svg x="{x}" y="24" width="{w}" height="{h}" viewBox="{cx} {cy} {cw} {ch}">'
                   f'<image x="0" y="0" width="{iw}" height="{ih}" style="image-rendering:pixelated" '
                   f'xlink:href="data:image/png;base64,{b64}"/></svg>')
        out.append(f'<text x="{x + w / 2}" y="{24 + h + 17}" text-anchor="middle" '
                   f'font-family="sans-serif" font-size="13">{esc(label)}</text>')
    out.append("</svg>")
    with open(path, "w") as f:
        f.write("\n".join(out))
    return path


def loglog_plot(series, path, title, xlabel, ylabel, floor=None, warning=None):
    """series: {name: [(x, y), ...]}; hand-written SVG with log-log axes. floor: the reference's
    own error, drawn as a grey dashed line; warning: a red line under the title."""
    pts = [(x, y) for s in series.values() for x, y in s if x > 0 and y > 0]
    if pts and floor and floor > 0:
        pts.append((pts[0][0], floor))
    if not pts:
        return None
    W, H = 720, 480
    L, R, T, B = 80, 190, 40, 60
    x0 = math.floor(math.log10(min(p[0] for p in pts)))
    x1 = math.ceil(math.log10(max(p[0] for p in pts)))
    y0 = math.floor(math.log10(min(p[1] for p in pts)))
    y1 = math.ceil(math.log10(max(p[1] for p in pts)))
    x1 = max(x1, x0 + 1)
    y1 = max(y1, y0 + 1)

    def X(v):
        return L + (math.log10(v) - x0) / (x1 - x0) * (W - L - R)

    def Y(v):
        return H - B - (math.log10(v) - y0) / (y1 - y0) * (H - T - B)

    o = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{W}" height="{H}" viewBox="0 0 {W} {H}" '
         f'font-family="sans-serif" font-size="12">',
         f'<rect width="{W}" height="{H}" fill="white"/>',
         f'<text x="{(L + W - R) / 2}" y="22" text-anchor="middle" font-size="15">{esc(title)}</text>']
    if warning:
        o.append(f'<text x="{(L + W - R) / 2}" y="36" text-anchor="middle" font-size="11" fill="#c00000">'
                 f'{esc(warning)}</text>')
    # grid and ticks
    for e in range(x0, x1 + 1):
        for m in range(1, 10):
            v = m * 10 ** e
            if e == x1 and m > 1:
                break
            x = X(v)
            o.append(f'<line x1="{x:.1f}" y1="{T}" x2="{x:.1f}" y2="{H - B}" '
                     f'stroke="{"#ccc" if m == 1 else "#eee"}"/>')
        o.append(f'<text x="{X(10 ** e):.1f}" y="{H - B + 18}" text-anchor="middle">{10 ** e:g}</text>')
    for e in range(y0, y1 + 1):
        for m in range(1, 10):
            v = m * 10 ** e
            if e == y1 and m > 1:
                break
            y = Y(v)
            o.append(f'<line x1="{L}" y1="{y:.1f}" x2="{W - R}" y2="{y:.1f}" '
                     f'stroke="{"#ccc" if m == 1 else "#eee"}"/>')
        o.append(f'<text x="{L - 6}" y="{Y(10 ** e) + 4:.1f}" text-anchor="end">{10 ** e:g}</text>')
    o.append(f'<rect x="{L}" y="{T}" width="{W - L - R}" height="{H - T - B}" fill="none" stroke="black"/>')
    o.append(f'<text x="{(L + W - R) / 2}" y="{H - 18}" text-anchor="middle">{esc(xlabel)}</text>')
    o.append(f'<text x="18" y="{(T + H - B) / 2}" text-anchor="middle" '
             f'transform="rotate(-90 18 {(T + H - B) / 2})">{esc(ylabel)}</text>')
    ly = T + 10
    if floor and floor > 0:
        o.append(f'<line x1="{L}" y1="{Y(floor):.1f}" x2="{W - R}" y2="{Y(floor):.1f}" stroke="#666" '
                 f'stroke-width="1.5" stroke-dasharray="2 3"/>')
        o.append(f'<text x="{W - R - 4}" y="{Y(floor) - 4:.1f}" text-anchor="end" font-size="10" fill="#444">'
                 f'reference\'s own error {fmt(floor)}</text>')
    for name, s in series.items():
        s = sorted((x, y) for x, y in s if x > 0 and y > 0)
        if not s:
            continue
        col = COLORS.get(name, "black")
        dash = "" if name in CONSISTENT else ' stroke-dasharray="6 4"'
        o.append(f'<polyline fill="none" stroke="{col}" stroke-width="2"{dash} points="'
                 + " ".join(f"{X(x):.1f},{Y(y):.1f}" for x, y in s) + '"/>')
        for x, y in s:
            o.append(f'<circle cx="{X(x):.1f}" cy="{Y(y):.1f}" r="3.5" fill="{col}"/>')
        o.append(f'<line x1="{W - R + 12}" y1="{ly}" x2="{W - R + 40}" y2="{ly}" stroke="{col}" '
                 f'stroke-width="2"{dash}/>')
        o.append(f'<circle cx="{W - R + 26}" cy="{ly}" r="3.5" fill="{col}"/>')
        label = METHODS[name][2] if name in METHODS else PROGRESSIVE[name][2] if name in PROGRESSIVE else name
        o.append(f'<text x="{W - R + 46}" y="{ly + 4}">{esc(label)}</text>')
        ly += 20
    o.append(f'<text x="{W - R + 12}" y="{ly + 8}" font-size="10" fill="#555">dashed: not consistent</text>')
    o.append("</svg>")
    with open(path, "w") as f:
        f.write("\n".join(o))
    return path


def profile_plot(csvs, path, title):
    """csvs: [(name, csv from tdpm compare)]; luminance along the row, every method over the reference."""
    curves = {}
    for name, c in csvs:
        if not os.path.exists(c):
            continue
        with open(c) as f:
            rd = list(csv.DictReader(f))
        if "reference" not in curves:
            curves["reference"] = [(int(r["x"]), float(r["ref_lum"])) for r in rd]
        curves[name] = [(int(r["x"]), float(r["test_lum"])) for r in rd]
    if len(curves) < 2:
        return None
    W, H, L, R, T, B = 760, 400, 70, 160, 40, 50
    xmax = max(x for c in curves.values() for x, _ in c) or 1
    ymax = max(y for c in curves.values() for _, y in c) or 1
    e = 10 ** math.floor(math.log10(ymax))
    step = next(m * e for m in (0.1, 0.2, 0.25, 0.5, 1, 2, 2.5, 5, 10) if ymax / (m * e) <= 6)
    ymax = math.ceil(ymax / step) * step

    def X(v):
        return L + v / xmax * (W - L - R)

    def Y(v):
        return H - B - v / ymax * (H - T - B)

    o = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{W}" height="{H}" viewBox="0 0 {W} {H}" '
         f'font-family="sans-serif" font-size="12">', f'<rect width="{W}" height="{H}" fill="white"/>',
         f'<text x="{(L + W - R) / 2}" y="22" text-anchor="middle" font-size="14">{esc(title)}</text>']
    v = 0.0
    while v <= ymax + 1e-9:
        o.append(f'<line x1="{L}" y1="{Y(v):.1f}" x2="{W - R}" y2="{Y(v):.1f}" stroke="#e4e4e4"/>')
        o.append(f'<text x="{L - 6}" y="{Y(v) + 4:.1f}" text-anchor="end">{v:g}</text>')
        v += step
    xs = 50 if xmax <= 400 else 100
    for x in range(0, xmax + 1, xs):
        o.append(f'<text x="{X(x):.1f}" y="{H - B + 16}" text-anchor="middle">{x}</text>')
    o.append(f'<rect x="{L}" y="{T}" width="{W - L - R}" height="{H - T - B}" fill="none" stroke="black"/>')
    o.append(f'<text x="{(L + W - R) / 2}" y="{H - 12}" text-anchor="middle">pixel column</text>')
    o.append(f'<text x="16" y="{(T + H - B) / 2}" text-anchor="middle" '
             f'transform="rotate(-90 16 {(T + H - B) / 2})">luminance (linear)</text>')
    ly = T + 10
    for name, c in curves.items():
        col = "black" if name == "reference" else COLORS.get(name, "#444")
        wdt = 2.5 if name == "reference" else 1.5
        o.append(f'<polyline fill="none" stroke="{col}" stroke-width="{wdt}" stroke-linejoin="round" points="'
                 + " ".join(f"{X(x):.1f},{Y(y):.1f}" for x, y in c) + '"/>')
        o.append(f'<line x1="{W - R + 12}" y1="{ly}" x2="{W - R + 36}" y2="{ly}" stroke="{col}" '
                 f'stroke-width="{wdt}"/>')
        o.append(f'<text x="{W - R + 42}" y="{ly + 4}">'
                 f'{esc(METHODS[name][2] if name in METHODS else name)}</text>')
        ly += 20
    o.append("</svg>")
    with open(path, "w") as f:
        f.write("\n".join(o))
    return path


def to_png(svg):
    exe = shutil.which("rsvg-convert")
    if not exe or not svg:
        return None
    png = svg[:-4] + ".png"
    p = subprocess.run([exe, "-o", png, svg], capture_output=True, text=True)
    return png if p.returncode == 0 else None
