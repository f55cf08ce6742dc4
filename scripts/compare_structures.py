#!/usr/bin/env python3
"""Every acceleration structure against the BVH2 on the same rays, in one run.

For each scene: camera rays at RES x RES (raypack rays), then raypack trace
with one thread for every structure and packet width, median of REPEAT timed
passes after a warm-up. Prints a Markdown table of Mrays/s and ratios to the
first structure listed (the BVH2 by default) at the same width. Until `raypack bench` exists (issue 6), this is how
the README's structure table is made.

usage: scripts/compare_structures.py [--res 1024] [--repeat 5] [SCENE ...]
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
RAYPACK = os.path.join(ROOT, os.environ.get("RAYPACK_BUILD_DIR", "build"), "raypack")


def trace(scene, rays, accel, packet, repeat):
    out = subprocess.run([RAYPACK, "trace", scene, "--rays", rays, "--accel", accel, "--packet", str(packet),
                          "--threads", "1", "--repeat", str(repeat), "--json"],
                         check=True, capture_output=True, text=True).stdout
    return json.loads(out)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("scenes", nargs="*", default=["scenes/balls.nff", "scenes/tetra.nff", "scenes/mount.nff",
                                                    "scenes/tree.nff", "gen:balls:4"])
    ap.add_argument("--res", type=int, default=1024)
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--accels", default="bvh2,grid,octree,kdtree")
    ap.add_argument("--packets", default="1,8,16")
    args = ap.parse_args()
    accels = args.accels.split(",")
    packets = [int(p) for p in args.packets.split(",")]
    print("| scene | K | " + " | ".join(f"{a} Mrays/s" for a in accels) + " | " +
          " | ".join(f"{a}/{accels[0]}" for a in accels[1:]) + " |")
    print("|---" * (2 + 2 * len(accels) - 1) + "|")
    with tempfile.TemporaryDirectory() as tmp:
        for scene in args.scenes:
            path = scene if scene.startswith("gen:") else os.path.join(ROOT, scene)
            rays = os.path.join(tmp, "camera.rays")
            subprocess.run([RAYPACK, "rays", path, "--kind", "camera", "--res", str(args.res), str(args.res),
                            "-o", rays], check=True, capture_output=True)
            for k in packets:
                rate = {a: trace(path, rays, a, k, args.repeat)["mrays_per_s_median"] for a in accels}
                base = rate[accels[0]]
                print(f"| {scene} | {k} | " + " | ".join(f"{rate[a]:.2f}" for a in accels) + " | " +
                      " | ".join(f"{rate[a] / base:.2f}" for a in accels[1:]) + " |", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
