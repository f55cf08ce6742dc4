#!/usr/bin/env python3
"""Render throughput at 2 threads against 1 thread on the SPD scenes, with
what this machine allows in the same round: two 1-thread renders run at once,
one per core. On the project's shared virtual machines the two cores slow
each other down by a varying amount (two independent renders have each run
at 0.6x of their speed alone), which bounds any program's 2-thread speed-up.

Per round and scene: a 1-thread render, a 2-thread render, and the pair; the
table gives medians over rounds of the per-round ratios. The pair and its
1-thread reference render at --ceiling-res (default 1024 x 1024), so that
the two renders' tracing overlaps in time despite their load and build.
  2T/1T    = render throughput at 2 threads / at 1 thread (rays / render_ms)
  ceiling  = (throughput of the pair's two renders, summed) / throughput alone
  2T/ceil  = how much of the machine's ceiling the renderer's threads reach
  fastest  = the fastest 1-thread render time / the fastest 2-thread one: a
             short render (tetra: 8 ms) loses a whole scheduler tick (4 ms)
             whenever something else on the machine needs a core, which at 1
             thread runs on the idle one

usage: scripts/thread_scaling.py [--raypack build/raypack] [--rounds 5] [--ceiling-res 1024] [SCENE ...]
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


def command(binary, scene, threads, out, res=None):
    path = scene if os.path.exists(scene) else os.path.join(ROOT, "scenes", scene + ".nff")
    extra = ["--res", str(res), str(res)] if res else []
    return [binary, "render", path, "--threads", str(threads), "-o", out, "--json"] + extra


def throughput(stdout):
    j = json.loads(stdout)
    return sum(j["rays"].values()) - j["rays"]["eye_hits"], j["render_ms"]


def run(cmd, times=None):
    r = subprocess.run(cmd, capture_output=True, text=True, check=True)
    n, ms = throughput(r.stdout)
    if times is not None:
        times.append(ms)
    return n / ms


def pair(cmds):
    procs = [subprocess.Popen(["taskset", "-c", str(core)] + cmd, stdout=subprocess.PIPE, text=True)
             for core, cmd in enumerate(cmds)]
    total = 0.0
    for p in procs:
        out, _ = p.communicate()
        if p.returncode != 0:
            raise SystemExit(f"render failed: {' '.join(cmds[0])}")
        n, ms = throughput(out)
        total += n / ms
    return total


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("scenes", nargs="*", default=SCENES)
    ap.add_argument("--raypack", default=os.path.join(ROOT, "build", "raypack"))
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--ceiling-res", type=int, default=1024)
    args = ap.parse_args()
    tmp = tempfile.mkdtemp(prefix="raypack_scaling_")
    out = [os.path.join(tmp, f"{k}.png") for k in range(2)]
    print(f"# {args.rounds} rounds, 2T/1T at 512 x 512, ceiling at {args.ceiling_res} x {args.ceiling_res}, "
          "medians of per-round ratios")
    print("| scene | 2T/1T | ceiling (two 1T renders at once) | 2T/ceiling | fastest 1T / fastest 2T |")
    print("|---|---|---|---|---|")
    for scene in args.scenes:
        speedup, ceiling, ms1, ms2 = [], [], [], []
        for _ in range(args.rounds):
            one = run(command(args.raypack, scene, 1, out[0]), ms1)
            two = run(command(args.raypack, scene, 2, out[0]), ms2)
            alone = run(command(args.raypack, scene, 1, out[0], args.ceiling_res))
            both = pair([command(args.raypack, scene, 1, out[k], args.ceiling_res) for k in range(2)])
            speedup.append(two / one)
            ceiling.append(both / alone)
        s, c = statistics.median(speedup), statistics.median(ceiling)
        print(f"| {scene} | {s:.2f}x | {c:.2f}x | {s / c:.2f} | {min(ms1) / min(ms2):.2f}x |", flush=True)


if __name__ == "__main__":
    sys.exit(main())
