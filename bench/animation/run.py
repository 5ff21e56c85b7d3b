#!/usr/bin/env python3
"""bench/animation/run.py — throughput at equal error and flicker of an
animation rendered from one photon timeline (issue 12), against separate
single-frame runs. Usage (from the repository root, after a Release build):

  bench/animation/run.py SCENE FIRST LAST --res 96x54 --spp 4 --photons 20000 \
      --global-photons 5000 --ref-mult 8 --crop X,Y,W,H --out /tmp/bench-anim

Runs, all with -t 2, timing CPU seconds (user + system: the machine is shared):
  ref   the sequence with ref-mult x the photons and 4x the spp (seed 99): the
        per-frame converged reference
  seq   the sequence (default: photon paths share random numbers across frames)
  ind   the sequence with --independent-frames
  sep   each frame alone: bench/animation/single_frames.py writes one-frame
        scenes (camera.shutter = the frame's shutter), rendered one process
        each, seed 1000 + i (independent maps)
  same  the same single-frame runs, all with seed 1 (what a user would get)
  shr   the sequence with time-invariant photons shared per block of --window
        frames (issue 26): --shared-photons / --moving-photons from --shr-args
        ("seq" is then rendered with --shared-photons 0: every frame its own)
and prints, per variant, total CPU seconds, mean relMSE against the
reference, and flicker: the mean over consecutive frames of the RMSE
between frame i+1 and frame i inside --crop (a region whose true image does
not change; the reference's own flicker there is printed too).

Throughput at equal error, against sep: (T_sep relMSE_sep) / (T_v relMSE_v),
i.e. the ratio of 1 / (time x error), which is the ratio of times at equal
error where relMSE falls as 1 / time (printed for the mean and the median).
--variants picks which of seq, ind, sep, same, shr to render (default all
but shr; the reference is always needed unless --skip-ref).

--seeds N renders N realisations: the sequences with --seed 1..N (into
seq, seq.1, ...), the single frames with seeds 1000 + i + 100 k, and pools
the errors of every frame of every realisation (CPU seconds: the mean per
realisation). One seed is one realisation, not one per frame: a sequence's
frames share random numbers (common random numbers, docs/animation.md
section 4), so its frames' errors move together."""
import argparse, json, os, shutil, subprocess, sys, time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
TDPM = os.environ.get("TDPM", os.path.join(ROOT, "build", "tdpm"))


def cpu_run(args):
    t0 = os.times()
    subprocess.run(args, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    t1 = os.times()
    return (t1.children_user - t0.children_user) + (t1.children_system - t0.children_system)


def compare(test, ref, crop=None):
    args = [TDPM, "compare", test, ref, "--json"]
    if crop:
        args += ["--crop", crop]
    out = subprocess.run(args, check=True, capture_output=True, text=True).stdout
    return json.loads(out)


def vdir(out, v, k):
    """Realisation k of variant v (k = 0: the directory of a one-seed run)."""
    return "%s/%s" % (out, v) if k == 0 else "%s/%s.%d" % (out, v, k)


def render_variants(a, k, variants, rng, frames, seq_args, win, own, single, out, times):
    """Realisation k: the sequences with --seed k + 1, the single frames with seeds 1000 + i + 100 k."""
    seed = ["--seed", str(k + 1)]
    def put(v, t):
        if not isinstance(times.get(v), dict):
            times[v] = {}  # a one-seed run's times.json held a number
        times[v][str(k)] = t
    if "seq" in variants:
        put("seq", cpu_run([TDPM, "render", a.scene, "-o", vdir(out, "seq", k) + "/f_####.exr", "--frame-range", rng]
                           + seq_args + win + own + seed))
    if "shr" in variants:
        put("shr", cpu_run([TDPM, "render", a.scene, "-o", vdir(out, "shr", k) + "/f_####.exr", "--frame-range", rng]
                           + seq_args + win + a.shr_args.split() + seed))
    if "ind" in variants:
        put("ind", cpu_run([TDPM, "render", a.scene, "-o", vdir(out, "ind", k) + "/f_####.exr", "--frame-range", rng,
                            "--independent-frames"] + seq_args + win + own + seed))
    for variant in ("sep", "same"):
        if variant not in variants:
            continue
        d = vdir(out, variant, k)
        os.makedirs(d, exist_ok=True)
        total = 0.0
        for i in frames:
            s = str(1000 + i + 100 * k) if variant == "sep" else str(k + 1)
            total += cpu_run([TDPM, "render", "%s/frame_%04d.json" % (single, i), "-o", "%s/f_%04d.exr" % (d, i),
                              "--seed", s, "--fixed-budget"] + seq_args)
        put(variant, total)


def mean_time(times, v, seeds):
    t = times.get(v)
    if isinstance(t, dict):
        got = [t[str(k)] for k in range(seeds) if str(k) in t]
        return sum(got) / len(got) if got else float("nan")
    return t if t is not None else float("nan")  # times.json of a one-seed run before --seeds


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("scene")
    ap.add_argument("first", type=int)
    ap.add_argument("last", type=int)
    ap.add_argument("--res", default="96x54")
    ap.add_argument("--spp", type=int, default=4)
    ap.add_argument("--photons", type=int, default=20000)
    ap.add_argument("--global-photons", type=int, default=5000)
    ap.add_argument("--ref-mult", type=int, default=8)
    ap.add_argument("--crop", required=True, action="append", help="X,Y,W,H; repeat for several regions")
    ap.add_argument("--out", default="/tmp/bench-anim")
    ap.add_argument("--skip-ref", action="store_true", help="reuse the reference of an earlier run in --out")
    ap.add_argument("--metrics-only", action="store_true", help="render nothing: measure the images already in --out")
    ap.add_argument("--variants", default="seq,ind,sep,same")
    ap.add_argument("--shr-args", default="--shared-photons 1", help="flags of the shr variant (one string)")
    ap.add_argument("--window", type=int, default=4)
    ap.add_argument("--seeds", type=int, default=1,
                    help="render seq/ind/shr with seeds 1..N and sep with N seed sets (1000 + i + 100 k); errors are "
                         "pooled over all frames and seeds, CPU seconds averaged per realisation")
    a = ap.parse_args()
    out = a.out
    os.makedirs(out, exist_ok=True)
    meshes = os.path.join(os.path.dirname(os.path.abspath(a.scene)), "meshes")
    single = os.path.join(out, "single")
    os.makedirs(single, exist_ok=True)
    if os.path.isdir(meshes) and not os.path.isdir(os.path.join(single, "meshes")):
        shutil.copytree(meshes, os.path.join(single, "meshes"))
    frames = list(range(a.first, a.last + 1))
    rng = "%d-%d" % (a.first, a.last)
    common = ["--resolution", a.res, "-t", "2", "-q"]
    seq_args = common + ["--spp", str(a.spp), "--photons", str(a.photons), "--global-photons", str(a.global_photons)]
    variants = a.variants.split(",")
    win = ["--window", str(a.window)]
    # The sequence without sharing (the earlier issue's "seq").
    own = ["--shared-photons", "0"]
    times = {}
    tfile = os.path.join(out, "times.json")
    if os.path.exists(tfile):
        times = json.load(open(tfile))
    if not a.metrics_only:
        if not a.skip_ref:
            times["ref"] = cpu_run([TDPM, "render", a.scene, "-o", out + "/ref/f_####.exr", "--frame-range", rng,
                                    "--seed", "99", "--spp", str(4 * a.spp), "--photons", str(a.ref_mult * a.photons),
                                    "--global-photons", str(a.ref_mult * a.global_photons)] + common + own)
        subprocess.run([sys.executable, os.path.join(ROOT, "bench", "animation", "single_frames.py"), a.scene, single,
                        str(a.first), str(a.last)], check=True)
        for k in range(a.seeds):
            render_variants(a, k, variants, rng, frames, seq_args, win, own, single, out, times)
        json.dump(times, open(tfile, "w"))
    print("scene %s frames %s at %s, spp %d, photons %d + %d global per frame; reference x%d photons, x4 spp; %d seed(s)"
          % (a.scene, rng, a.res, a.spp, a.photons, a.global_photons, a.ref_mult, a.seeds))
    for crop in a.crop:
        ref_flicker = [compare("%s/ref/f_%04d.exr" % (out, i + 1), "%s/ref/f_%04d.exr" % (out, i), crop)["rmse"]["overall"]
                       for i in frames[:-1]]
        print("crop %s: reference flicker %.5f" % (crop, sum(ref_flicker) / len(ref_flicker)))
        print("%-5s %10s %12s %14s %12s %12s %10s %10s" % ("", "CPU s", "relMSE mean", "relMSE median", "relMSE crop",
                                                       "flicker", "thr mean", "thr med"))
        rows = {}
        for v in ("seq", "ind", "sep", "same", "shr"):
            ks = [k for k in range(a.seeds) if os.path.exists("%s/f_%04d.exr" % (vdir(out, v, k), frames[-1]))]
            if not ks:
                continue
            rel, relc, fl = [], [], []
            for k in ks:
                d = vdir(out, v, k)
                rel += [compare("%s/f_%04d.exr" % (d, i), "%s/ref/f_%04d.exr" % (out, i))["rel_mse"]["overall"]
                        for i in frames]
                relc += [compare("%s/f_%04d.exr" % (d, i), "%s/ref/f_%04d.exr" % (out, i), crop)["rel_mse"]["overall"]
                         for i in frames]
                fl += [compare("%s/f_%04d.exr" % (d, i + 1), "%s/f_%04d.exr" % (d, i), crop)["rmse"]["overall"]
                       for i in frames[:-1]]
            med = sorted(rel)[len(rel) // 2]
            rows[v] = (mean_time(times, v, a.seeds), sum(rel) / len(rel), med, sum(relc) / len(relc), sum(fl) / len(fl))
        for v, (t, mean, med, crop_err, fl) in rows.items():
            thr = lambda i: (rows["sep"][0] * rows["sep"][i]) / (t * (mean if i == 1 else med)) if "sep" in rows else float("nan")
            print("%-5s %10.2f %12.6f %14.6f %12.6f %12.5f %10.3f %10.3f" % (v, t, mean, med, crop_err, fl, thr(1), thr(2)))

main()
