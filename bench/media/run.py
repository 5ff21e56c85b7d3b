#!/usr/bin/env python3
# bench/media/run.py — issue 25's media measurements (minutes, not a CTest;
# bench/README.md "Media"). Every part that needs a photon method in media
# first asks the binary with a 1-spp render: while `time`/`progressive`
# refuse media ("need -m pathtrace") the part is skipped with that message,
# and once they render media the same command measures them.
#
#   run.py TDPM OUT [--part all|ref|caustic|progressive|memory|beam|majorant]
#          [--base BASE_TDPM] [--ref-spp 4096] [--pt-spp 64] [--res 240x160]
#
# ref:         a converged volumetric `pathtrace` of scenes/fog-glass-ball.json
#              at REF_SPP, cached in OUT/ref_<res>_<spp>.exr (never committed).
# caustic:     `-m pathtrace` at PT_SPP, its CPU time (user + system of the
#              child), then `-m time` progressive with that --time-limit
#              (equal time); relMSE of both against the reference on the
#              whole image and on the caustic crop (the cone under the ball),
#              by `tdpm compare --json`. Target (issue 25): time >= 10x lower.
# progressive: `--progressive` at time limits 8, 16, 32, 64 s: relMSE against
#              the reference, and the log-log slope of relMSE over time
#              (least squares).
# memory:      `-m time --stats` on the scene: the volume map's bytes per
#              photon as printed (target <= 24, including tree and radius).
# beam:        the library-level beam-vs-march benchmark (bench_volume.cpp)
#              through TDPM's sibling bench/tdpm_bench, if built.
# majorant:    bench/media/smoke_blob.py's sparse 64^3 blob (still and
#              moving), `-m pathtrace` -t 1, HEAD against --base: CPU time,
#              median of 3 interleaved runs each, and the two images' relMSE
#              against each other (the same picture up to noise).
import argparse
import json
import math
import os
import resource
import statistics
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
SCENE = os.path.join(ROOT, "scenes", "fog-glass-ball.json")
# The volumetric caustic at 240x160: the converging cone between the ball
# (rows ~45-85 over the shutter) and the floor, x over the ball's sweep.
CAUSTIC_CROP = (70, 60, 100, 70)


def cpu_run(cmd):
    """Runs cmd; returns (returncode, stdout+stderr, child CPU seconds)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return p.returncode, p.stdout, cpu


def scale(crop, res):
    w, h = (int(v) for v in res.split("x"))
    sx, sy = w / 240.0, h / 160.0
    x, y, cw, ch = crop
    return "%d,%d,%d,%d" % (x * sx, y * sy, cw * sx, ch * sy)


def rel_mse(tdpm, test, ref, crop=None):
    cmd = [tdpm, "compare", "--json", test, ref] + (["--crop", crop] if crop else [])
    out = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, check=True).stdout
    return float(json.loads(out)["rel_mse"]["overall"])


def refuses_media(tdpm, method, out, extra=()):
    """None when `method` renders a media scene; else the binary's message.
    Probed at a fixed budget: main at 9bc26f3 refuses `-m time` with media
    but renders `-m time --progressive` *without* them (a missing refusal on
    the progressive path), so a progressive probe would measure a fog-less
    image."""
    probe = os.path.join(out, "probe_%s.exr" % method)
    rc, text, _ = cpu_run([tdpm, "render", SCENE, "-m", method, "--spp", "1", "--resolution", "24x16", "-q",
                           "-o", probe] + list(extra))
    return None if rc == 0 else text.strip().splitlines()[-1] if text.strip() else "exit %d" % rc


def reference(a):
    ref = os.path.join(a.out, "ref_%s_%d.exr" % (a.res, a.ref_spp))
    if not os.path.exists(ref):
        print("reference: pathtrace %s spp at %s (cached in %s) ..." % (a.ref_spp, a.res, ref), flush=True)
        rc, text, cpu = cpu_run([a.tdpm, "render", SCENE, "-m", "pathtrace", "--spp", str(a.ref_spp),
                                 "--resolution", a.res, "-q", "-o", ref])
        if rc != 0:
            raise SystemExit("reference render failed:\n" + text)
        print("reference: %.0f s CPU" % cpu)
    return ref


def caustic(a, ref):
    pt = os.path.join(a.out, "pt_%d.exr" % a.pt_spp)
    rc, text, cpu = cpu_run([a.tdpm, "render", SCENE, "-m", "pathtrace", "--spp", str(a.pt_spp),
                             "--resolution", a.res, "-q", "-o", pt, "--seed", "7"])
    if rc != 0:
        raise SystemExit(text)
    crop = scale(CAUSTIC_CROP, a.res)
    e_pt, c_pt = rel_mse(a.tdpm, pt, ref), rel_mse(a.tdpm, pt, ref, crop)
    print("caustic: pathtrace %d spp: %.1f s CPU, relMSE image %.4g, caustic crop %s %.4g" % (a.pt_spp, cpu, e_pt, crop, c_pt))
    why = refuses_media(a.tdpm, "time", a.out)
    if why:
        print("caustic: `-m time` skipped, the binary refuses media: %s" % why)
        return
    tm = os.path.join(a.out, "time_eq.exr")
    rc, text, cpu_t = cpu_run([a.tdpm, "render", SCENE, "-m", "time", "--progressive", "--time-limit", "%.1f" % cpu,
                               "-t", "1", "--resolution", a.res, "-q", "-o", tm, "--seed", "7"])
    if rc != 0:
        raise SystemExit(text)
    e_t, c_t = rel_mse(a.tdpm, tm, ref), rel_mse(a.tdpm, tm, ref, crop)
    print("caustic: time, --time-limit %.1f s (-t 1): %.1f s CPU, relMSE image %.4g, caustic crop %.4g" % (cpu, cpu_t, e_t, c_t))
    print("caustic: pathtrace / time relMSE at equal time: image %.2fx, caustic %.2fx (target >= 10x)" % (e_pt / e_t, c_pt / c_t))


def progressive(a, ref):
    why = refuses_media(a.tdpm, "time", a.out)
    if why:
        print("progressive: skipped, the binary refuses media: %s" % why)
        return
    pts = []
    for limit in (8, 16, 32, 64):
        img = os.path.join(a.out, "prog_%d.exr" % limit)
        rc, text, cpu = cpu_run([a.tdpm, "render", SCENE, "-m", "time", "--progressive", "--time-limit", str(limit),
                                 "-t", "1", "--resolution", a.res, "-q", "-o", img])
        if rc != 0:
            raise SystemExit(text)
        e = rel_mse(a.tdpm, img, ref, scale(CAUSTIC_CROP, a.res))
        pts.append((cpu, e))
        print("progressive: limit %d s: %.1f s CPU, caustic relMSE %.4g" % (limit, cpu, e), flush=True)
    xs, ys = [math.log(c) for c, _ in pts], [math.log(e) for _, e in pts]
    mx, my = statistics.mean(xs), statistics.mean(ys)
    slope = sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sum((x - mx) ** 2 for x in xs)
    print("progressive: log-log slope of relMSE over CPU time %.3f (a consistent estimator falls; -1 is Monte Carlo's rate)" % slope)


def memory(a):
    why = refuses_media(a.tdpm, "time", a.out)
    if why:
        print("memory: skipped, the binary refuses media: %s" % why)
        return
    rc, text, _ = cpu_run([a.tdpm, "render", SCENE, "-m", "time", "--spp", "1", "--resolution", a.res, "--stats", "-q",
                           "-o", os.path.join(a.out, "stats.exr")])
    lines = [l for l in text.splitlines() if "byte" in l.lower() or "volume" in l.lower()]
    print("memory: --stats lines naming bytes or volume:\n  " + "\n  ".join(lines or ["(none)"]))


def beam(a):
    exe = os.path.join(os.path.dirname(os.path.abspath(a.tdpm)), "bench", "tdpm_bench")
    if not os.path.exists(exe):
        print("beam: %s not built (cmake --build build --target tdpm_bench); skipped" % exe)
        return
    subprocess.run([exe, "--benchmark_filter=BM_Volume", "--benchmark_min_time=0.1", "--benchmark_repetitions=3",
                    "--benchmark_report_aggregates_only=true"], check=True)


def majorant(a):
    if not a.base:
        print("majorant: needs --base BASE_TDPM (a binary without the majorant grid); skipped")
        return
    for moving in (False, True):
        scene = os.path.join(a.out, "blob%s.json" % ("_moving" if moving else ""))
        subprocess.run([sys.executable, os.path.join(HERE, "smoke_blob.py"), scene] + (["--moving"] if moving else []),
                       check=True)
        times = {"base": [], "head": []}
        for rep in range(3):
            for name, exe in (("base", a.base), ("head", a.tdpm)):
                img = os.path.join(a.out, "blob_%s_%d.exr" % (name, int(moving)))
                rc, text, cpu = cpu_run([exe, "render", scene, "-m", "pathtrace", "-t", "1", "-q", "-o", img])
                if rc != 0:
                    raise SystemExit(text)
                times[name].append(cpu)
        b, h = statistics.median(times["base"]), statistics.median(times["head"])
        d = rel_mse(a.tdpm, os.path.join(a.out, "blob_head_%d.exr" % int(moving)),
                    os.path.join(a.out, "blob_base_%d.exr" % int(moving)))
        print("majorant: %s blob, pathtrace 160x120 16 spp -t 1: base %s s, head %s s CPU (medians %.2f / %.2f): %.2fx; "
              "relMSE head vs base %.4g" % ("moving" if moving else "still", " ".join("%.2f" % t for t in times["base"]),
                                            " ".join("%.2f" % t for t in times["head"]), b, h, b / h, d), flush=True)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("tdpm")
    ap.add_argument("out")
    ap.add_argument("--part", default="all", choices=["all", "ref", "caustic", "progressive", "memory", "beam", "majorant"])
    ap.add_argument("--base")
    ap.add_argument("--ref-spp", type=int, default=4096)
    ap.add_argument("--pt-spp", type=int, default=64)
    ap.add_argument("--res", default="240x160")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    subprocess.run(["sh", "-c", "lscpu | grep -E 'Model name|^CPU\\(s\\)'; uptime"])
    part = a.part
    if part in ("all", "majorant"):
        majorant(a)
    if part in ("all", "beam"):
        beam(a)
    if part in ("all", "memory"):
        memory(a)
    if part in ("all", "ref", "caustic", "progressive"):
        ref = reference(a)
        if part in ("all", "caustic"):
            caustic(a, ref)
        if part in ("all", "progressive"):
            progressive(a, ref)


if __name__ == "__main__":
    main()
