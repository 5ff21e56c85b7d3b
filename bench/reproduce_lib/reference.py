"""bench/reproduce_lib/reference.py — one scene's render arguments under a
profile (Settings: every method's, and the reference's) and its reference:
the mean of two independent halves, cached under a key of the scene and
settings, with its own error estimated from the halves."""
import json
import os
import shutil
import subprocess
import time

from reproduce_lib import run
from reproduce_lib.config import METHODS, REF_SEEDS, SCENES, TEST_SEED
from reproduce_lib.report import fmt
from reproduce_lib.run import crop_pixels, die, image_size, log, metrics, render, scene_block, scene_hash


class Settings:
    """The render arguments of one scene under one profile."""

    def __init__(self, name, prof, spp_override=None):
        self.name = name
        self.cfg = SCENES[name]
        self.prof = prof
        block = scene_block(self.cfg["file"]).get("render", {})
        self.block = block
        self.photons = self.cfg["photons"] or int(block.get("photons", 200000))
        self.frames = self.cfg["frames"] or int(block.get("frames", 8))
        self.k = self.cfg.get("k") or int(block.get("k", 100))
        self.fraction = self.cfg.get("fraction") or float(block.get("fraction", 0.5))
        self.global_photons = int(block.get("global_photons", 50000))
        self.spp = spp_override or prof["spp"] or int(block.get("spp", 16))
        self.resolution = prof["resolution"]
        self.w, self.h = image_size(self.cfg["file"], self.resolution)

    def common(self):
        a = ["--seed", TEST_SEED]
        if self.resolution:
            a += ["--resolution", self.resolution]
        return a

    def method_args(self, method, scale=1.0):
        """Arguments for one method at `scale` times the base budget (photons and spp)."""
        if method == "pathtrace":
            raise ValueError
        base, _, _ = METHODS[method]
        photons = max(1000, int(round(self.photons * scale)))
        glob = max(1000, int(round(self.global_photons * scale)))
        spp = max(1, int(round(self.spp * scale)))
        self.effective_spp = spp
        if method == "accumulation" and self.frames > 1:
            # the renderer takes max(1, spp / frames) samples in each frame
            self.effective_spp = self.frames * max(1, spp // self.frames)
        a = list(base) + self.common() + ["--spp", spp, "--photons", photons,
                                          "--global-photons", glob]
        if method == "accumulation":
            a += ["--frames", self.frames, "--k", self.k]
        elif method == "time":
            a += ["--k", self.k, "--fraction", self.fraction]
        elif method == "time-4d":
            # the same number of photons in the estimate as two-pass keeps (k_s * f)
            a += ["--k", max(1, int(round(self.k * self.fraction)))]
        else:
            a += ["--k", self.k]
        return a, photons, spp

    def reference_args(self, seed=REF_SEEDS[0]):
        """The arguments of one half of the reference (the other half: another seed)."""
        kind = self.cfg["reference"]
        a = ["--seed", seed]
        if self.resolution:
            a += ["--resolution", self.resolution]
        if kind == "pathtrace":
            spp = self.prof["ref_pt_spp"][self.name]
            a += ["-m", "pathtrace", "--spp", spp]
            desc = f"path traced, 2 x {spp} spp"
        else:
            r = self.prof["ref_acc"]
            photons = self.photons * r["photon_mult"]
            glob = self.global_photons * r["photon_mult"] // 4
            a += ["-m", "accumulation", "--frames", r["frames"], "--photons", photons,
                  "--global-photons", glob, "--spp", r["spp"], "--k", self.k]
            desc = (f"accumulation, 2 x ({r['frames']} frames, {photons:,} caustic photons, "
                    f"{r['spp']} spp) (not path traced: delta-light caustics)")
        return a, desc


def ensure_reference(st, outdir, force):
    """The reference: the mean of two independent halves (seeds REF_SEEDS), cached with a key,
    and its own error per measure estimated from the halves (bench/README.md, "References").
    Returns (exr, description, info); info["own_error"] holds the estimates."""
    tool = shutil.which("oiiotool")
    if not tool:
        die("oiiotool (OpenImageIO tools, installed by scripts/setup.sh) is needed to average the "
            "reference's two halves")
    halves_args = [st.reference_args(seed)[0] for seed in REF_SEEDS]
    desc = st.reference_args()[1]
    settings = {"args": [[str(x) for x in a] for a in halves_args], "version": 2}
    key = scene_hash(st.cfg["file"], settings)
    exr = os.path.join(outdir, "reference.exr")
    keyfile = os.path.join(outdir, "reference.key.json")
    if not force and os.path.exists(exr) and os.path.exists(keyfile):
        try:
            with open(keyfile) as f:
                old = json.load(f)
            if old.get("sha256") == key and "own_error" in old:
                log(f"  reference: cached ({desc}, {old.get('seconds', 0):.1f} s)")
                return exr, desc, old
        except (OSError, ValueError):
            pass
    halves, secs = [], 0.0
    for i, args in enumerate(halves_args):
        h = os.path.join(outdir, f"reference-half{i + 1}.exr")
        hkey = scene_hash(st.cfg["file"], {"args": [str(x) for x in args], "version": 2})
        hkeyfile = h[:-4] + ".key.json"
        r = None
        if not force and os.path.exists(h) and os.path.exists(hkeyfile):
            try:
                with open(hkeyfile) as f:
                    r = json.load(f)
                r = r if r.get("sha256") == hkey else None
            except (OSError, ValueError):
                r = None
        if r is None:
            log(f"  reference half {i + 1}: rendering ({desc})")
            r = render(st.cfg["file"], h, args, run.ARGS.threads)
            if r is None:
                die(f"the reference of {st.name} failed; see {os.path.join(outdir, '..', 'log.txt')}")
            r["sha256"] = hkey
            with open(hkeyfile, "w") as f:
                json.dump(r, f, indent=1)
        else:
            log(f"  reference half {i + 1}: cached ({r['seconds']:.1f} s)")
        halves.append((h, r))
        secs += r["seconds"]
    (h1, r1), (h2, _) = halves
    p = subprocess.run([tool, h1, "--ch", "R,G,B", h2, "--ch", "R,G,B", "--add", "--mulc", "0.5",
                        "-d", "float", "-o", exr], capture_output=True, text=True)
    if p.returncode != 0:
        die(f"oiiotool could not average the reference halves of {st.name}: {p.stderr.strip()}")
    shutil.copyfile(h1[:-4] + ".png", exr[:-4] + ".png")  # the montage shows half 1
    # Own error: for independent halves h1, h2 of one estimator, the mean's
    # error is E[(h1 - h2)^2] / 4 per pixel (README), so each measure of
    # (h1 against h2), divided by 4.
    crop = crop_pixels(st.cfg["crop"], st.w, st.h)
    m = metrics(h1, h2, crop, st.w, st.h) or {}
    own = {k: m[k] / 4.0 for k in ("relmse", "relmse_crop", "relmse_b", "relmse_b_crop") if k in m}
    info = {"sha256": key, "scene": st.cfg["file"], "settings": settings,
            "description": desc, "seconds": secs,
            "caustic_photons": sum(int(r["caustic_photons"] or 0) for _, r in halves),
            "spp": sum(int(r["spp"] or 0) for _, r in halves), "own_error": own,
            "date": time.strftime("%Y-%m-%d %H:%M:%S")}
    with open(keyfile, "w") as f:
        json.dump(info, f, indent=1)
    log(f"  reference: {secs:.1f} s; own error (halves' relMSE / 4): " +
        ", ".join(f"{k} {fmt(v)}" for k, v in own.items()))
    return exr, desc, info
