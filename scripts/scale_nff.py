#!/usr/bin/env python3
# Writes an NFF scene with every position mapped to p * S + T and every length times S
# (docs/reliability.md). Usage: scale_nff.py FILE S T
import sys
src, s, t = sys.argv[1], float(sys.argv[2]), float(sys.argv[3])
lines = open(src).read().split('\n'); out = []; pend = None
def pt(ws, n=3, extra_r=False):
    v = [float(w) * s + t for w in ws[:3]]
    r = [float(w) * s for w in ws[3:4]] if extra_r else []
    return ' '.join('%.9g' % x for x in v + r) + (' ' + ' '.join(ws[4 if extra_r else 3:]) if len(ws) > (4 if extra_r else 3) else '')
i = 0
while i < len(lines):
    ws = lines[i].split()
    if not ws: out.append(lines[i]); i += 1; continue
    k = ws[0]
    if k in ('from', 'at'): out.append(k + ' ' + pt(ws[1:]))
    elif k == 'hither': out.append('hither %.9g' % (float(ws[1]) * s))
    elif k == 'l': out.append('l ' + pt(ws[1:]))
    elif k == 's': out.append('s ' + pt(ws[1:], extra_r=True))
    elif k == 'c' and len(ws) >= 9:
        out.append('c ' + pt(ws[1:5], extra_r=True) + ' ' + pt(ws[5:9], extra_r=True))
    elif k == 'c':
        out.append('c'); out.append(pt(lines[i+1].split(), extra_r=True)); out.append(pt(lines[i+2].split(), extra_r=True)); i += 3; continue
    elif k == 'p':
        n = int(ws[1]); out.append(lines[i])
        for j in range(n): out.append(pt(lines[i+1+j].split()))
        i += n + 1; continue
    else: out.append(lines[i])
    i += 1
print('\n'.join(out))
