#!/usr/bin/env python3
"""Render throughput of each integrator against `raypack trace` on rays of
the same kinds on the same scene (issue 17's measure), one thread.

For each (scene, integrator): `raypack render --json` gives the rays it traced
by kind and its render time; `raypack rays --kind camera|shadow|diffuse`
(one ray per pixel at the render's resolution) and `raypack trace` (default
configuration, median of its timed passes) give trace's rate for each kind.
The time trace would need for the render's rays is

    eye / camera rate + shadow / shadow rate + (diffuse + reflect + refract) / R

with R the diffuse-ray rate (mirror and refracted rays counted as incoherent
bounces) or, in the second column, the camera rate (counted as coherent);
throughput ratio = that time / the render's time. Medians of --rounds renders,
renders and trace runs alternating.

Those sets stand in for the render's rays: a reflection ray three bounces
deep in a sphereflake costs several times a diffuse ray from a camera hit.
The last columns time the render's own rays instead (`render --save-rays`:
its eye, bounce and shadow rays, in the order it traced them), each set with
trace's default configuration and with the render's own (the same structure
and packet widths), the faster of the two: the ratio is then the share of the
render's time that tracing those very rays would take at trace's best, i.e.
one minus the renderer's own overhead.

usage: scripts/integrator_throughput.py [--raypack build/raypack] [--rounds 3] [--cases 1,3]
"""
import argparse
import json
import os
import statistics
import subprocess
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

# (label, scene spec, integrator flags). Path tracing and distribution ray
# tracing on scenes with the light kinds they are made for.
CASES = [
    ("balls", "scenes/balls.nff", ["--integrator", "whitted"]),
    ("gears", "scenes/gears.nff", ["--integrator", "whitted"]),
    ("teapot", "scenes/teapot.nff", ["--integrator", "whitted"]),
    ("balls area+lens+glossy", "gen:balls:3:area-lights+lens+glossy", ["--integrator", "distribution", "--spp", "4"]),
    ("cornell", "gen:cornell:1", ["--integrator", "distribution", "--spp", "4"]),
    ("cornell", "gen:cornell:2", ["--integrator", "path", "--spp", "4", "--depth", "4"]),
    ("balls", "scenes/balls.nff", ["--integrator", "path", "--spp", "4", "--depth", "4"]),
    ("bunny (docs/renderer.md)", "BUNNY", ["--integrator", "path", "--spp", "16", "--depth", "5"]),
]

# The path-tracing anchor of docs/renderer.md: Embree's pathtracer's view of
# the bunny under one directional light.
BUNNY_NFF = """v
from 0.133428 0.200316 0.208839
at -0.0168404 0.110154 -0.00153695
up 0 1 0
angle 45
hither 0.001
resolution 512 512
b 0 0 0
ld -1 -1 -1 3 3 3
f 0.8 0.8 0.8 1 0 0 0 1
obj {obj}
"""



BUNNY_PATH = None


def spec_path(spec):
    if spec == "BUNNY":
        return BUNNY_PATH
    return spec if spec.startswith("gen:") else os.path.join(ROOT, spec)


def render(raypack, spec, flags, out):
    cmd = [raypack, "render", spec_path(spec), "--threads", "1", "-o", out, "--json"] + flags
    return json.loads(subprocess.run(cmd, capture_output=True, text=True, check=True).stdout)


def trace_rate(raypack, spec, rays, extra=()):
    cmd = [raypack, "trace", spec_path(spec), "--rays", rays, "--threads", "1", "--json"] + list(extra)
    return json.loads(subprocess.run(cmd, capture_output=True, text=True, check=True).stdout)["mrays_per_s_median"]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--raypack", default=os.path.join(ROOT, "build", "raypack"))
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--cases", help="comma-separated case numbers to run (1-based, in the table's order)")
    args = ap.parse_args()
    tmp = tempfile.mkdtemp(prefix="raypack_it_")
    out = os.path.join(tmp, "x.png")
    global BUNNY_PATH
    BUNNY_PATH = os.path.join(tmp, "bunny_pt.nff")
    with open(BUNNY_PATH, "w") as f:
        f.write(BUNNY_NFF.format(obj=os.path.join(ROOT, "scenes", "bunny.obj")))
    print(f"# 1 thread, medians of {args.rounds} alternating rounds; Mrays/s")
    print("| scene | integrator | rays: eye / shadow / bounces | render Mrays/s | trace camera / shadow / diffuse |"
          " render / trace mix (bounces as diffuse) | (bounces as camera) |"
          " trace the render's own eye / shadow / bounce rays | render / trace (own rays) |")
    print("|---|---|---|---|---|---|---|---|---|")
    chosen = [int(c) for c in args.cases.split(",")] if args.cases else range(1, len(CASES) + 1)
    for label, spec, flags in (CASES[c - 1] for c in chosen):
        prefix = os.path.join(tmp, "own")
        first = render(args.raypack, spec, flags + ["--save-rays", prefix], out)
        w, h = first["width"], first["height"]
        files = {}
        for kind in ("camera", "shadow", "diffuse"):
            files[kind] = os.path.join(tmp, kind + ".rays")
            subprocess.run([args.raypack, "rays", spec_path(spec), "--kind", kind, "--res", str(w), str(h),
                            "-o", files[kind]], capture_output=True, check=True)
        # The render's own rays; each traced with trace's default and with the render's configuration.
        own = {k: f"{prefix}-{k}.rays" for k in ("eye", "shadow", "bounce") if os.path.exists(f"{prefix}-{k}.rays")}
        own_configs = {k: [[], ["--accel", first["accel"], "--packet",
                                str(first["packet"] if k == "eye" else first["secondary_packet"])]] for k in own}
        render_ms, rates = [], {k: [] for k in files}
        own_rates = {k: [] for k in own}
        for _ in range(args.rounds):
            render_ms.append(render(args.raypack, spec, flags, out)["render_ms"])
            for kind, f in files.items():
                rates[kind].append(trace_rate(args.raypack, spec, f))
            for kind, f in own.items():
                own_rates[kind].append(max(trace_rate(args.raypack, spec, f, c) for c in own_configs[kind]))
        r = first["rays"]
        eye, shadow = r["eye"], r["shadow"]
        bounces = r["diffuse"] + r["reflect"] + r["refract"]
        total = eye + shadow + bounces
        ms = statistics.median(render_ms)
        cam, sh, dif = (statistics.median(rates[k]) for k in ("camera", "shadow", "diffuse"))
        as_diffuse = (eye / cam + shadow / sh + bounces / dif) / 1e3  # ms
        as_camera = (eye / cam + shadow / sh + bounces / cam) / 1e3
        own_rate = {k: statistics.median(v) for k, v in own_rates.items()}
        own_count = {"eye": eye, "shadow": shadow, "bounce": bounces}
        own_ms = sum(own_count[k] / own_rate[k] for k in own_rate) / 1e3
        own_cells = " / ".join(f"{own_rate[k]:.1f}" if k in own_rate else "-" for k in ("eye", "shadow", "bounce"))
        print(f"| {label} | {flags[1]}{' ' + ' '.join(flags[2:]) if len(flags) > 2 else ''} | "
              f"{eye} / {shadow} / {bounces} | {total / (ms * 1e3):.1f} | {cam:.1f} / {sh:.1f} / {dif:.1f} | "
              f"{as_diffuse / ms:.2f}x | {as_camera / ms:.2f}x | {own_cells} | {own_ms / ms:.2f}x |")
        for f in own.values():
            os.remove(f)


if __name__ == "__main__":
    main()
