#!/usr/bin/env python3
"""raypack's Embree backend and raypack's default configuration against Embree
called directly (bench/tools/embree_direct.cpp), on the same .rays files, one
thread. Each round runs the three programs one after the other on every
scene and ray kind; the table gives medians over the rounds (docs/embree.md).

  direct best   the fastest of Embree's fast and robust modes at widths
                1/4/8/16 (coherent context where every ray shares one origin)
  backend best  the fastest row of `raypack bench --accel embree,embree-robust
                --packet 1,4,8,16` on the same file
  default       `raypack trace` with no structure named (the configuration
                raypack picks for the kind of rays)

usage: scripts/embree_check.py [--rounds N] [--res N] [--repeat R] [--build DIR]
                               [--scenes a,b] [--kinds camera,shadow,diffuse] [--threads T]
                               [--order tiles|rows]

--scenes takes the names below or any scene raypack loads (a file or
gen:NAME:SIZE), e.g. --scenes gen:tetra:10 for a million triangles.
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCENES = {
    "balls": "scenes/balls.nff",
    "mount": "scenes/mount.nff",
    "tetra": "scenes/tetra.nff",
    "teapot": "scenes/teapot.nff",
    "gears": "scenes/gears.nff",
    "bunny": "scenes/bunny.obj",
}


def run(cmd):
    done = subprocess.run(cmd, cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if done.returncode != 0:
        sys.exit(f"embree_check: {' '.join(cmd)} failed:\n{done.stderr[-2000:]}")
    return done.stdout


def direct_best(build, scene, rays, repeat):
    best = None
    for line in run([os.path.join(build, "bench", "embree_direct"), scene, rays, "--mode", "both",
                     "--repeat", str(repeat), "--json"]).splitlines():
        row = json.loads(line)
        if best is None or row["mrays_per_s_median"] > best[0]:
            best = (row["mrays_per_s_median"], f'{row["mode"]} /{row["packet"]}')
    return best


def backend_best(build, scene, rays, repeat, out, threads):
    run([os.path.join(build, "raypack"), "bench", scene, "--rays-file", rays, "--accel", "embree,embree-robust",
         "--packet", "1,4,8,16", "--threads", str(threads), "--repeat", str(repeat), "--json", out])
    with open(out) as f:
        rows = json.load(f)
    row = max(rows, key=lambda r: r["mrays_per_s_median"])
    return row["mrays_per_s_median"], f'{row["accel"]} /{row["packet"]}'


def default_config(build, scene, rays, repeat, threads):
    row = json.loads(run([os.path.join(build, "raypack"), "trace", scene, "--rays", rays, "--threads", str(threads),
                          "--repeat", str(repeat), "--json"]).strip().splitlines()[-1])
    return row["mrays_per_s_median"], f'{row["accel"]} /{row["packet"]}'


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--res", type=int, default=1024)
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--scenes", default="bunny,tetra,balls")
    ap.add_argument("--kinds", default="camera,shadow,diffuse")
    ap.add_argument("--order", choices=["tiles", "rows"], default="tiles",
                    help="pixel order of the ray sets (raypack rays --order; docs/rays.md)")
    ap.add_argument("--threads", type=int, default=1,
                    help="threads for the backend and raypack; embree_direct runs one thread, so above 1 it is left out")
    args = ap.parse_args()
    scenes = args.scenes.split(",")
    kinds = args.kinds.split(",")
    for s in scenes:
        if s not in SCENES and not os.path.exists(s) and not s.startswith("gen:"):
            sys.exit(f"embree_check: unknown scene '{s}' (expected {', '.join(SCENES)})")
    results = {}
    with tempfile.TemporaryDirectory() as tmp:
        files = {}
        for s in scenes:
            for k in kinds:
                files[s, k] = os.path.join(tmp, f"{os.path.basename(s).replace(':', '_')}-{k}.rays")
                run([os.path.join(args.build, "raypack"), "rays", SCENES.get(s, s), "--kind", k, "--res", str(args.res),
                     str(args.res), "--order", args.order, "-o", files[s, k]])
        for r in range(args.rounds):
            for s in scenes:
                for k in kinds:
                    cell = results.setdefault((s, k), {"direct": [], "backend": [], "default": []})
                    d = (direct_best(args.build, SCENES.get(s, s), files[s, k], args.repeat) if args.threads == 1
                         else (0.0, "-"))
                    b = backend_best(args.build, SCENES.get(s, s), files[s, k], args.repeat, os.path.join(tmp, "b.json"),
                                     args.threads)
                    f = default_config(args.build, SCENES.get(s, s), files[s, k], args.repeat, args.threads)
                    cell["direct"].append(d)
                    cell["backend"].append(b)
                    cell["default"].append(f)
                    print(f"round {r + 1}: {s} {k}: direct {d[0]:.1f} ({d[1]}), backend {b[0]:.1f} ({b[1]}), "
                          f"default {f[0]:.1f} ({f[1]})", file=sys.stderr)

    def med(values):
        return statistics.median(v[0] for v in values)

    def most_common(values):
        names = [v[1] for v in values]
        return max(set(names), key=names.count)

    threads = "one thread" if args.threads == 1 else f"{args.threads} threads (no direct row)"
    print(f"{args.res} x {args.res} rays, {threads}, medians of {args.rounds} rounds (Mrays/s)\n")
    print("| scene | rays | Embree direct best | backend best | backend / direct | raypack default | default / Embree best |")
    print("|---|---|---|---|---|---|---|")
    for (s, k), c in results.items():
        d, b, f = med(c["direct"]), med(c["backend"]), med(c["default"])
        best = max(d, b)
        direct = f"{d:.1f} ({most_common(c['direct'])})" if d > 0 else "-"
        ratio = f"{b / d:.2f}" if d > 0 else "-"
        print(f"| {s} | {k} | {direct} | {b:.1f} ({most_common(c['backend'])}) | "
              f"{ratio} | {f:.1f} ({most_common(c['default'])}) | {f / best:.2f}x |")


if __name__ == "__main__":
    main()
