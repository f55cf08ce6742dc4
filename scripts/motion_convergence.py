#!/usr/bin/env python3
"""Motion blur converges: RMSE of distribution renders of a moving scene
against a many-sample reference, as spp grows (docs/motion.md).

Usage: motion_convergence.py [--raypack build/raypack] [--scene gen:balls:2:motion]
                             [--res 128] [--reference-spp 1024] [--spp 4 16 64 256]
                             [--sampler random]
Each render uses another seed than the reference's. Prints a Markdown table:
spp, RMSE (8-bit units), and the ratio to the previous row (1 / sqrt(spp):
2.0 per 4x samples). The reference's own noise adds to every row's error
(its variance is 1/reference_spp of one sample's)."""
import argparse
import math
import os
import subprocess
import tempfile


def read_ppm(path):
    data = open(path, 'rb').read()
    fields, i = [], 0
    while len(fields) < 4:
        while data[i:i + 1].isspace():
            i += 1
        j = i
        while not data[j:j + 1].isspace():
            j += 1
        fields.append(data[i:j])
        i = j
    return data[i + 1:]


def rmse(a, b):
    return math.sqrt(sum((x - y) ** 2 for x, y in zip(a, b)) / len(a))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('--raypack', default='build/raypack')
    ap.add_argument('--scene', default='gen:balls:2:motion')
    ap.add_argument('--res', type=int, default=128)
    ap.add_argument('--reference-spp', type=int, default=1024)
    ap.add_argument('--spp', type=int, nargs='+', default=[4, 16, 64, 256])
    ap.add_argument('--sampler', default='random')
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        def render(spp, seed):
            out = os.path.join(tmp, f'r{spp}_{seed}.ppm')
            subprocess.run([args.raypack, 'render', args.scene, '--integrator', 'distribution', '--spp', str(spp),
                            '--sampler', args.sampler, '--seed', str(seed), '--res', str(args.res), str(args.res),
                            '--quiet', '-o', out], check=True, stdout=subprocess.DEVNULL)
            return read_ppm(out)
        reference = render(args.reference_spp, 1000)
        print(f'| spp | RMSE vs {args.reference_spp} spp (8-bit) | ratio to previous row |')
        print('|---|---|---|')
        previous = None
        for spp in args.spp:
            e = rmse(render(spp, spp + 1), reference)
            ratio = '' if previous is None else f'{previous / e:.2f}'
            print(f'| {spp} | {e:.2f} | {ratio} |')
            previous = e


if __name__ == '__main__':
    main()
