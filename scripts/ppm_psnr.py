#!/usr/bin/env python3
# PSNR (dB, 8-bit RGB) and fraction of differing pixels of two binary PPM images.
# Usage: ppm_psnr.py A.ppm B.ppm
import sys, math
def rd(p):
    d = open(p,'rb').read()
    # P6\nW H\n255\n
    parts = d.split(maxsplit=4)
    return parts[4] if len(parts)==5 else None, d
def load(p):
    d = open(p,'rb').read(); f=[]; i=0
    while len(f) < 4:
        while d[i:i+1].isspace(): i+=1
        j=i
        while not d[j:j+1].isspace(): j+=1
        f.append(d[i:j]); i=j
    return d[i+1:]
a, b = load(sys.argv[1]), load(sys.argv[2])
se = 0; diff = 0; n = len(a)//3
for k in range(n):
    pa, pb = a[3*k:3*k+3], b[3*k:3*k+3]
    if pa != pb:
        diff += 1
        se += sum((x-y)**2 for x,y in zip(pa,pb))
mse = se / (3*n)
print("%.1f %.4f" % (99.0 if mse == 0 else 10*math.log10(255*255/mse), diff/n))
