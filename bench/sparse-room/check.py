#!/usr/bin/env python3
# bench/sparse-room/check.py — issue 24's two scene checks against path-traced
# references (minutes, not a CTest; docs/photon-map.md "Few photons").
#
#   check.py TDPM OUT [--part sparse|room|all] [--seeds 1 ... 12] [--res 160x120]
#            [--extra "--gather 4 ..."]
#
# sparse: scenes/sparse-room.json, `-m time` and `-m time --search 4d` at the
#   default settings (fixed budget, 16 spp, 50,000 global photons, the gather
#   guide on; --extra "--gather-guide off" for the BSDF-only gather) at RES, one
#   render per seed: image mean, every 32x32 block's mean, relMSE and salt
#   (`tdpm compare --salt`) against a 1024-spp path trace (made once, cached
#   in OUT); then `-m pathtrace` at the spp that takes the same CPU time
#   (user + system of the child) and its relMSE, for "relMSE at equal time".
#   Per seed and averaged over the seeds: the per-seed image mean of a
#   16-spp render moves by a few percent with the seed, in every method alike,
#   from the rows holding the lamp (how many of a pixel's samples land on it),
#   so the mean is also given without the lamp's band of rows
#   [0.23 h, 0.35 h) and the bounds apply to the seed means. The blocks
#   holding those rows are bounded only over 12 seeds or more: one seed of a
#   16-spp path trace puts them anywhere in 0.93-1.11 of the reference, and
#   3 seeds left `time` at 0.976 (stop 31) while 40 seeds of pathtrace and
#   12 of `time` put every such block within 1.4% (stop 33).
# room: scenes/static-room.json with tall_block moving x-0.4 -> x+0.4 over
#   the shutter, the global map seen directly (`--global-direct --gather 0
#   --photons 0`), 80x60, 8 spp, `time` and `standard` at 2,000, 20,000 and
#   100,000 global photons, against a 4096-spp path trace of the same scene
#   (the global map holds every photon that reached a diffuse surface, so
#   seen directly it estimates the light a path tracer computes there: the
#   same lighting). Whole image, the static receivers (x < 40, where no eye
#   ray meets the block's motion) and the block (40,20 30x30).
# --extra is appended to every photon render (e.g. "--gather 4 --spp 4").
# Exit 0 when every Done-when bound of issue 24 holds on the seed means.
import argparse
import json
import os
import resource
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def cpu_run(cmd):
    """Runs cmd; returns the child's user + system CPU seconds."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def compare(tdpm, test, ref, crop=None):
    cmd = [tdpm, "compare", test, ref, "--json", "--salt"]
    if crop:
        cmd += ["--crop", "%d,%d,%d,%d" % crop]
    return json.loads(subprocess.run(cmd, check=True, capture_output=True, text=True).stdout)


def ratio(c):
    return c["mean_test"]["overall"] / max(c["mean_reference"]["overall"], 1e-30)


def blocks(tdpm, test, ref, w, h, size=32):
    out = []
    for y in range(0, h, size):
        for x in range(0, w, size):
            out.append(((x, y), ratio(compare(tdpm, test, ref, (x, y, min(size, w - x), min(size, h - y))))))
    return out


def mean_outside_band(tdpm, test, ref, w, h):
    """test/ref image means over the rows outside [0.23 h, 0.35 h)."""
    b0, b1 = int(0.23 * h), int(0.35 * h)
    st = sr = 0.0
    for y0, y1 in ((0, b0), (b1, h)):
        c = compare(tdpm, test, ref, (0, y0, w, y1 - y0))
        st += c["mean_test"]["overall"] * (y1 - y0)
        sr += c["mean_reference"]["overall"] * (y1 - y0)
    return st / sr


def render(tdpm, scene, out, args):
    return cpu_run([tdpm, "render", scene, "-q", "-t", "2", "-o", out] + args)


def sparse_part(a, tdpm, out):
    scene = os.path.join(ROOT, "scenes", "sparse-room.json")
    w, h = (int(v) for v in a.res.split("x"))
    ref = os.path.join(out, "sparse-ref-%s.exr" % a.res)
    if not os.path.exists(ref):
        print("reference: pathtrace 1024 spp at %s (once)" % a.res, flush=True)
        render(tdpm, scene, ref + ".tmp.exr", ["-m", "pathtrace", "--resolution", a.res, "--spp", "1024", "--seed", "101"])
        os.replace(ref + ".tmp.exr", ref)
    ok = True
    for label, margs in (("time", ["-m", "time"]), ("time 4d", ["-m", "time", "--search", "4d"])):
        means, bands, rels, salts, ptrels = [], [], [], [], []
        block_sum = None
        for seed in a.seeds:
            img = os.path.join(out, "sparse-%s-%d.exr" % (label.replace(" ", "-"), seed))
            cpu = render(tdpm, scene, img, margs + ["--resolution", a.res, "--seed", str(seed)] + a.extra.split())
            c = compare(tdpm, img, ref)
            b = blocks(tdpm, img, ref, w, h)
            block_sum = [v for _, v in b] if block_sum is None else [s + v for s, (_, v) in zip(block_sum, b)]
            # The path tracer at the same CPU time: 16 spp measured, scaled.
            pt16 = os.path.join(out, "sparse-pt16-%d.exr" % seed)
            cpu16 = render(tdpm, scene, pt16, ["-m", "pathtrace", "--resolution", a.res, "--spp", "16", "--seed", str(seed)])
            spp = max(1, round(16 * cpu / max(cpu16, 1e-6)))
            pt = os.path.join(out, "sparse-pteq-%d.exr" % seed)
            render(tdpm, scene, pt, ["-m", "pathtrace", "--resolution", a.res, "--spp", str(spp), "--seed", str(seed)])
            ptrel = compare(tdpm, pt, ref)["rel_mse"]["overall"]
            worst_b = max(b, key=lambda kv: abs(kv[1] - 1))
            bands.append(mean_outside_band(tdpm, img, ref, w, h))
            print("%-8s seed %d: mean %.4f (without the lamp rows %.4f) relMSE %.4f salt %.4f%% worst block %s %.4f | %.1f s; pathtrace %d spp relMSE %.4f"
                  % (label, seed, ratio(c), bands[-1], c["rel_mse"]["overall"], 100 * c["salt"]["share"], worst_b[0], worst_b[1],
                     cpu, spp, ptrel), flush=True)
            means.append(ratio(c))
            rels.append(c["rel_mse"]["overall"])
            salts.append(c["salt"]["share"])
            ptrels.append(ptrel)
        n = len(a.seeds)
        bm = [s / n for s in block_sum]
        mean, band, rel, salt, ptrel = sum(means) / n, sum(bands) / n, sum(rels) / n, sum(salts) / n, sum(ptrels) / n
        # Blocks holding lamp rows carry its pixel-sampling noise (a few % per
        # seed, in every method): judged apart.
        b0, b1 = int(0.23 * h), int(0.35 * h)
        lamp = [y < b1 and y + 32 > b0 for (x, y), _ in b]
        worst_mean = max((v for v, l in zip(bm, lamp) if not l), key=lambda v: abs(v - 1))
        worst_lamp = max((v for v, l in zip(bm, lamp) if l), key=lambda v: abs(v - 1))
        print("%-8s over %d seeds: mean %.4f (without the lamp rows %.4f), worst block (seed-averaged) %.4f "
              "(of those holding lamp rows %.4f), salt %.4f%%, relMSE %.4f = %.2fx pathtrace's at equal time"
              % (label, n, mean, band, worst_mean, worst_lamp, 100 * salt, rel, rel / ptrel), flush=True)
        ok = ok and abs(mean - 1) <= 0.02 and abs(worst_mean - 1) <= 0.02 and salt <= 0.0005 and rel <= 1.5 * ptrel
        if n >= 12:
            ok = ok and abs(worst_lamp - 1) <= 0.02
        else:
            print("%-8s blocks holding the lamp rows: not bounded with fewer than 12 seeds" % label, flush=True)
    return ok


def room_part(a, tdpm, out):
    d = json.load(open(os.path.join(ROOT, "scenes", "static-room.json")))
    for o in d["objects"]:
        if o["name"] == "tall_block":
            o["motion"] = [{"time": 0, "translate": [-0.4, 0, 0]}, {"time": 1, "translate": [0.4, 0, 0]}]
    scene = os.path.join(out, "moving-room.json")
    with open(scene, "w") as f:
        json.dump(d, f, indent=1)
    ref = os.path.join(out, "room-ref-80x60.exr")
    if not os.path.exists(ref):
        print("reference: pathtrace 4096 spp at 80x60 (once)", flush=True)
        render(tdpm, scene, ref + ".tmp.exr", ["-m", "pathtrace", "--resolution", "80x60", "--spp", "4096", "--seed", "101"])
        os.replace(ref + ".tmp.exr", ref)
    ok = True
    regions = (("whole", None), ("static x<40", (0, 0, 40, 60)), ("block", (40, 20, 30, 30)))
    for g in (2000, 20000, 100000):
        res = {}
        for m in ("time", "standard"):
            vals = {r: 0.0 for r, _ in regions}
            for seed in a.seeds:
                img = os.path.join(out, "room-%s-%d-%d.exr" % (m, g, seed))
                render(tdpm, scene, img, ["-m", m, "--fixed-budget", "--resolution", "80x60", "--spp", "8", "--seed",
                                          str(seed), "--global-direct", "--gather", "0", "--photons", "0",
                                          "--global-photons", str(g)])
                for r, crop in regions:
                    vals[r] += ratio(compare(tdpm, img, ref, crop)) / len(a.seeds)
            res[m] = vals
        # The Done-when's literal ratio, time over standard (image means, seed
        # means): not a bound here, since standard is wrong on the moving block
        # by design (docs/photon-map.md); printed so that it is on record.
        ts = sum(ratio(compare(tdpm, os.path.join(out, "room-time-%d-%d.exr" % (g, seed)),
                               os.path.join(out, "room-standard-%d-%d.exr" % (g, seed)))) for seed in a.seeds) / len(a.seeds)
        print("%6d global photons: time / standard, image means: %.4f" % (g, ts), flush=True)
        print("%6d global photons, over pathtrace (seed means): %s" % (g, "; ".join(
            "%s %s" % (m, ", ".join("%s %.4f" % (r, res[m][r]) for r, _ in regions)) for m in res)), flush=True)
        ok = ok and abs(res["time"]["whole"] - 1) <= 0.02 and abs(res["standard"]["static x<40"] - 1) <= 0.02
    return ok


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("tdpm")
    p.add_argument("out")
    p.add_argument("--part", choices=("sparse", "room", "all"), default="all")
    p.add_argument("--seeds", type=int, nargs="+", default=list(range(1, 13)))
    p.add_argument("--res", default="160x120")
    p.add_argument("--extra", default="")
    a = p.parse_args()
    os.makedirs(a.out, exist_ok=True)
    ok = True
    if a.part in ("room", "all"):
        ok = room_part(a, a.tdpm, a.out) and ok
    if a.part in ("sparse", "all"):
        ok = sparse_part(a, a.tdpm, a.out) and ok
    print("issue 24 bounds:", "all hold" if ok else "NOT all hold")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
