#!/usr/bin/env python3
"""Every acceleration structure against the BVH2 on the same rays, in one run.

One `raypack bench` run (camera rays at RES x RES, one thread, every
structure and packet width, each validated against the oracle, median of
REPEAT timed passes after a warm-up), printed as a Markdown table of Mrays/s
and ratios to the first structure listed (the BVH2 by default) at the same
width; "-" where a structure has no packets of that width. This is how the
structure table of docs/structures.md is made.

usage: scripts/compare_structures.py [--res 1024] [--repeat 5] [SCENE ...]
       scripts/compare_structures.py --best --accels bvh4,grid,octree,kdtree --packets 1,4,8,16 [SCENE ...]

--best: one row per scene, every structure at its fastest width against the
first structure at its fastest (bvh4 at 16 is the default configuration
for camera rays): the measure of issue 21.

--rounds N: the whole bench N times over, each row's rate the median of its
N rounds: a burst of load on a shared machine then spoils one round of a
row, not the row's ratio.
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
RAYPACK = os.path.join(ROOT, os.environ.get("RAYPACK_BUILD_DIR", "build"), "raypack")


def bench(scenes, accels, packets, res, repeat, rounds=1):
    """Rows of raypack bench --json, keyed by (scene as given, accel, packet);
    with several rounds, each row's mrays_per_s_median is the median of its
    rounds' medians."""
    runs = []
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "bench.json")
        for _ in range(rounds):
            subprocess.run([RAYPACK, "bench", *scenes, "--accel", ",".join(accels),
                            "--packet", ",".join(str(k) for k in packets), "--rays", "camera", "--threads", "1",
                            "--res", str(res), str(res), "--repeat", str(repeat), "--json", out],
                           check=True, stdout=subprocess.DEVNULL)
            with open(out) as f:
                runs.append({(r["scene_file"], r["accel"], r["packet"]): r for r in json.load(f)})
    rows = runs[0]
    for key, row in rows.items():
        row["mrays_per_s_median"] = statistics.median(run[key]["mrays_per_s_median"] for run in runs)
    return rows


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("scenes", nargs="*", default=["scenes/balls.nff", "scenes/tetra.nff", "scenes/mount.nff",
                                                    "scenes/tree.nff", "gen:balls:4"])
    ap.add_argument("--res", type=int, default=1024)
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--rounds", type=int, default=1, help="whole bench runs; each row the median of its rounds")
    ap.add_argument("--accels", default="bvh2,grid,octree,kdtree")
    ap.add_argument("--packets", default="1,8,16")
    ap.add_argument("--best", action="store_true", help="each structure at its fastest width")
    args = ap.parse_args()
    accels = args.accels.split(",")
    packets = [int(p) for p in args.packets.split(",")]
    if args.best:
        return print_best(args, accels, packets)
    paths, rows = table_head(args, accels, packets, ["scene", "K"], " Mrays/s")
    for scene, path in zip(args.scenes, paths):
        for k in packets:
            rate = {a: rows[(path, a, k)]["mrays_per_s_median"] if (path, a, k) in rows else None for a in accels}
            base = rate[accels[0]]
            cells = [f"{rate[a]:.2f}" if rate[a] else "-" for a in accels]
            ratios = [f"{rate[a] / base:.2f}" if rate[a] and base else "-" for a in accels[1:]]
            print(f"| {scene} | {k} | " + " | ".join(cells) + " | " + " | ".join(ratios) + " |", flush=True)
    return 0


def table_head(args, accels, packets, first_columns, rate_suffix):
    """Prints the table's head, runs the bench: (scene paths, rows)."""
    print("| " + " | ".join(first_columns) + " | " + " | ".join(f"{a}{rate_suffix}" for a in accels) + " | " +
          " | ".join(f"{a}/{accels[0]}" for a in accels[1:]) + " |")
    print("|---" * (len(first_columns) + 2 * len(accels) - 1) + "|")
    paths = [scene if scene.startswith("gen:") else os.path.join(ROOT, scene) for scene in args.scenes]
    if args.rounds < 1:
        sys.exit("compare_structures.py: --rounds must be at least 1")
    return paths, bench(paths, accels, packets, args.res, args.repeat, args.rounds)


def print_best(args, accels, packets):
    paths, rows = table_head(args, accels, packets, ["scene"], " Mrays/s (K)")
    for scene, path in zip(args.scenes, paths):
        best = {}
        for a in accels:
            rates = [(rows[(path, a, k)]["mrays_per_s_median"], k) for k in packets if (path, a, k) in rows]
            best[a] = max(rates) if rates else None
        base = best[accels[0]]
        cells = [f"{best[a][0]:.2f} ({best[a][1]})" if best[a] else "-" for a in accels]
        ratios = [f"{best[a][0] / base[0]:.2f}" if best[a] and base else "-" for a in accels[1:]]
        print(f"| {scene} | " + " | ".join(cells) + " | " + " | ".join(ratios) + " |", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
