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
but shr; the reference is always needed unless --skip-ref)."""
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
        if "seq" in variants:
            times["seq"] = cpu_run([TDPM, "render", a.scene, "-o", out + "/seq/f_####.exr", "--frame-range", rng]
                                   + seq_args + win + own)
        if "shr" in variants:
            times["shr"] = cpu_run([TDPM, "render", a.scene, "-o", out + "/shr/f_####.exr", "--frame-range", rng]
                                   + seq_args + win + a.shr_args.split())
        if "ind" in variants:
            times["ind"] = cpu_run([TDPM, "render", a.scene, "-o", out + "/ind/f_####.exr", "--frame-range", rng,
                                    "--independent-frames"] + seq_args + win + own)
        subprocess.run([sys.executable, os.path.join(ROOT, "bench", "animation", "single_frames.py"), a.scene, single,
                        str(a.first), str(a.last)], check=True)
        for variant, seed in (("sep", None), ("same", 1)):
            if variant not in variants:
                continue
            os.makedirs(out + "/" + variant, exist_ok=True)
            total = 0.0
            for i in frames:
                s = str(1000 + i) if seed is None else str(seed)
                total += cpu_run([TDPM, "render", "%s/frame_%04d.json" % (single, i), "-o",
                                  "%s/%s/f_%04d.exr" % (out, variant, i), "--seed", s, "--fixed-budget"] + seq_args)
            times[variant] = total
        json.dump(times, open(tfile, "w"))
    print("scene %s frames %s at %s, spp %d, photons %d + %d global per frame; reference x%d photons, x4 spp"
          % (a.scene, rng, a.res, a.spp, a.photons, a.global_photons, a.ref_mult))
    for crop in a.crop:
        ref_flicker = [compare("%s/ref/f_%04d.exr" % (out, i + 1), "%s/ref/f_%04d.exr" % (out, i), crop)["rmse"]["overall"]
                       for i in frames[:-1]]
        print("crop %s: reference flicker %.5f" % (crop, sum(ref_flicker) / len(ref_flicker)))
        print("%-5s %10s %12s %14s %12s %12s %10s %10s" % ("", "CPU s", "relMSE mean", "relMSE median", "relMSE crop",
                                                       "flicker", "thr mean", "thr med"))
        rows = {}
        for v in ("seq", "ind", "sep", "same", "shr"):
            if not os.path.exists("%s/%s/f_%04d.exr" % (out, v, frames[-1])):
                continue
            rel = [compare("%s/%s/f_%04d.exr" % (out, v, i), "%s/ref/f_%04d.exr" % (out, i))["rel_mse"]["overall"]
                   for i in frames]
            relc = [compare("%s/%s/f_%04d.exr" % (out, v, i), "%s/ref/f_%04d.exr" % (out, i), crop)["rel_mse"]["overall"]
                    for i in frames]
            fl = [compare("%s/%s/f_%04d.exr" % (out, v, i + 1), "%s/%s/f_%04d.exr" % (out, v, i), crop)["rmse"]["overall"]
                  for i in frames[:-1]]
            med = sorted(rel)[len(rel) // 2]
            rows[v] = (times.get(v, float("nan")), sum(rel) / len(rel), med, sum(relc) / len(relc), sum(fl) / len(fl))
        for v, (t, mean, med, crop_err, fl) in rows.items():
            thr = lambda i: (rows["sep"][0] * rows["sep"][i]) / (t * (mean if i == 1 else med)) if "sep" in rows else float("nan")
            print("%-5s %10.2f %12.6f %14.6f %12.6f %12.5f %10.3f %10.3f" % (v, t, mean, med, crop_err, fl, thr(1), thr(2)))

main()
