#!/usr/bin/env python3
"""Build times of raypack's BVHs and of Embree on the same scenes, interleaved
round by round; prints medians as a Markdown table (docs/embree.md, "Build
speed"). A build is timed by `raypack trace SCENE --rays R --accel A
--repeat 1 --json` (build_ms: from the loaded scene to a structure ready to
trace; Embree's device is created before the clock starts).

usage: scripts/build_times.py [--rounds N] [--threads 1,2] [--accels bvh2,bvh8,embree,embree-robust]
                              [--build DIR] [SCENE ...]
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def run(cmd):
    done = subprocess.run(cmd, cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if done.returncode != 0:
        sys.exit(f"build_times: {' '.join(cmd)} failed:\n{done.stderr[-2000:]}")
    return done.stdout


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("scenes", nargs="*", default=["scenes/bunny.obj", "gen:balls:4", "gen:mount:6", "gen:tetra:6"])
    ap.add_argument("--rounds", type=int, default=9)
    ap.add_argument("--threads", default="1,2")
    ap.add_argument("--accels", default="bvh2,bvh8,embree,embree-robust")
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    args = ap.parse_args()
    raypack = os.path.join(args.build, "raypack")
    accels = args.accels.split(",")
    threads = [int(t) for t in args.threads.split(",")]
    times = {}
    with tempfile.TemporaryDirectory() as tmp:
        rays = {}
        for s in args.scenes:
            rays[s] = os.path.join(tmp, f"{len(rays)}.rays")
            run([raypack, "rays", s, "--kind", "camera", "--res", "16", "16", "-o", rays[s]])
        for _ in range(args.rounds):
            for s in args.scenes:
                for t in threads:
                    for a in accels:
                        row = json.loads(run([raypack, "trace", s, "--rays", rays[s], "--accel", a, "--threads",
                                              str(t), "--repeat", "1", "--json"]).strip().splitlines()[-1])
                        times.setdefault((s, t, a), []).append(row["build_ms"])
    print(f"build_ms, medians of {args.rounds} interleaved rounds\n")
    print("| scene | threads | " + " | ".join(f"{a} ms" for a in accels) + " | " +
          " | ".join(f"{a} speed / best Embree" for a in accels if not a.startswith("embree")) + " |")
    print("|---|---|" + "---|" * (len(accels) + sum(not a.startswith("embree") for a in accels)))
    for s in args.scenes:
        for t in threads:
            med = {a: statistics.median(times[s, t, a]) for a in accels}
            embree = min(v for a, v in med.items() if a.startswith("embree"))
            cells = [f"{med[a]:.1f}" for a in accels]
            ratios = [f"{embree / med[a]:.2f}x" for a in accels if not a.startswith("embree")]
            print(f"| {s} | {t} | " + " | ".join(cells + ratios) + " |")


if __name__ == "__main__":
    main()
