#!/usr/bin/env python3
# bench/progressive-point-table.py — the table of bench/progressive-point:
# relMSE (pbrt-v4's, from `tdpm compare --json`) of every run against the
# frozen-time reference, over the whole image and over the caustic region's
# bounding box (reference caustic = reference minus direct light > 5% of its
# peak, as tests/test_caustic_variance.cpp's mask), user CPU seconds and peak
# RSS, the log-log slope of the progressive curve, and the two targets of
# issue 10. Standard library only. Usage: progressive-point-table.py OUT TDPM
import glob, json, math, os, re, struct, subprocess, sys

out, tdpm = sys.argv[1], sys.argv[2]
ref = os.path.join(out, "ref", "ref.pfm")


def read_pfm(path):
    with open(path, "rb") as f:
        kind = f.readline().strip()
        w, h = map(int, f.readline().split())
        scale = float(f.readline())
        ch = 3 if kind == b"PF" else 1
        data = struct.unpack(("<" if scale < 0 else ">") + "f" * (w * h * ch), f.read(4 * w * h * ch))
    lum = [sum(data[i * ch:(i + 1) * ch]) / ch for i in range(w * h)]  # grey scene: channels equal
    return w, h, lum  # rows bottom to top in PFM


def caustic_box():
    w, h, r = read_pfm(ref)
    _, _, d = read_pfm(os.path.join(out, "ref", "direct.pfm"))
    c = [a - b for a, b in zip(r, d)]
    peak = max(c)
    xs, ys = [], []
    for i, v in enumerate(c):
        if v > 0.05 * peak:
            xs.append(i % w)
            ys.append(h - 1 - i // w)  # PFM is bottom-up; compare's y is from the top
    return min(xs), min(ys), max(xs) - min(xs) + 1, max(ys) - min(ys) + 1, len(xs)


def compare(img, reference=ref, crop=None):
    cmd = [tdpm, "compare", "--json", img, reference] + (["--crop", ",".join(map(str, crop))] if crop else [])
    j = json.loads(subprocess.run(cmd, check=True, capture_output=True, text=True).stdout)
    return j["rel_mse"]["overall"], j["relative_mean_difference"]


def variance_part(img):
    """relMSE of (reference + the EXR's standard error of the mean) against the
    reference: the noise part of a progressive image's relMSE, from its
    variance.R/G/B layer (spread of the pass means). None without oiiotool."""
    x = img[:-4] + ".sd.exr"
    try:
        subprocess.run(["oiiotool", img, "--ch", "variance.R,variance.G,variance.B", "--chnames", "R,G,B",
                        "--powc", "0.5", ref, "--add", "-o", x], check=True, capture_output=True)
    except (OSError, subprocess.CalledProcessError):
        return None
    return compare(x)[0], compare(x, crop=crop)[0]


def cpu_rss(name):
    u, m = open(os.path.join(out, name + ".time")).read().split()
    return float(u), int(m) / 1024.0


def passes(name):
    m = re.search(r"samples per pixel: (\d+)", open(os.path.join(out, name + ".log")).read())
    return int(m.group(1)) // 16 if m else None  # 16 spp per pass (the scene's)


def fit(points):  # least squares slope and intercept of log y on log x
    lx = [math.log(x) for x, _ in points]
    ly = [math.log(y) for _, y in points]
    mx, my = sum(lx) / len(lx), sum(ly) / len(ly)
    s = sum((a - mx) * (b - my) for a, b in zip(lx, ly)) / sum((a - mx) ** 2 for a in lx)
    return s, my - s * mx


box = caustic_box()
crop = box[:4]
print(f"caustic region: {box[4]} px, bounding box x,y,w,h = {','.join(map(str, crop))}")
hw, hc = compare(os.path.join(out, "ref", "refA.pfm"), os.path.join(out, "ref", "refB.pfm")), \
    compare(os.path.join(out, "ref", "refA.pfm"), os.path.join(out, "ref", "refB.pfm"), crop)
print(f"reference halves A vs B: relMSE whole {hw[0]:.5f}, caustic box {hc[0]:.5f} (region mean {hc[1]*100:+.2f}%);"
      f" the mean's own relMSE is about a quarter: {hw[0]/4:.5f} / {hc[0]/4:.5f}")

rows = {}
for series in ("time", "acc"):
    names = sorted((os.path.basename(p)[:-5] for p in glob.glob(os.path.join(out, f"prog-{series}-*.time"))),
                   key=lambda n: int(n.rsplit("-", 1)[1]))
    cum, pts = 0.0, []
    for n in names:
        u, m = cpu_rss(n)
        cum += u
        w, c = compare(os.path.join(out, n + ".exr")), compare(os.path.join(out, n + ".exr"), crop=crop)
        pts.append((n, passes(n), cum, m, w, c, variance_part(os.path.join(out, n + ".exr"))))
    rows[series] = pts

fixed = {}
for p in glob.glob(os.path.join(out, "fixed-time-*.time")):
    n = os.path.basename(p)[:-5]
    key = n.rsplit("-s", 1)[0]
    u, m = cpu_rss(n)
    fixed.setdefault(key, []).append((u, m, compare(os.path.join(out, n + ".exr")),
                                      compare(os.path.join(out, n + ".exr"), crop=crop)))

print("\n| run | passes | user CPU s | peak RSS MiB | relMSE whole | relMSE caustic box | caustic box mean "
      "| noise part whole / caustic box |")
print("|---|---|---|---|---|---|---|---|")
for series, pts in rows.items():
    label = "time" if series == "time" else "accumulation"
    for n, ps, t, m, w, c, v in pts:
        vs = f"{v[0]:.5f} / {v[1]:.5f}" if v else "-"
        print(f"| {label} --progressive | {ps} | {t:.1f} | {m:.1f} | {w[0]:.5f} | {c[0]:.5f} | {c[1]*100:+.2f}% | {vs} |")
fixed_mean = {}
for key in sorted(fixed, key=lambda k: (len(k), k)):
    v = fixed[key]
    k = len(v)
    t = sum(x[0] for x in v) / k
    m = max(x[1] for x in v)
    w = sum(x[2][0] for x in v) / k
    c = sum(x[3][0] for x in v) / k
    fixed_mean[key] = (t, w, c)
    per = ", ".join(f"{x[3][0]:.4f}" for x in v)
    means = ", ".join(f"{x[3][1]*100:+.1f}%" for x in v)
    print(f"| {key.replace('fixed-', 'fixed ')} ({k} seeds, mean) | - | {t:.1f} | {m:.1f} | {w:.5f} | {c:.5f} "
          f"(seeds: {per}) | {means} | - |")

for series, pts in rows.items():
    if len(pts) < 2:
        continue
    for idx, region in ((4, "whole"), (5, "caustic box")):
        s, b = fit([(p[2], p[idx][0]) for p in pts])
        s2 = fit([(p[2], p[idx][0]) for p in pts[-3:]])[0]
        print(f"{series} --progressive, {region}: log-log slope of relMSE against CPU s {s:.3f} (all points), "
              f"{s2:.3f} (last three)")
    if all(p[6] for p in pts):  # what is left when the noise is taken out: bias^2 + the reference's error
        rest = [(p[2], p[5][0] - p[6][1]) for p in pts]
        if all(r > 0 for _, r in rest):
            print(f"{series} --progressive, caustic box minus its noise part: " +
                  ", ".join(f"{r:.5f}" for _, r in rest) + f"; slope {fit(rest)[0]:.3f}, last three {fit(rest[-3:])[0]:.3f}")
    rss = [p[3] for p in pts]
    print(f"{series} --progressive: peak RSS {min(rss):.1f}-{max(rss):.1f} MiB over the runs")

if rows.get("time") and fixed_mean:
    pts = rows["time"]
    for idx, col, region in ((4, 1, "whole"), (5, 2, "caustic box")):
        best = min(fixed_mean.items(), key=lambda kv: kv[1][col])
        goal = best[1][col] / 2
        t_reach = None
        for a, bb in zip(pts, pts[1:]):
            ya, yb = a[idx][0], bb[idx][0]
            if ya > goal >= yb:  # log-log interpolation between the two points
                f = (math.log(goal) - math.log(ya)) / (math.log(yb) - math.log(ya))
                t_reach = math.exp(math.log(a[2]) + f * (math.log(bb[2]) - math.log(a[2])))
                break
        if pts[0][idx][0] <= goal:
            t_reach = pts[0][2]
            note = " (already at the first point)"
        else:
            note = ""
        verdict = ("not reached within the curve" if t_reach is None else
                   f"reached at {t_reach:.1f} s{note} = {t_reach / best[1][0]:.2f}x its time "
                   f"({'met' if t_reach <= 4 * best[1][0] else 'not met'}: target <= 4x)")
        print(f"{region}: best fixed {best[0]} relMSE {best[1][col]:.5f} at {best[1][0]:.1f} s; half = {goal:.5f}: "
              f"{verdict}")
