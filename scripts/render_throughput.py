#!/usr/bin/env python3
"""Render throughput of two raypack builds on the SPD scenes, alternating the
builds run by run: all rays traced / render time (the renderer's own timer,
load, build and image write excluded), medians. Prints a Markdown table.

usage: scripts/render_throughput.py --old OLD/raypack [--new build/raypack]
                                    [--threads 1 2] [--rounds 3] [SCENE ...]
The old build may predate --json: its text report is read instead.
"""
import argparse
import json
import os
import re
import statistics
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCENES = ["balls", "gears", "mount", "rings", "teapot", "tetra", "tree"]


def render(binary, scene, threads, out):
    cmd = [binary, "render", os.path.join(ROOT, "scenes", scene + ".nff"), "--threads", str(threads), "-o", out]
    text = subprocess.run(cmd + ["--json"], capture_output=True, text=True)
    if text.returncode == 0:
        j = json.loads(text.stdout)
        r = j["rays"]
        return r["eye"] + r["shadow"] + r["reflect"] + r["refract"], j["render_ms"]
    text = subprocess.run(cmd, capture_output=True, text=True, check=True).stdout
    ms = float(re.search(r"Whitted: ([0-9.]+) ms", text).group(1))
    m = re.search(r"eye (\d+) \(\d+ hit\), reflect (\d+), refract (\d+), shadow (\d+)", text)
    return sum(int(x) for x in m.groups()), ms


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("scenes", nargs="*", default=SCENES)
    ap.add_argument("--old", required=True)
    ap.add_argument("--new", default=os.path.join(ROOT, "build", "raypack"))
    ap.add_argument("--threads", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--rounds", type=int, default=3)
    args = ap.parse_args()
    out = os.path.join(tempfile.mkdtemp(prefix="raypack_tp_"), "x.png")
    print(f"# {args.rounds} alternating rounds, 512 x 512, medians of render Mrays/s")
    cols = " | ".join(f"old {t}T | new {t}T | new/old {t}T" for t in args.threads)
    print(f"| scene | rays | {cols} | new {args.threads[-1]}T / new {args.threads[0]}T |")
    print("|---|---|" + "---|" * (3 * len(args.threads) + 1))
    for scene in args.scenes:
        row, new_by_threads, rays = [], {}, 0
        for t in args.threads:
            old, new = [], []
            for _ in range(args.rounds):
                n, ms = render(args.old, scene, t, out)
                old.append(n / (ms * 1e3))
                n, ms = render(args.new, scene, t, out)
                new.append(n / (ms * 1e3))
                rays = n
            o, w = statistics.median(old), statistics.median(new)
            new_by_threads[t] = w
            row += [f"{o:.1f}", f"{w:.1f}", f"{w / o:.2f}x"]
        scaling = new_by_threads[args.threads[-1]] / new_by_threads[args.threads[0]]
        print(f"| {scene} | {rays} | " + " | ".join(row) + f" | {scaling:.2f}x |", flush=True)


if __name__ == "__main__":
    sys.exit(main())
