#!/usr/bin/env python3
"""bench/media/smoke_blob.py — writes a sparse smoke-blob grid scene for the
majorant grid's before/after timing (bench/README.md, "Media"): a 64^3
density grid filling a 2 m interface box over a floor, zero except a soft
blob (radius 0.3 m, peak density 8) near one corner and a thin haze band
(density 0.05) along the bottom, lit by an area lamp. Usage:
    smoke_blob.py OUT.json [--moving]
--moving: the box (and so the grid inside it) moves 0.5 m along x over the
shutter. Written to a scratch dir, never committed (it is 1.5 MB)."""
import math
import sys

n = 64
out = sys.argv[1]
moving = "--moving" in sys.argv[2:]
vals = []
cx, cy, cz, r = 0.3, 0.62, 0.35, 0.15  # grid space [0, 1]^3: the blob sits off-centre
for z in range(n):
    for y in range(n):
        for x in range(n):
            px, py, pz = (x + 0.5) / n, (y + 0.5) / n, (z + 0.5) / n
            d2 = ((px - cx) ** 2 + (py - cy) ** 2 + (pz - cz) ** 2) / (r * r)
            v = 8.0 * math.exp(-2.0 * d2) if d2 < 4.0 else 0.0
            if py < 0.08:
                v += 0.05
            vals.append("0" if v == 0.0 else "%.4g" % v)
motion = ', "motion": [{"time": 0, "translate": [-0.25, 0, 0]}, {"time": 1, "translate": [0.25, 0, 0]}]' if moving else ""
scene = """{
  "camera": {"position": [0, 1.4, 4.5], "target": [0, 1.0, 0], "fov": 45, "resolution": [160, 120], "shutter": [0, 1]},
  "media": {
    "smoke": {"type": "grid", "sigma_a": [0.5, 0.5, 0.5], "sigma_s": [4, 4, 4], "g": 0.3,
              "resolution": [%d, %d, %d], "transform": {"scale": [2, 2, 2], "translate": [-1, -1, -1]},
              "density": [%s]}
  },
  "materials": {"floor": {"type": "diffuse", "color": [0.6, 0.6, 0.6]}},
  "objects": [
    {"name": "floor", "shape": {"type": "quad", "size": [8, 8]}, "material": "floor"},
    {"name": "box", "shape": {"type": "box", "size": [2, 2, 2]}, "material": "interface", "medium": "smoke",
     "transform": {"translate": [0, 1.001, 0]}%s}
  ],
  "lights": [
    {"name": "lamp", "type": "area", "size": [1, 1], "power": [200, 200, 200],
     "transform": {"translate": [0.5, 3.5, 1]}}
  ],
  "background": [0.05, 0.05, 0.06],
  "render": {"method": "pathtrace", "spp": 16, "max_depth": 8, "seed": 1}
}
""" % (n, n, n, ", ".join(vals), motion)
with open(out, "w") as f:
    f.write(scene)
