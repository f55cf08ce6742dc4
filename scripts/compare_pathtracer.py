#!/usr/bin/env python3
"""Issue 17's anchor: path tracing the bunny with raypack against Embree's own
path tracer (`pathtracer` from Debian's embree-tools), whole process, one
thread, same camera, light, image size, samples per pixel and path length,
alternating the two programs round by round; prints both medians, the
ratio of the medians and the median of the rounds' own ratios
(docs/renderer.md, "Path tracing against Embree's path tracer").

Path length L is Embree's --max-path-length L: at most L closest-hit rays
per path and a shadow ray at each of their L hits. raypack's --depth counts
rays, and its last ray only gathers emission (none here: no area light, a
black background, so it is not traced), so the same work is --depth L + 1.

usage: scripts/compare_pathtracer.py [--rounds N] [--spp 16] [--path-length 4]
                                     [--raypack BUILD/raypack] [--obj scenes/bunny.obj]
"""
import argparse
import os
import shutil
import statistics
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "scripts"))
from compare_renderers import cpu_name, timed  # noqa: E402
from integrator_throughput import BUNNY_NFF  # noqa: E402

# Embree's view of the bunny, as BUNNY_NFF's from / at / up / angle.
EMBREE_CAMERA = ["--vp", "0.133428", "0.200316", "0.208839", "--vi", "-0.0168404", "0.110154", "-0.00153695",
                 "--vu", "0", "1", "0", "--fov", "45"]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--rounds", type=int, default=7)
    ap.add_argument("--spp", type=int, default=16)
    ap.add_argument("--path-length", type=int, default=4)
    ap.add_argument("--raypack", default=os.path.join(ROOT, "build", "raypack"))
    ap.add_argument("--obj", default=os.path.join(ROOT, "scenes", "bunny.obj"))
    args = ap.parse_args()
    raypack = os.path.abspath(args.raypack)
    embree = shutil.which("pathtracer")
    if not embree:
        sys.exit("compare_pathtracer: Embree's pathtracer is not installed (Debian: apt-get install embree-tools)")
    work = tempfile.mkdtemp(prefix="raypack_pathtracer_")
    nff = os.path.join(work, "bunny_pt.nff")
    with open(nff, "w") as f:
        f.write(BUNNY_NFF.format(obj=os.path.abspath(args.obj)))
    ours = [raypack, "render", nff, "--integrator", "path", "--spp", str(args.spp),
            "--depth", str(args.path_length + 1),
            "--threads", "1", "-o", os.path.join(work, "raypack.png")]
    theirs = [embree, "-i", os.path.abspath(args.obj), "--size", "512", "512", "--spp", str(args.spp),
              "--max-path-length", str(args.path_length), "--threads", "1", "--directionallight", "-1", "-1", "-1", "3",
              "3", "3", *EMBREE_CAMERA, "-o", os.path.join(work, "embree.tga")]
    times = {"raypack": [], "embree": []}
    for _ in range(args.rounds):
        times["embree"].append(timed(theirs, work))
        times["raypack"].append(timed(ours, work))
    shutil.rmtree(work, ignore_errors=True)
    med = {k: statistics.median(v) for k, v in times.items()}
    per_round = statistics.median(e / r for e, r in zip(times["embree"], times["raypack"]))
    print(f"# bunny, 512 x 512, {args.spp} spp, path length {args.path_length}, 1 thread, {args.rounds} alternating "
          f"rounds, whole-process seconds; processor: {cpu_name()}")
    print("| Embree pathtracer | raypack | Embree / raypack (medians) | median of the rounds' ratios |")
    print("|---|---|---|---|")
    print(f"| {med['embree']:.3f} | {med['raypack']:.3f} | {med['embree'] / med['raypack']:.2f}x | {per_round:.2f}x |")


if __name__ == "__main__":
    main()
