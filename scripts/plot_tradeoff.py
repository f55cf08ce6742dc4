#!/usr/bin/python3
"""Draws `raypack bench --tradeoff --json` results: the trade curves, one PNG
per family (triangle, sphere, slabs, rcp, precision, builder, offset), one
panel per error measure the family has (builder: also SAH cost and build
time), each variant a point at (error, Mrays/s median) with the min-max
spread of the timed passes as a vertical bar; where a family runs on several
structures (slabs, rcp: bvh2 and bvh8), points are labelled "variant
(structure)". Up and left is better.

usage: scripts/plot_tradeoff.py TRADEOFF.json OUTDIR   (writes OUTDIR/tradeoff_FAMILY.png)

Needs Debian's python3-matplotlib; run it with /usr/bin/python3 if another
python3 comes first on PATH.
"""
import json
import os
import sys

import matplotlib

matplotlib.use("Agg")  # files only, no display
import matplotlib.pyplot as plt  # noqa: E402

REQUIRED = ("family", "variant", "mrays_per_s_median", "mrays_per_s_min", "mrays_per_s_max")


def shadow_wrong_fraction(row):
    """Wrong shadow answers over every placement, or None."""
    wrong = [v for k, v in row.items() if k.startswith("shadow_wrong_") and v is not None]
    rays = [v for k, v in row.items() if k.startswith("self_shadow_rays_") and v is not None]
    if not wrong or not sum(rays):
        return None
    return sum(wrong) / sum(rays)


# (label, function of a row giving the error or None); log scale on x.
MEASURES = (
    ("leak fraction (edge/vertex/inside rays)", lambda r: r.get("leak_fraction")),
    ("t error p99 (ULPs vs double)", lambda r: r.get("t_ulp_p99")),
    ("self-intersection fraction", lambda r: r.get("self_fraction")),
    ("wrong shadow fraction", shadow_wrong_fraction),
    ("pixels differing from the double reference", lambda r: r.get("differing_fraction")),
    ("SAH cost of the BVH", lambda r: r.get("sah_cost")),
    ("build time, ms (one thread)", lambda r: r.get("build_ms")),
)


def load_rows(path):
    with open(path) as f:
        rows = json.load(f)
    if not isinstance(rows, list):
        raise ValueError(f"{path}: expected a JSON array of rows (raypack bench --tradeoff --json)")
    for i, r in enumerate(rows):
        for key in REQUIRED:
            if key not in r:
                raise ValueError(f"{path}: row {i} lacks '{key}' (not a raypack bench --tradeoff file?)")
    return rows


def plot_family(family, rows, out_path):
    # Files written before the structure column have none: one structure.
    several = len({r.get("structure") for r in rows}) > 1
    measures = [(label, f) for label, f in MEASURES if any(f(r) is not None for r in rows)]
    fig, axes = plt.subplots(1, len(measures), figsize=(4.2 * len(measures), 3.8), squeeze=False)
    for ax, (label, f) in zip(axes[0], measures):
        points = [(f(r), r) for r in rows if f(r) is not None]
        positive = [e for e, _ in points if e > 0]
        # Log scale where the errors span decades; zero cannot sit on a log
        # axis, so there it is drawn at a floor a decade below and marked "0".
        log = len(positive) > 0 and max(positive) / min(positive) >= 10
        floor = min(positive) / 10 if log else 0
        for error, r in points:
            x = error if error > 0 else floor
            y = r["mrays_per_s_median"]
            ax.errorbar([x], [y], yerr=[[y - r["mrays_per_s_min"]], [r["mrays_per_s_max"] - y]], fmt="o", capsize=3)
            name = r["variant"] + (f" ({r.get('structure')})" if several else "")
            ax.annotate(name + (" (0)" if error == 0 else ""), (x, y), textcoords="offset points",
                        xytext=(5, 5), fontsize=8)
        if log:
            ax.set_xscale("log")
        ax.set_xlabel(label)
        ax.set_ylabel("Mrays/s (median, min-max)")
        ax.set_ylim(bottom=0)
        ax.grid(True, which="both", alpha=0.3)
    scene = rows[0].get("throughput_scene", "")
    kind = rows[0].get("throughput_rays", "")
    kernels = {r.get("kernels") for r in rows}
    # One kernel choice for the whole family (builder) is worth the title.
    shared = f"\n{kernels.pop()}" if len(kernels) == 1 and None not in kernels else ""
    fig.suptitle(f"{family}: throughput ({kind} rays, {scene}) against error{shared}")
    fig.tight_layout()
    fig.savefig(out_path, dpi=100)
    plt.close(fig)


def main(argv):
    if len(argv) != 3:
        print(__doc__, file=sys.stderr)
        return 2
    try:
        rows = load_rows(argv[1])
    except (OSError, ValueError) as e:
        print(f"plot_tradeoff.py: {e}", file=sys.stderr)
        return 1
    os.makedirs(argv[2], exist_ok=True)
    families = []
    for r in rows:
        if r["family"] not in families:
            families.append(r["family"])
    for family in families:
        out = os.path.join(argv[2], f"tradeoff_{family}.png")
        plot_family(family, [r for r in rows if r["family"] == family], out)
        print(out)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
