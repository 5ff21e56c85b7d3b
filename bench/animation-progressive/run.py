#!/usr/bin/env python3
"""bench/animation-progressive/run.py — progressive animation frames with
the time-invariant photons of a block shared per pass (issue 26,
docs/animation.md "Progressive frames sharing time-invariant photons")
against the same frames each rendered progressively alone. Usage (from the
repository root, after a Release build):

  bench/animation-progressive/run.py SCENE FIRST LAST --res 96x54 --spp 4 \\
      --photons 20000 --global-photons 5000 --passes 8 --seeds 4 \\
      --variants alone,shared,shared1 --out /tmp/bench-aprog

Renders, every timed run with -t 1 and its user CPU seconds measured:
  ref      the frames alone (--shared-photons 0) with --ref-passes passes
           (default 8 x --passes), seed 99, -t 2 (not timed): the converged
           reference of the progressive estimate
  alone    --shared-photons 0: each frame its own passes (the old path)
  shared   the defaults (--shared-photons 0.5 --moving-photons 0.5)
  shared1  --shared-photons 1 --moving-photons 1 (each pass at a frame's
           photon density)
interleaved per seed (alone, shared, shared1 for seed 1, then seed 2, ...),
and prints per variant the mean CPU seconds per realisation, the mean and
median relMSE over every frame of every seed against the reference, and
the throughput at equal error against `alone`: (T_alone e_alone) /
(T_v e_v), for the mean and the median.

--slope FRAME renders that frame alone (its block's sets traced for it
alone, the same image as in the sequence) at 2, 4, 8, 16 passes for each
variant and seed and prints the least-squares slope of log relMSE against
log passes (the kernel bias against the reference counts in it)."""
import argparse, math, os, statistics, subprocess, sys, json

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
TDPM = os.environ.get("TDPM", os.path.join(ROOT, "build", "tdpm"))
ARGS = {"alone": ["--shared-photons", "0"],
        "shared": ["--shared-photons", "0.5", "--moving-photons", "0.5"],
        "shared1": ["--shared-photons", "1", "--moving-photons", "1"]}


def cpu_run(args):
    t0 = os.times()
    subprocess.run(args, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    t1 = os.times()
    return t1.children_user - t0.children_user


def rel_mse(test, ref):
    out = subprocess.run([TDPM, "compare", test, ref, "--json"], check=True, capture_output=True, text=True).stdout
    return json.loads(out)["rel_mse"]["overall"]


def slope(xs, ys):
    lx, ly = [math.log(x) for x in xs], [math.log(y) for y in ys]
    mx, my = sum(lx) / len(lx), sum(ly) / len(ly)
    return sum((a - mx) * (b - my) for a, b in zip(lx, ly)) / sum((a - mx) ** 2 for a in lx)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("scene")
    ap.add_argument("first", type=int)
    ap.add_argument("last", type=int)
    ap.add_argument("--res", default="96x54")
    ap.add_argument("--spp", type=int, default=4)
    ap.add_argument("--photons", type=int, default=20000)
    ap.add_argument("--global-photons", type=int, default=5000)
    ap.add_argument("--passes", type=int, default=8)
    ap.add_argument("--ref-passes", type=int, default=0)
    ap.add_argument("--window", type=int, default=4)
    ap.add_argument("--seeds", type=int, default=4)
    ap.add_argument("--variants", default="alone,shared,shared1")
    ap.add_argument("--slope", type=int, default=-1)
    ap.add_argument("--skip-ref", action="store_true")
    ap.add_argument("--out", default="/tmp/bench-aprog")
    a = ap.parse_args()
    variants = a.variants.split(",")
    common = ["--progressive", "--resolution", a.res, "--spp", str(a.spp), "--photons", str(a.photons),
              "--global-photons", str(a.global_photons), "--window", str(a.window), "-q"]
    rng = "%d-%d" % (a.first, a.last)
    ref = os.path.join(a.out, "ref")
    if not a.skip_ref:
        subprocess.run([TDPM, "render", a.scene, "-o", ref + "/f_####.exr", "--frame-range", rng, "--seed", "99",
                        "--passes", str(a.ref_passes or 8 * a.passes), "-t", "2"] + common + ARGS["alone"],
                       check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    frames = range(a.first, a.last + 1)
    times = {v: [] for v in variants}
    errs = {v: [] for v in variants}
    for k in range(1, a.seeds + 1):
        for v in variants:
            d = os.path.join(a.out, "%s.%d" % (v, k))
            times[v].append(cpu_run([TDPM, "render", a.scene, "-o", d + "/f_####.exr", "--frame-range", rng,
                                     "--seed", str(k), "--passes", str(a.passes), "-t", "1"] + common + ARGS[v]))
            errs[v] += [rel_mse("%s/f_%04d.exr" % (d, i), "%s/f_%04d.exr" % (ref, i)) for i in frames]
    print("scene %s frames %s at %s, spp %d, photons %d + %d global per pass, %d passes, --window %d; "
          "reference %d passes; %d seed(s)" % (a.scene, rng, a.res, a.spp, a.photons, a.global_photons, a.passes,
                                               a.window, a.ref_passes or 8 * a.passes, a.seeds))
    base = variants[0]
    tb, mb, db = statistics.mean(times[base]), statistics.mean(errs[base]), statistics.median(errs[base])
    for v in variants:
        t, m, md = statistics.mean(times[v]), statistics.mean(errs[v]), statistics.median(errs[v])
        print("%-8s CPU %7.2f s  relMSE mean %.5f median %.5f  throughput vs %s: %.2fx (median %.2fx)"
              % (v, t, m, md, base, tb * mb / (t * m), tb * db / (t * md)))
    if a.slope >= 0:
        for v in variants:
            ps, es = [2, 4, 8, 16], []
            for p in ps:
                e = []
                for k in range(1, a.seeds + 1):
                    d = os.path.join(a.out, "slope-%s-%d.%d" % (v, p, k))
                    subprocess.run([TDPM, "render", a.scene, "-o", d + "/f_####.exr", "--frame-range",
                                    "%d-%d" % (a.slope, a.slope), "--seed", str(k), "--passes", str(p), "-t", "2"]
                                   + common + ARGS[v], check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
                    e.append(rel_mse("%s/f_%04d.exr" % (d, a.slope), "%s/f_%04d.exr" % (ref, a.slope)))
                es.append(statistics.mean(e))
            print("%-8s frame %d relMSE at passes %s: %s; log-log slope %.2f"
                  % (v, a.slope, ps, ", ".join("%.5f" % e for e in es), slope(ps, es)))


if __name__ == "__main__":
    sys.exit(main())
