#!/usr/bin/env python3
"""Havran's measures of whole Whitted renders of the SPD scenes, per
structure, beside the figures Havran and Sixta published for the same scenes
(1999, docs/havran_stats_grids.txt and docs/havran_stats_octrees.txt of
github.com/erich666/StandardProceduralDatabases): per ray over every ray of
a 513 x 513 render (eye, shadow, reflected and refracted together), N_IT
ray-primitive tests, N_TS traversal steps, N_ETS leaves or cells entered,
N_EETS empty ones. The counts come from `raypack render --counts`, which
traces every ray through the structure's counting walk; they do not depend on
the machine or the thread count.

Havran and Sixta's columns: their uniform grid at the "customary" resolution
they found best by experiment, and Glassner's octree (Octree84-C, centre
subdivision, at most one object a leaf) at maximum depth 7.

usage: scripts/havran_table.py [--raypack build/raypack] [SCENE ...]
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCENES = ["balls", "gears", "mount", "rings", "teapot", "tetra", "tree"]
STRUCTURES = ["grid", "octree", "kdtree", "bvh4"]
MEASURES = ["n_it", "n_ts", "n_ets", "n_eets"]

# (N_IT, N_TS, N_ETS, N_EETS) from Havran and Sixta's tables.
HAVRAN_GRID_CUSTOMARY = {
    "balls": (41.48, 17.32, 17.32, 13.93), "gears": (17.52, 18.95, 18.95, 14.62),
    "mount": (13.32, 15.01, 15.01, 9.60), "rings": (21.48, 33.71, 33.71, 27.22),
    "teapot": (13.30, 41.24, 41.24, 38.08), "tetra": (9.17, 18.24, 18.24, 16.63),
    "tree": (355.45, 56.36, 56.36, 45.36),
}
HAVRAN_OCTREE84C_DEPTH7 = {
    "balls": (94.75, 167.00, 24.71, 16.12), "gears": (39.13, 88.60, 13.20, 6.27),
    "mount": (18.52, 60.08, 9.44, 3.31), "rings": (35.20, 120.80, 17.65, 8.29),
    "teapot": (40.02, 83.40, 13.75, 9.53), "tetra": (47.07, 58.09, 9.21, 7.22),
    "tree": (741.30, 219.30, 32.74, 23.33),
}
HAVRAN = {"grid": ("uniform grid, customary resolution", HAVRAN_GRID_CUSTOMARY),
          "octree": ("Octree84-C, depth 7", HAVRAN_OCTREE84C_DEPTH7)}


def counts(binary, scene, accel, out):
    cmd = [binary, "render", os.path.join(ROOT, "scenes", scene + ".nff"), "--res", "513", "513", "--accel", accel,
           "--counts", "--json", "-o", out]
    j = json.loads(subprocess.run(cmd, capture_output=True, text=True, check=True).stdout)
    return [j[m] for m in MEASURES], j["counted_rays"]


def fmt(values):
    return " / ".join(f"{v:.2f}" if v < 100 else f"{v:.0f}" for v in values)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("scenes", nargs="*", default=SCENES)
    ap.add_argument("--raypack", default=os.path.join(ROOT, "build", "raypack"))
    args = ap.parse_args()
    out = os.path.join(tempfile.mkdtemp(prefix="raypack_havran_"), "x.png")
    print("N_IT / N_TS / N_ETS / N_EETS per ray, whole 513 x 513 Whitted renders")
    print()
    print("| scene | rays | " + " | ".join(f"raypack {s}" for s in STRUCTURES) + " | " +
          " | ".join(f"Havran and Sixta: {HAVRAN[s][0]}" for s in HAVRAN) + " |")
    print("|---|---|" + "---|" * (len(STRUCTURES) + len(HAVRAN)))
    for scene in args.scenes:
        cells, rays = [], 0
        for accel in STRUCTURES:
            values, rays = counts(args.raypack, scene, accel, out)
            cells.append(fmt(values))
        theirs = [fmt(HAVRAN[s][1][scene]) if scene in HAVRAN[s][1] else "-" for s in HAVRAN]
        print(f"| {scene} | {rays} | " + " | ".join(cells + theirs) + " |", flush=True)


if __name__ == "__main__":
    sys.exit(main())
