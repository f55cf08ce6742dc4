#!/usr/bin/python3
"""Draws `raypack bench --json` results: one PNG per (scene, ray kind[, threads]),
grouped bars of Mrays/s per structure, one bar per packet width, the median
with the min-max spread of the timed passes as error bars.

usage: scripts/plot_bench.py BENCH.json OUTDIR

Needs Debian's python3-matplotlib (scripts/setup installs it); run it with
/usr/bin/python3 if another python3 comes first on PATH.
"""
import json
import os
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")  # files only, no display
import matplotlib.pyplot as plt  # noqa: E402


def load_rows(path):
    with open(path) as f:
        rows = json.load(f)
    if not isinstance(rows, list):
        raise ValueError(f"{path}: expected a JSON array of rows (raypack bench --json)")
    for i, r in enumerate(rows):
        for key in ("scene", "accel", "packet", "rays", "threads",
                    "mrays_per_s_median", "mrays_per_s_min", "mrays_per_s_max"):
            if key not in r:
                raise ValueError(f"{path}: row {i} has no '{key}'")
    return rows


def plot_case(rows, title, out_path):
    accels = list(dict.fromkeys(r["accel"] for r in rows))  # first-seen order, as benched
    widths = sorted({r["packet"] for r in rows})
    by_key = {(r["accel"], r["packet"]): r for r in rows}
    bar = 0.8 / len(widths)
    fig, ax = plt.subplots(figsize=(max(6.0, 1.1 * len(accels) + 2), 4.2), dpi=100)
    colours = plt.get_cmap("viridis")
    for k, w in enumerate(widths):
        xs, med, lo, hi = [], [], [], []
        for a, accel in enumerate(accels):
            r = by_key.get((accel, w))
            if r is None:
                continue
            xs.append(a - 0.4 + bar * (k + 0.5))
            med.append(r["mrays_per_s_median"])
            lo.append(r["mrays_per_s_median"] - r["mrays_per_s_min"])
            hi.append(r["mrays_per_s_max"] - r["mrays_per_s_median"])
        ax.bar(xs, med, bar * 0.95, yerr=[lo, hi], capsize=2, label=f"K={w}",
               color=colours(k / max(1, len(widths) - 1) * 0.85))
    ax.set_xticks(range(len(accels)))
    ax.set_xticklabels(accels)
    ax.set_ylabel("Mrays/s (median; bars: min-max)")
    ax.set_title(title)
    ax.legend(title="packet width", fontsize="small")
    ax.grid(axis="y", alpha=0.3)
    fig.tight_layout()
    tmp = out_path + ".tmp.png"
    fig.savefig(tmp)
    plt.close(fig)
    os.replace(tmp, out_path)  # atomic, like raypack's own outputs


def main(argv):
    if len(argv) != 3:
        print(__doc__.strip(), file=sys.stderr)
        return 2
    json_path, out_dir = argv[1], argv[2]
    try:
        rows = load_rows(json_path)
    except (OSError, ValueError) as e:
        print(f"plot_bench: {e}", file=sys.stderr)
        return 1
    os.makedirs(out_dir, exist_ok=True)
    cases = defaultdict(list)
    for r in rows:
        cases[(r["scene"], r["rays"], r["threads"])].append(r)
    several_thread_counts = len({r["threads"] for r in rows}) > 1
    for (scene, rays, threads), case_rows in sorted(cases.items()):
        name = f"{scene}_{rays.replace(':', '-')}" + (f"_t{threads}" if several_thread_counts else "")
        rays_count = case_rows[0].get("ray_count", "?")
        title = f"{scene}, {rays} rays ({rays_count}), {threads} thread{'s' if threads > 1 else ''}"
        out = os.path.join(out_dir, name + ".png")
        plot_case(case_rows, title, out)
        print(out)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
