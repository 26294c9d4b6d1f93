#!/usr/bin/env python3
"""Compares two benchmark results and fails on a slowdown.

Accepts, as OLD and NEW, either two bench/run_jobs.py result files, two Google Benchmark JSON
files (--benchmark_format=json or --benchmark_out output), or two directories of Google
Benchmark JSON files as written by bench/run_micro.sh (matched by benchmark name).

  bench/compare.py OLD.json NEW.json [--threshold 0.10] [--normalize]
  bench/compare.py --self-test

Exit status: 0 no regression, 1 a regression (or a job that ran before now fails), 2 usage or
input error. Python 3 standard library only.
"""

import argparse
import contextlib
import io
import json
import os
import statistics
import sys
import tempfile

DEFAULT_THRESHOLD = 0.10
DEFAULT_MIN_SECONDS = 0.05

UNIT_SECONDS = {"ns": 1e-9, "us": 1e-6, "ms": 1e-3, "s": 1.0}


class InputError(Exception):
    pass


# ---------------------------------------------------------------------------------------------
# Loading: every input becomes {"kind", "calibration", "entries": {key: seconds or None}}, where
# a key is "job/stage" (with "job/total" for the job's median wall time) or a benchmark name, and
# None marks a job that failed.


def load_json(path):
    try:
        with open(path) as f:
            return json.load(f)
    except OSError as e:
        raise InputError("cannot read %s: %s" % (path, e.strerror))
    except json.JSONDecodeError as e:
        raise InputError("%s is not JSON: line %d: %s" % (path, e.lineno, e.msg))


def from_run_jobs(data):
    entries = {}
    for job in data.get("jobs", []):
        name = job["name"]
        if job.get("status") == "skipped":
            continue
        if job.get("status") != "ok":
            entries[name + "/total"] = None
            continue
        entries[name + "/total"] = job["wall_seconds"]
        for stage, s in job.get("stage_seconds", {}).items():
            entries["%s/%s" % (name, stage)] = s
    scaling = data.get("scaling")
    if scaling:
        for p in scaling["points"]:
            entries["%s@x%d/total" % (scaling["job"], p["area_factor"])] = p["wall_seconds"]
    cal = data.get("calibration") or {}
    return {"kind": "jobs", "calibration": cal, "entries": entries}


def benchmark_seconds(b):
    return b["real_time"] * UNIT_SECONDS.get(b.get("time_unit", "ns"), 1e-9)


def from_google_benchmark(data, prefix=""):
    """Median aggregate when present, else mean, else the median of the plain iterations."""
    by_name = {}
    for b in data.get("benchmarks", []):
        if b.get("error_occurred"):
            by_name.setdefault(b.get("run_name", b["name"]), {})["error"] = True
            continue
        name = b.get("run_name", b["name"])
        slot = by_name.setdefault(name, {})
        if b.get("run_type") == "aggregate":
            slot[b.get("aggregate_name", "")] = benchmark_seconds(b)
        else:
            slot.setdefault("runs", []).append(benchmark_seconds(b))
    entries = {}
    for name, slot in by_name.items():
        key = prefix + name
        if "median" in slot:
            entries[key] = slot["median"]
        elif "mean" in slot:
            entries[key] = slot["mean"]
        elif slot.get("runs"):
            entries[key] = statistics.median(slot["runs"])
        else:
            entries[key] = None
    return entries


def load(path):
    if os.path.isdir(path):
        entries = {}
        files = sorted(f for f in os.listdir(path) if f.endswith(".json"))
        if not files:
            raise InputError("%s holds no .json files" % path)
        for f in files:
            data = load_json(os.path.join(path, f))
            if "benchmarks" not in data:
                raise InputError("%s is not a Google Benchmark JSON file" % os.path.join(path, f))
            entries.update(from_google_benchmark(data, os.path.splitext(f)[0] + ":"))
        return {"kind": "gbench", "calibration": {}, "entries": entries}
    data = load_json(path)
    if isinstance(data, dict) and "benchmarks" in data:
        return {"kind": "gbench", "calibration": {}, "entries": from_google_benchmark(data)}
    if isinstance(data, dict) and str(data.get("schema", "")).startswith("meshquilt-bench-result"):
        return from_run_jobs(data)
    raise InputError("%s is neither a run_jobs.py result nor Google Benchmark JSON" % path)


# ---------------------------------------------------------------------------------------------


def compare(old, new, threshold, min_seconds, normalize, out):
    """Prints the table; returns the number of regressions."""
    if old["kind"] != new["kind"]:
        raise InputError("cannot compare a %s file with a %s file" % (old["kind"], new["kind"]))
    scale_old = scale_new = 1.0
    if normalize:
        field = "python_seconds" if normalize == "python" else "seconds"
        co, cn = old["calibration"].get(field), new["calibration"].get(field)
        if not co or not cn:
            raise InputError("--normalize needs a calibration '%s' in both files" % field)
        scale_old, scale_new = 1.0 / co, 1.0 / cn
        print("normalized by calibration %s: old %.4g s, new %.4g s" % (field, co, cn), file=out)
    unit = "x cal" if normalize else "s"
    # Each job's total first, then its stages.
    keys = sorted(set(old["entries"]) | set(new["entries"]),
                  key=lambda k: (k.rpartition("/")[0], not k.endswith("/total"), k))
    width = max([len(k) for k in keys] + [10])
    print("%-*s %12s %12s %8s" % (width, "job/stage" if old["kind"] == "jobs" else "benchmark",
                                  "old " + unit, "new " + unit, "ratio"), file=out)
    regressions = 0
    for key in keys:
        o, n = old["entries"].get(key, "missing"), new["entries"].get(key, "missing")
        mark = ""
        if o == "missing" or n == "missing":
            mark = "  (only in %s)" % ("new" if o == "missing" else "old")
            o_text = "-" if o == "missing" else fmt(o, scale_old)
            n_text = "-" if n == "missing" else fmt(n, scale_new)
            print("%-*s %12s %12s %8s%s" % (width, key, o_text, n_text, "", mark), file=out)
            continue
        if n is None:
            if o is not None:
                regressions += 1
                mark = "  FAILED (regression)"
            else:
                mark = "  failed in both"
            print("%-*s %12s %12s %8s%s" % (width, key, fmt(o, scale_old), "failed", "", mark),
                  file=out)
            continue
        if o is None:
            print("%-*s %12s %12s %8s  fixed" % (width, key, "failed", fmt(n, scale_new), ""),
                  file=out)
            continue
        ov, nv = o * scale_old, n * scale_new
        ratio = nv / ov if ov > 0 else float("inf")
        # The noise floor applies to raw seconds of job stages; micro-benchmarks are already
        # repetition aggregates of tiny times.
        noisy = old["kind"] == "jobs" and max(o, n) < min_seconds
        if ratio > 1.0 + threshold and not noisy:
            regressions += 1
            mark = "  SLOWER"
        elif ratio < 1.0 - threshold and not noisy:
            mark = "  faster"
        print("%-*s %12.4g %12.4g %8.3f%s" % (width, key, ov, nv, ratio, mark), file=out)
    verdict = "%d regression(s) beyond +%.0f%%" % (regressions, threshold * 100)
    print(verdict if regressions else "no regression beyond +%.0f%%" % (threshold * 100),
          file=out)
    return regressions


def fmt(value, scale):
    return "failed" if value is None else "%.4g" % (value * scale)


def main(argv=None, out=None):
    out = out or sys.stdout
    ap = argparse.ArgumentParser(
        description="Compare two benchmark results (bench/run_jobs.py result files, Google "
                    "Benchmark JSON files, or directories of them from bench/run_micro.sh) and "
                    "exit 1 when anything got slower than the threshold.",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        epilog="The default threshold is 10%: medians of 3 runs on a shared 2-core machine vary\n"
               "by about 5-10%, so a smaller threshold flags noise. Job stages whose old and new\n"
               "times are both below --min-seconds are shown but never fail. A job that ran in\n"
               "OLD and failed in NEW counts as a regression. Exit status: 0 ok, 1 regression,\n"
               "2 usage or input error.")
    ap.add_argument("old", nargs="?", help="baseline result (file or run_micro.sh directory)")
    ap.add_argument("new", nargs="?", help="new result of the same kind")
    ap.add_argument("--threshold", type=float, default=DEFAULT_THRESHOLD,
                    help="allowed relative slowdown, new/old - 1 (default: %(default)s)")
    ap.add_argument("--min-seconds", type=float, default=DEFAULT_MIN_SECONDS,
                    help="job stages faster than this in both files never fail "
                         "(default: %(default)s)")
    ap.add_argument("--normalize", nargs="?", const="plane", choices=["plane", "python"],
                    help="divide each file's times by its calibration figure: 'plane' (default; "
                         "the tiny meshquilt job, best for comparing machines at one commit) or "
                         "'python' (a fixed interpreter workload, independent of meshquilt's "
                         "code)")
    ap.add_argument("--self-test", action="store_true",
                    help="check this script on synthetic files and exit")
    try:
        args = ap.parse_args(argv)
    except SystemExit as e:
        return e.code if isinstance(e.code, int) else 2
    if args.self_test:
        return self_test(out)
    if not args.old or not args.new:
        print("compare.py: OLD and NEW are required (see --help)", file=sys.stderr)
        return 2
    if not (args.threshold >= 0):
        print("compare.py: --threshold must be >= 0", file=sys.stderr)
        return 2
    try:
        old, new = load(args.old), load(args.new)
        regressions = compare(old, new, args.threshold, args.min_seconds, args.normalize, out)
    except InputError as e:
        print("compare.py: %s" % e, file=sys.stderr)
        return 2
    return 1 if regressions else 0


# ---------------------------------------------------------------------------------------------


def synthetic_result(scale, calibration, failed_job=False):
    jobs = [{"name": "plane_wire", "status": "ok", "wall_seconds": 10.0 * scale,
             "stage_seconds": {"matching": 7.0 * scale, "merging": 2.0 * scale,
                               "write": 0.01 * scale * 3}},
            {"name": "bunny_weave", "status": "skipped"}]
    if failed_job:
        jobs.append({"name": "plane_apple", "status": "failed", "error": "exit 1"})
    else:
        jobs.append({"name": "plane_apple", "status": "ok", "wall_seconds": 100.0 * scale,
                     "stage_seconds": {"matching": 90.0 * scale}})
    return {"schema": "meshquilt-bench-result/1", "jobs": jobs,
            "calibration": {"seconds": calibration, "python_seconds": calibration / 10}}


def synthetic_gbench(scale):
    bms = []
    for name, t in (("BM_TranslationCost/64", 1500.0), ("BM_ClosestPoint/1000", 80.0)):
        for agg, v in (("mean", t * 1.01), ("median", t), ("stddev", t * 0.02)):
            bms.append({"name": "%s_%s" % (name, agg), "run_name": name, "run_type": "aggregate",
                        "aggregate_name": agg, "real_time": v * scale, "cpu_time": v * scale,
                        "time_unit": "us"})
    return {"context": {"num_cpus": 2}, "benchmarks": bms}


def self_test(out):
    failures = []

    def check(what, argv, expected_ok):
        buf = io.StringIO()
        with contextlib.redirect_stderr(io.StringIO()):
            code = main(argv, out=buf)
        ok = (code == 0) == expected_ok and code in (0, 1)
        if not ok:
            failures.append("%s: exit %s\n%s" % (what, code, buf.getvalue()))
        print("self-test %-48s %s" % (what, "ok" if ok else "FAILED"), file=out)

    with tempfile.TemporaryDirectory(prefix="compare-selftest-") as d:
        def write(name, data):
            path = os.path.join(d, name)
            with open(path, "w") as f:
                json.dump(data, f)
            return path

        base = write("base.json", synthetic_result(1.0, 0.5))
        same = write("same.json", synthetic_result(1.0, 0.5))
        slow = write("slow.json", synthetic_result(1.3, 0.5))
        fast = write("fast.json", synthetic_result(0.7, 0.5))
        slower_machine = write("machine.json", synthetic_result(1.3, 0.65))
        broken = write("broken.json", synthetic_result(1.0, 0.5, failed_job=True))
        # Only a tiny stage got slower: below the noise floor, must not fail.
        data = synthetic_result(1.0, 0.5)
        data["jobs"][0]["stage_seconds"]["write"] = 0.045
        noise = write("noise.json", data)
        check("equal results pass", [base, same], True)
        check("30% slowdown fails", [base, slow], False)
        check("30% slowdown passes with --threshold 0.35", [base, slow, "--threshold", "0.35"],
              True)
        check("speedup passes", [base, fast], True)
        check("slow tiny stage below --min-seconds passes", [base, noise], True)
        check("job that now fails is a regression", [base, broken], False)
        check("slower machine fails without --normalize", [base, slower_machine], False)
        check("slower machine passes with --normalize", [base, slower_machine, "--normalize"],
              True)
        check("--normalize python", [base, slower_machine, "--normalize", "python"], True)
        check("--normalize still catches a real slowdown",
              [base, write("real.json", synthetic_result(1.3 * 1.3, 0.65)), "--normalize"], False)
        gb_old = write("gb_old.json", synthetic_gbench(1.0))
        gb_same = write("gb_same.json", synthetic_gbench(1.05))
        gb_slow = write("gb_slow.json", synthetic_gbench(1.3))
        check("Google Benchmark: equal within threshold passes", [gb_old, gb_same], True)
        check("Google Benchmark: 30% slowdown fails", [gb_old, gb_slow], False)
        os.makedirs(os.path.join(d, "micro_old"))
        os.makedirs(os.path.join(d, "micro_new"))
        for sub, scale in (("micro_old", 1.0), ("micro_new", 1.3)):
            with open(os.path.join(d, sub, "translation_cost_bench.json"), "w") as f:
                json.dump(synthetic_gbench(scale), f)
        check("run_micro.sh directories: slowdown fails",
              [os.path.join(d, "micro_old"), os.path.join(d, "micro_new")], False)
        # Mixed kinds and missing files are input errors (exit 2), not passes.
        with contextlib.redirect_stderr(io.StringIO()):
            mixed = main([base, gb_old], out=io.StringIO())
            missing = main([base, os.path.join(d, "nope.json")], out=io.StringIO())
        for what, code in (("mixed kinds are an input error", mixed),
                           ("missing file is an input error", missing)):
            print("self-test %-48s %s" % (what, "ok" if code == 2 else "FAILED"), file=out)
            if code != 2:
                failures.append("%s: exit %s" % (what, code))
    if failures:
        print("\n".join(failures), file=out)
        return 1
    print("self-test passed", file=out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
