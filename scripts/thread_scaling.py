#!/usr/bin/env python3
"""Render throughput at 2 threads against 1 thread on the SPD scenes, beside
what this machine allows in the same round.

On the project's shared virtual machines the two vCPUs do not run at the
same speed: for minutes or hours one renders 1.2-1.4x slower than the other
(the host gives them unequal shares). A 1-thread render left to the kernel
lands on either; two threads can at best add the slower vCPU's throughput to
the faster one's. So each round renders, alternating: 1 thread pinned to the
first CPU, 1 thread pinned to the second, and 2 threads on both.
  2T/1T fast = throughput at 2 threads / at 1 thread on the faster vCPU
  2T/1T slow = the same against the slower vCPU
  bound      = (throughput on vCPU A + on vCPU B) / on the faster one: the
               most 2T/1T fast can be on this machine in that round
  2T/bound   = 2-thread throughput / (A + B): how much of it the renderer's
               threads reach
Medians over rounds of the per-round ratios; throughput = rays / render_ms.

usage: scripts/thread_scaling.py [--raypack build/raypack] [--rounds 5] [--cpus 0,1] [SCENE ...]
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCENES = ["balls", "gears", "mount", "rings", "teapot", "tetra", "tree"]


def command(binary, scene, threads, out):
    path = scene if os.path.exists(scene) else os.path.join(ROOT, "scenes", scene + ".nff")
    return [binary, "render", path, "--threads", str(threads), "-o", out, "--json"]


def throughput(cmd):
    r = subprocess.run(cmd, capture_output=True, text=True, check=True)
    j = json.loads(r.stdout)
    return (sum(j["rays"].values()) - j["rays"]["eye_hits"]) / j["render_ms"]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("scenes", nargs="*", default=SCENES)
    ap.add_argument("--raypack", default=os.path.join(ROOT, "build", "raypack"))
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--cpus", default="0,1", help="the two CPUs (default 0,1)")
    args = ap.parse_args()
    cpus = args.cpus.split(",")
    if len(cpus) != 2:
        raise SystemExit("--cpus: expected two CPUs, e.g. 0,1")
    out = os.path.join(tempfile.mkdtemp(prefix="raypack_scaling_"), "x.png")
    print(f"# {args.rounds} rounds at 512 x 512, vCPUs {cpus[0]} and {cpus[1]}, medians of per-round ratios")
    print("| scene | 2T/1T fast | 2T/1T slow | vCPU speed ratio | bound | 2T/bound |")
    print("|---|---|---|---|---|---|")
    for scene in args.scenes:
        fast, slow, ratio, bound, reach = [], [], [], [], []
        for _ in range(args.rounds):
            one = [throughput(["taskset", "-c", c] + command(args.raypack, scene, 1, out)) for c in cpus]
            two = throughput(["taskset", "-c", args.cpus] + command(args.raypack, scene, 2, out))
            hi, lo = max(one), min(one)
            fast.append(two / hi)
            slow.append(two / lo)
            ratio.append(hi / lo)
            bound.append((hi + lo) / hi)
            reach.append(two / (hi + lo))
        m = statistics.median
        print(f"| {scene} | {m(fast):.2f}x | {m(slow):.2f}x | {m(ratio):.2f} | {m(bound):.2f}x | {m(reach):.2f} |",
              flush=True)


if __name__ == "__main__":
    sys.exit(main())
