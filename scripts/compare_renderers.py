#!/usr/bin/env python3
"""Whole-process render times of raypack, POV-Ray 3.7 and Tachyon on the SPD
scenes, alternating the three programs round by round; prints medians and
ratios as a Markdown table (docs/renderer.md, "Whole-process time against POV-Ray 3.7 and Tachyon").

usage: scripts/compare_renderers.py [--rounds N] [--threads T] [--res N]
                                    [--raypack BUILD/raypack] [SCENE ...]
POV-Ray reads shared/peers/pov/SCENE.pov (the SPD generators' own POV-Ray
output: same camera, lights and geometry); Tachyon reads scenes/SCENE.nff.
Programs that are not installed (Debian: povray, tachyon) are left out.
"""
import argparse
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCENES = ["balls", "gears", "mount", "rings", "teapot", "tetra", "tree"]


def timed(cmd, cwd):
    start = time.perf_counter()
    done = subprocess.run(cmd, cwd=cwd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    elapsed = time.perf_counter() - start
    if done.returncode != 0:
        sys.exit(f"{os.path.basename(sys.argv[0])}: {' '.join(cmd)} failed:\n{done.stderr[-2000:]}")
    return elapsed


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("scenes", nargs="*", default=SCENES)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--res", type=int, default=512)
    ap.add_argument("--raypack", default=os.path.join(ROOT, "build", "raypack"))
    ap.add_argument("--peers", default=os.path.join(ROOT, "..", "shared", "peers"))
    args = ap.parse_args()
    povray, tachyon = shutil.which("povray"), shutil.which("tachyon")
    work = tempfile.mkdtemp(prefix="raypack_compare_")
    res, t = str(args.res), str(args.threads)
    # Older raypack builds (kept for before/after tables) have no --quiet.
    usage = subprocess.run([args.raypack, "render", "--help"], capture_output=True, text=True).stdout
    quiet = ["--quiet"] if "--quiet" in usage else []
    print(f"# {args.rounds} alternating rounds, {args.threads} thread(s), {args.res} x {args.res}, "
          f"whole-process seconds (median); processor: {cpu_name()}")
    print("| scene | raypack | POV-Ray 3.7 | POV-Ray / raypack | Tachyon | Tachyon / raypack |")
    print("|---|---|---|---|---|---|")
    for scene in args.scenes:
        nff = os.path.join(ROOT, "scenes", scene + ".nff")
        pov = os.path.abspath(os.path.join(args.peers, "pov", scene + ".pov"))
        runs = {"raypack": [], "povray": [], "tachyon": []}
        for _ in range(args.rounds):
            runs["raypack"].append(timed([args.raypack, "render", nff, "--threads", t, "--res", res, res, *quiet,
                                          "-o", os.path.join(work, scene + ".png")], work))
            if povray and os.path.exists(pov):
                runs["povray"].append(timed([povray, "+I" + pov, "+O" + os.path.join(work, scene + "_pov.png"),
                                             "+W" + res, "+H" + res, "-D", "+WT" + t], work))
            if tachyon:
                runs["tachyon"].append(timed([tachyon, nff, "-o", os.path.join(work, scene + "_tachyon.tga"),
                                              "-format", "TARGA", "-res", res, res, "-numthreads", t], work))
        med = {k: statistics.median(v) if v else None for k, v in runs.items()}
        cell = lambda k: f"{med[k]:.3f}" if med[k] is not None else "-"
        ratio = lambda k: f"{med[k] / med['raypack']:.1f}x" if med[k] is not None else "-"
        print(f"| {scene} | {cell('raypack')} | {cell('povray')} | {ratio('povray')} | {cell('tachyon')} | {ratio('tachyon')} |",
              flush=True)
    shutil.rmtree(work, ignore_errors=True)


def cpu_name():
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return "unknown"


if __name__ == "__main__":
    main()
