#!/usr/bin/env python3
"""bench/animation/single_frames.py SCENE.json OUTDIR FIRST LAST

Writes OUTDIR/frame_NNNN.json: frame i of an animated scene as a one-frame
scene (camera.shutter = frame i's shutter, no "animation" block), every
keyframed motion replaced by two keyframes at the shutter's ends with the
poses interpolated there: what a user without animation support renders
24 times. Translation and scale are linear; rotation is linear in angle,
which is slerp for keyframes sharing one axis (true of the shipped scenes;
the script refuses others)."""
import copy, json, sys

def lerp(a, b, u):
    return [x + (y - x) * u for x, y in zip(a, b)]

def pose_at(keys, t):
    if t <= keys[0]["time"]:
        return copy.deepcopy({k: v for k, v in keys[0].items() if k != "time"})
    if t >= keys[-1]["time"]:
        return copy.deepcopy({k: v for k, v in keys[-1].items() if k != "time"})
    for a, b in zip(keys, keys[1:]):
        if a["time"] <= t <= b["time"]:
            u = (t - a["time"]) / (b["time"] - a["time"])
            p = {}
            if "translate" in a or "translate" in b:
                p["translate"] = lerp(a.get("translate", [0, 0, 0]), b.get("translate", [0, 0, 0]), u)
            if "scale" in a or "scale" in b:
                sa, sb = a.get("scale", 1), b.get("scale", 1)
                sa = sa if isinstance(sa, list) else [sa] * 3
                sb = sb if isinstance(sb, list) else [sb] * 3
                p["scale"] = lerp(sa, sb, u)
            if "rotate" in a or "rotate" in b:
                ra, rb = a.get("rotate"), b.get("rotate")
                axis = (ra or rb)["axis"]
                if ra and rb and ra["axis"] != rb["axis"]:
                    sys.exit("keyframes rotate about different axes; not supported")
                aa = ra["angle"] if ra else 0.0
                ab = rb["angle"] if rb else 0.0
                p["rotate"] = {"axis": axis, "angle": aa + (ab - aa) * u}
            return p

def main():
    scene_path, outdir, first, last = sys.argv[1], sys.argv[2], int(sys.argv[3]), int(sys.argv[4])
    src = json.load(open(scene_path))
    anim = src.pop("animation")
    fps, angle = anim["fps"], anim.get("shutter_angle", 180)
    for i in range(first, last + 1):
        t0 = i / fps
        t1 = t0 + angle / 360.0 / fps
        s = copy.deepcopy(src)
        s["camera"]["shutter"] = [t0, t1]
        for o in s.get("objects", []) + s.get("lights", []):
            if "motion" in o:
                keys = o["motion"]
                o["motion"] = [dict(time=t0, **pose_at(keys, t0)), dict(time=t1, **pose_at(keys, t1))]
        if "motion" in s["camera"]:
            sys.exit("camera motion not supported")
        json.dump(s, open("%s/frame_%04d.json" % (outdir, i), "w"))

main()
