# Bends an OFF mesh about the z axis along its tallest (y) extent by DEGREES, as a bend
# deformer: python3 scripts/bend_base.py IN.off OUT.off DEGREES (issue 25: the posed knight).
import sys, math
src, dst, deg = sys.argv[1], sys.argv[2], float(sys.argv[3])
lines = [l for l in open(src).read().split('\n') if l.strip() and not l.startswith('#')]
assert lines[0].strip() == 'OFF'
nv, nf, _ = map(int, lines[1].split())
V = [list(map(float, l.split()[:3])) for l in lines[2:2 + nv]]
ys = [v[1] for v in V]; xs = [v[0] for v in V]
y0, L = min(ys), max(ys) - min(ys)
xc = 0.5 * (min(xs) + max(xs))
th = math.radians(deg)
R = L / th
out = []
for x, y, z in V:
    phi = th * (y - y0) / L
    r = R - (x - xc)
    out.append((xc + R - r * math.cos(phi), y0 + r * math.sin(phi), z))
with open(dst, 'w') as f:
    f.write('OFF\n%d %d 0\n' % (nv, nf))
    for p in out: f.write('%.17g %.17g %.17g\n' % p)
    f.write('\n'.join(lines[2 + nv:2 + nv + nf]) + '\n')
