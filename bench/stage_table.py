#!/usr/bin/env python3
"""Prints, as a Markdown table, where each job of a bench/run_jobs.py result spends its time:
the median wall time, its floor (read, one closest-point query per output vertex, write), the
multiple of the floor, and the stages that take most of it, in seconds and shares.

  bench/stage_table.py RESULT.json [--top N]

Python 3 standard library only.
"""

import argparse
import json


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("result", help="a bench/run_jobs.py result file")
    parser.add_argument("--top", type=int, default=4, help="stages shown per job (4)")
    args = parser.parse_args()
    with open(args.result) as f:
        result = json.load(f)
    print("| job | s | floor s | x floor | largest stages (s, share of the run) |")
    print("|---|---|---|---|---|")
    for job in result["jobs"]:
        if job.get("status") != "ok":
            print("| %s | failed | | | |" % job["name"])
            continue
        wall = job["wall_seconds"]
        floor = job.get("floor", {}).get("floor_seconds")
        stages = sorted(job.get("stage_seconds", {}).items(), key=lambda kv: -kv[1])
        shown = ", ".join("%s %.2f (%.0f%%)" % (name, seconds, 100 * seconds / wall)
                          for name, seconds in stages[:args.top])
        print("| %s | %.2f | %s | %s | %s |" % (
            job["name"], wall, "%.2f" % floor if floor else "-",
            "%.1f" % (wall / floor) if floor else "-", shown))


if __name__ == "__main__":
    main()
