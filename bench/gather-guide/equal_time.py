#!/usr/bin/env python3
# bench/gather-guide/equal_time.py — the final gather's guide at equal time
# (issue 24; docs/photon-map.md "The gather guide's cost"): relMSE x CPU
# seconds of `-m time` renders with the guide on, off, and under extra
# environment settings, against a path-traced reference (made once, cached
# in OUT), medians over seeds, the configurations interleaved per seed so
# that the machine's load falls on each alike.
#
#   equal_time.py TDPM OUT [--scenes cube-caustic static-room sparse-room]
#                 [--res 80x60] [--seeds 1 2 3] [--ref-spp 4096]
#                 [--config NAME=[ENV=VALUE ...] [@BINARY] ARGS ...]
#
# CPU = user + system of the child (photon pass included: what a render
# costs). Default configs: "off" (--gather-guide off) and "on" (default);
# @BINARY renders that configuration with another tdpm (a base build), so
# base and head ratios come from one run. Results: bench/README.md.
import argparse
import json
import os
import resource
import statistics
import subprocess

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def cpu_run(cmd, env=None):
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, env=env)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("tdpm")
    ap.add_argument("out")
    ap.add_argument("--scenes", nargs="+", default=["cube-caustic", "static-room", "sparse-room"])
    ap.add_argument("--res", default="80x60")
    ap.add_argument("--seeds", nargs="+", type=int, default=[1, 2, 3])
    ap.add_argument("--ref-spp", type=int, default=4096)
    ap.add_argument("--config", nargs="*", default=["off=--gather-guide off", "on="],
                    help="NAME=ARGS; ARGS may start with ENV=VALUE words, set in the child's environment, "
                         "and then @BINARY, rendered with instead of TDPM")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    configs = []
    for c in a.config:
        name, _, rest = c.partition("=")
        words = rest.split()
        env = dict(os.environ)
        while words and "=" in words[0] and not words[0].startswith("-"):
            k, _, v = words.pop(0).partition("=")
            env[k] = v
        binary = a.tdpm
        if words and words[0].startswith("@"):
            binary = words.pop(0)[1:]
        configs.append((name, words, env, binary))
    for scene in a.scenes:
        path = os.path.join(ROOT, "scenes", scene + ".json")
        ref = os.path.join(a.out, "ref-%s-%s.exr" % (scene, a.res))
        if not os.path.exists(ref):
            cpu_run([a.tdpm, "render", path, "-q", "-t", "2", "-m", "pathtrace", "--resolution", a.res,
                     "--spp", str(a.ref_spp), "--seed", "101", "-o", ref + ".tmp.exr"])
            os.replace(ref + ".tmp.exr", ref)
        res = {c[0]: ([], []) for c in configs}
        for seed in a.seeds:
            for name, args, env, binary in configs:
                img = os.path.join(a.out, "%s-%s-%d.exr" % (scene, name, seed))
                cpu = cpu_run([binary, "render", path, "-q", "-t", "1", "-m", "time", "--resolution", a.res,
                               "--seed", str(seed), "-o", img] + args, env)
                c = json.loads(subprocess.run([a.tdpm, "compare", img, ref, "--json", "--salt"], check=True,
                                              capture_output=True, text=True).stdout)
                rel = c["rel_mse"]["overall"]
                res[name][0].append(rel)
                res[name][1].append(cpu)
                print("%-13s %-10s seed %d: relMSE %.5f  CPU %.2f s  relMSE x CPU %.5f  salt %.3f%%"
                      % (scene, name, seed, rel, cpu, rel * cpu, 100 * c["salt"]["share"]), flush=True)
        base = None
        for name, _, _, _ in configs:
            rels, cpus = res[name]
            prod = statistics.median([r * t for r, t in zip(rels, cpus)])
            base = base or prod
            print("%-13s %-10s median relMSE %.5f  CPU %.2f s  relMSE x CPU %.5f (%.2fx %s)"
                  % (scene, name, statistics.median(rels), statistics.median(cpus), prod, prod / base,
                     configs[0][0]), flush=True)


if __name__ == "__main__":
    main()
