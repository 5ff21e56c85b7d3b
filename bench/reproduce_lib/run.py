"""bench/reproduce_lib/run.py — running tdpm for bench/reproduce: a render
(its time and photon counts read back from the EXR's own attributes), `tdpm
compare --json` (whole image, crop, profile row), the block-averaged
measures, and the scene files (derived scenes, hashes for the caches).
ARGS (the parsed command line) and LOG (results/log.txt) are set by main."""
import hashlib
import json
import os
import shutil
import struct
import subprocess
import sys
import time

from reproduce_lib.config import BLOCK, ROOT, SCENES, TDPM

ARGS = None
LOG = None


def die(msg):
    sys.exit(f"bench/reproduce: {msg}")


def log(msg):
    print(msg, flush=True)
    if LOG:
        LOG.write(msg + "\n")
        LOG.flush()


def read_exr_attributes(path):
    """The string/int/float attributes of a scanline OpenEXR header (stdlib only)."""
    attrs = {}
    with open(path, "rb") as f:
        data = f.read(1 << 16)
    if data[:4] != b"\x76\x2f\x31\x01":
        return attrs
    pos = 8

    def cstr(p):
        e = data.index(b"\0", p)
        return data[p:e].decode("latin-1"), e + 1

    try:
        while pos < len(data) and data[pos] != 0:
            name, pos = cstr(pos)
            typ, pos = cstr(pos)
            (size,) = struct.unpack_from("<i", data, pos)
            pos += 4
            raw = data[pos:pos + size]
            pos += size
            if typ == "string":
                attrs[name] = raw.decode("utf-8", "replace")
            elif typ == "int":
                attrs[name] = struct.unpack("<i", raw)[0]
            elif typ == "float":
                attrs[name] = struct.unpack("<f", raw)[0]
    except (ValueError, struct.error):
        pass
    return attrs


def derive_scene(name, out):
    """Writes the derived scene of SCENES[name] (lights kept: derive_lights) under out/scenes/."""
    cfg = SCENES[name]
    src = os.path.join(ROOT, cfg["file"])
    with open(src) as f:
        d = json.load(f)
    d["lights"] = [l for l in d["lights"] if l.get("name") in cfg["derive_lights"]]
    for obj in d.get("objects", []):
        shape = obj.get("shape", {})
        if shape.get("file") and not os.path.isabs(shape["file"]):
            shape["file"] = os.path.join(os.path.dirname(src), shape["file"])
    os.makedirs(os.path.join(out, "scenes"), exist_ok=True)
    dst = os.path.join(out, "scenes", name + ".json")
    with open(dst, "w") as f:
        json.dump(d, f, indent=1)
    cfg["source"] = cfg["file"]
    cfg["file"] = dst
    return dst


def display(name):
    cfg = SCENES[name]
    if cfg.get("derive_lights"):
        return f"{cfg.get('source', cfg['file'])} with lights {', '.join(cfg['derive_lights'])} only"
    return cfg["file"]


def scene_block(scene_file):
    with open(os.path.join(ROOT, scene_file)) as f:
        return json.load(f)


def scene_hash(scene_file, settings):
    """sha256 of the scene file, the meshes it names, and the settings."""
    h = hashlib.sha256()
    path = os.path.join(ROOT, scene_file)
    with open(path, "rb") as f:
        h.update(f.read())
    for obj in scene_block(scene_file).get("objects", []):
        mesh = obj.get("shape", {}).get("file")
        if mesh:
            mp = os.path.join(os.path.dirname(path), mesh)
            if os.path.exists(mp):
                with open(mp, "rb") as f:
                    h.update(f.read())
    h.update(json.dumps(settings, sort_keys=True).encode())
    return h.hexdigest()


def render(scene_file, out, args, threads):
    cmd = [TDPM, "render", os.path.join(ROOT, scene_file), "-o", out,
           "--threads", str(threads), "--quiet"] + [str(a) for a in args]
    shown = " ".join(os.path.relpath(c, ROOT) if c.startswith(ROOT) else c for c in cmd)
    if ARGS.reuse and os.path.exists(out):
        attrs = read_exr_attributes(out)
        if "tdpm/render_seconds" in attrs:
            log(f"  reused {os.path.relpath(out, ROOT)} ({float(attrs['tdpm/render_seconds']):.2f} s)")
            return {"seconds": float(attrs["tdpm/render_seconds"]), "wall": None,
                    "caustic_photons": attrs.get("tdpm/caustic_photons", ""),
                    "global_photons": attrs.get("tdpm/global_photons", ""),
                    "spp": attrs.get("tdpm/spp", ""), "max_spp": attrs.get("tdpm/max_spp", "")}
    t0 = time.monotonic()
    p = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.monotonic() - t0
    shown = " ".join(os.path.relpath(c, ROOT) if c.startswith(ROOT) else c for c in cmd)
    if p.returncode != 0:
        log(f"FAILED ({p.returncode}) after {wall:.1f} s: {shown}\n{p.stderr.strip()}")
        return None
    attrs = read_exr_attributes(out)
    secs = float(attrs.get("tdpm/render_seconds", wall))
    log(f"  {secs:8.2f} s (wall {wall:6.1f} s)  {shown}")
    return {"seconds": secs, "wall": wall,
            "caustic_photons": attrs.get("tdpm/caustic_photons", ""),
            "global_photons": attrs.get("tdpm/global_photons", ""),
            "spp": attrs.get("tdpm/spp", ""), "max_spp": attrs.get("tdpm/max_spp", "")}


def compare(test, ref, crop=None, row=None, csv_path=None, plot=None):
    rel = lambda q: os.path.relpath(q, ROOT) if q else q  # noqa: E731 (shorter labels in the plots)
    test, ref, csv_path, plot = rel(test), rel(ref), rel(csv_path), rel(plot)
    cmd = [TDPM, "compare", test, ref, "--json"]
    if crop:
        cmd += ["--crop", ",".join(str(c) for c in crop)]
    if row is not None:
        cmd += ["--profile-row", str(row)]
        if csv_path:
            cmd += ["--csv", csv_path]
        if plot:
            cmd += ["--plot", plot]
    p = subprocess.run(cmd, capture_output=True, text=True, cwd=ROOT)
    if p.returncode != 0:
        log(f"compare FAILED: {' '.join(cmd)}\n{p.stderr.strip()}")
        return None
    try:
        return json.loads(p.stdout)
    except ValueError:
        log(f"compare: no JSON from {' '.join(cmd)}")
        return None


def image_size(scene_file, resolution):
    if resolution:
        w, h = resolution.lower().split("x")
        return int(w), int(h)
    w, h = scene_block(scene_file)["camera"]["resolution"]
    return int(w), int(h)


def crop_pixels(frac, w, h):
    x, y, cw, ch = frac
    return (int(round(x * w)), int(round(y * h)), max(1, int(round(cw * w))), max(1, int(round(ch * h))))


def downsample(exr, w, h):
    """exr (w x h) box-filtered to BLOCK x BLOCK pixel blocks (oiiotool), cached beside it; None without oiiotool."""
    tool = shutil.which("oiiotool")
    if not tool:
        return None
    small = exr[:-4] + f".b{BLOCK}.exr"
    if os.path.exists(small) and os.path.getmtime(small) >= os.path.getmtime(exr):
        return small
    p = subprocess.run([tool, exr, "--ch", "R,G,B", f"--resize:filter=box",
                        f"{w // BLOCK}x{h // BLOCK}", "-o", small], capture_output=True, text=True)
    return small if p.returncode == 0 else None


def metrics(test, ref, crop, w, h):
    whole = compare(test, ref)
    part = compare(test, ref, crop=crop)
    if not whole or not part:
        return None
    extra = {}
    st, sr = downsample(test, w, h), downsample(ref, w, h)
    if st and sr:
        x, y, cw, ch = crop
        bc = (x // BLOCK, y // BLOCK, max(1, -(-(x + cw) // BLOCK) - x // BLOCK),
              max(1, -(-(y + ch) // BLOCK) - y // BLOCK))
        bw, bp = compare(st, sr), compare(st, sr, crop=bc)
        if bw and bp:
            extra = {"relmse_b": bw["rel_mse"]["overall"], "relmse_b_crop": bp["rel_mse"]["overall"]}
    return {**extra,"relmse": whole["rel_mse"]["overall"], "rmse": whole["rmse"]["overall"],
            "relmse_crop": part["rel_mse"]["overall"], "rmse_crop": part["rmse"]["overall"],
            "mean_ratio_crop": (part["mean_test"]["overall"] / part["mean_reference"]["overall"]
                                if part["mean_reference"]["overall"] > 0 else float("nan"))}
