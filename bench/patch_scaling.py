#!/usr/bin/env python3
"""How the cost of a local patch grows with the base's resolution (issue 14's 1M-face base).

A base of over 200,000 faces is simplified first (the `surface` default); with --no-proxy every
base is used as given, to see what the tessellation alone costs.

The shared 70k-face Stanford bunny is split 1-to-4 once and twice (the same surface with 278k
and 1.1M faces) and each is covered with the sample apples at the same scale through local
patches (`surface --method patches --embedding normal`, so that the shell map's whole-base cost
stays out of the figure). Per run: wall time, the parameterisation stage (growing and flattening
the patches), patches, and faces per patch from `--stats`. Median of --runs runs.

    python3 bench/patch_scaling.py [--runs 3] [--levels 0 1 2] [--out bench/results/X.json]
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SHARED = os.path.join(os.path.dirname(ROOT), "shared", "data")


def read_obj(path):
    V, F = [], []
    with open(path) as f:
        for line in f:
            p = line.split()
            if not p:
                continue
            if p[0] == "v":
                V.append(tuple(float(x) for x in p[1:4]))
            elif p[0] == "f":
                F.append(tuple(int(x.split("/")[0]) - 1 for x in p[1:4]))
    return V, F


def split_1_to_4(V, F):
    """Midpoint subdivision: the same piecewise-flat surface with four times the faces."""
    V = list(V)
    mid = {}

    def m(a, b):
        key = (a, b) if a < b else (b, a)
        if key not in mid:
            pa, pb = V[a], V[b]
            mid[key] = len(V)
            V.append(tuple(0.5 * (x + y) for x, y in zip(pa, pb)))
        return mid[key]

    out = []
    for a, b, c in F:
        ab, bc, ca = m(a, b), m(b, c), m(c, a)
        out += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
    return V, out


def write_off(path, V, F):
    with open(path, "w") as f:
        f.write("OFF\n%d %d 0\n" % (len(V), len(F)))
        f.writelines("%.9g %.9g %.9g\n" % v for v in V)
        f.writelines("3 %d %d %d\n" % t for t in F)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--levels", type=int, nargs="+", default=[0, 1, 2])
    ap.add_argument("--meshquilt", default=os.path.join(ROOT, "build", "meshquilt"))
    ap.add_argument("--out")
    ap.add_argument("--no-proxy", action="store_true", help="keep every base as given")
    args = ap.parse_args()
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        swatch = os.path.join(tmp, "apples.obj")
        subprocess.run([args.meshquilt, "swatch", "apples", "-o", swatch, "--quiet"], check=True)
        V, F = read_obj(os.path.join(SHARED, "base", "stanford_bunny_70k.obj"))
        for level in range(max(args.levels) + 1):
            if level in args.levels:
                base = os.path.join(tmp, "bunny_%d.off" % level)
                write_off(base, V, F)
                runs = []
                for _ in range(args.runs):
                    stats = os.path.join(tmp, "stats.json")
                    subprocess.run([args.meshquilt, "surface", "--base", base, "--swatch", swatch,
                                    "--method", "patches", "--embedding", "normal", "--quiet",
                                    "-o", os.path.join(tmp, "out.ply"), "--stats", stats] +
                                   (["--no-proxy"] if args.no_proxy else []),
                                   check=True)
                    with open(stats) as f:
                        runs.append(json.load(f))
                s = runs[0]
                param = statistics.median(r["stage_seconds"]["parameterization"] for r in runs)
                row = {
                    "input_faces": len(F),
                    "proxy_faces": s.get("proxy_faces", 0),
                    "base_faces": s["base_faces"],
                    "patches": s["iterations"],
                    "faces_per_patch": s["patch_faces"] / max(1, s["iterations"]),
                    "wall_seconds": statistics.median(r["wall_seconds"] for r in runs),
                    "parameterization_seconds": param,
                    "ms_per_patch": 1e3 * param / max(1, s["iterations"]),
                    "us_per_patch_face": 1e6 * param / max(1, s["patch_faces"]),
                    "elements": s["output"]["elements"],
                    "runs": args.runs,
                }
                rows.append(row)
                print("%9d faces (proxy %d, refined %d): %4d patches of %7.0f faces, "
                      "parameterisation %7.2f s (%6.1f ms a patch, %.2f us a patch face), "
                      "wall %.1f s, %d elements" % (
                          row["input_faces"], row["proxy_faces"], row["base_faces"],
                          row["patches"], row["faces_per_patch"], param,
                          row["ms_per_patch"], row["us_per_patch_face"], row["wall_seconds"],
                          row["elements"]), flush=True)
            V, F = split_1_to_4(V, F)
    if args.out:
        with open(args.out, "w") as f:
            json.dump({"job": "stanford_bunny_70k split 1-to-4, apples, scale 0.1, patches, "
                              "normal embedding", "rows": rows}, f, indent=1)
            f.write("\n")


if __name__ == "__main__":
    sys.exit(main())
