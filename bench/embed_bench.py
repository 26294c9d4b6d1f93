#!/usr/bin/env python3
"""Times re-embedding a saved quilt against the synthesis that made it (issue 25: embedding at
most a quarter of synthesis time), on the armor job (5 x 6 chain mail on the knight, scale 0.13):
the synthesis with --save-quilt, `embed` on the unchanged base (the same bytes, checked) and on
the knight bent 20 degrees (scripts/bend_base.py). Medians of --runs, interleaved, in one run.

  bench/embed_bench.py [--runs 3] [--build build] [--threads 2] [-o bench/results/embed_armor.json]

Python 3 standard library only.
"""

import argparse
import filecmp
import json
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def timed(argv, cwd):
    start = time.perf_counter()
    subprocess.run(argv, cwd=cwd, check=True, stdout=subprocess.DEVNULL)
    return time.perf_counter() - start


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--runs", type=int, default=3)
    p.add_argument("--build", default=os.path.join(REPO, "build"))
    p.add_argument("--threads", type=int, default=2)
    p.add_argument("-o", "--output", default=None)
    a = p.parse_args()
    mq = os.path.join(os.path.abspath(a.build), "meshquilt")
    knight = os.path.join(REPO, "..", "shared", "data", "base", "knight_decimated_1k.off")
    threads = ["--threads", str(a.threads)]
    with tempfile.TemporaryDirectory() as d:
        subprocess.run([mq, "swatch", "chainmail", "--rows", "5", "--cols", "6", "-o", "sw.obj",
                        "--quiet"], cwd=d, check=True)
        subprocess.run([sys.executable, os.path.join(REPO, "scripts", "bend_base.py"), knight,
                        "bent.off", "20"], cwd=d, check=True)
        times = {"synthesis": [], "embed_same_base": [], "embed_bent_20": []}
        for _ in range(a.runs):
            times["synthesis"].append(timed(
                [mq, "surface", "--base", knight, "--swatch", "sw.obj", "--scale", "0.13", "-o",
                 "rest.ply", "--save-quilt", "q.mqq", "--quiet"] + threads, d))
            times["embed_same_base"].append(timed(
                [mq, "embed", "--quilt", "q.mqq", "--base", knight, "-o", "same.ply", "--quiet"]
                + threads, d))
            if not filecmp.cmp(os.path.join(d, "rest.ply"), os.path.join(d, "same.ply"), False):
                sys.exit("embed on the unchanged base did not reproduce the synthesis")
            times["embed_bent_20"].append(timed(
                [mq, "embed", "--quilt", "q.mqq", "--base", "bent.off", "-o", "bent.ply",
                 "--quiet"] + threads, d))
    med = {k: statistics.median(v) for k, v in times.items()}
    result = {
        "job": "armor (knight_decimated_1k, chainmail 5x6, --scale 0.13)",
        "runs": a.runs, "threads": a.threads, "machine": platform.node(),
        "commit": subprocess.run(["git", "-C", REPO, "rev-parse", "--short", "HEAD"],
                                 capture_output=True, text=True).stdout.strip(),
        "seconds": times, "median_seconds": med,
        "embed_over_synthesis": {k: med[k] / med["synthesis"] for k in med if k != "synthesis"},
    }
    text = json.dumps(result, indent=2)
    print(text)
    if a.output:
        with open(a.output, "w") as f:
            f.write(text + "\n")


if __name__ == "__main__":
    main()
