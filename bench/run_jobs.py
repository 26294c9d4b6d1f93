#!/usr/bin/env python3
"""Runs the Table 1 benchmark jobs of bench/jobs.json with an already built meshquilt.

Each job's swatch is generated into a temporary directory, then the job runs --runs times with
--stats; the result JSON holds, per job, the median wall time, the median of every stage, the
peak resident memory, the output sizes, the paper's figures and the paper/ours time ratio, plus
the machine, the OpenCL device, the git commit and a calibration time measured in the same run.

  bench/run_jobs.py [--jobs a,b] [--runs N] [--build build] [-o result.json]
  bench/run_jobs.py --scaling plane_wire [-o scaling.json]

Python 3 standard library only. Compare two result files with bench/compare.py.
"""

import argparse
import datetime
import json
import math
import os
import platform
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

SCHEMA = "meshquilt-bench-result/1"
REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


class JobFailed(Exception):
    pass


def log(msg):
    print(msg, file=sys.stderr, flush=True)


def run_measured(argv, cwd=None):
    """Runs argv; returns (exit status, wall seconds, peak RSS in KiB, stderr text)."""
    start = time.perf_counter()
    proc = subprocess.Popen(argv, cwd=cwd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    # Read stderr before reaping so a chatty child cannot block on a full pipe; wait4 then gives
    # this child's own rusage (ru_maxrss in KiB on Linux).
    err = proc.stderr.read()
    proc.stderr.close()
    _, status, usage = os.wait4(proc.pid, 0)
    wall = time.perf_counter() - start
    proc.returncode = os.waitstatus_to_exitcode(status) if hasattr(os, "waitstatus_to_exitcode") \
        else (status >> 8)
    return proc.returncode, wall, usage.ru_maxrss, err.decode(errors="replace")


def last_line(text):
    lines = [l for l in text.strip().splitlines() if l.strip()]
    return lines[-1] if lines else ""


def has_command(meshquilt, command):
    try:
        r = subprocess.run([meshquilt, command, "--help"], stdout=subprocess.DEVNULL,
                           stderr=subprocess.DEVNULL, timeout=60)
        return r.returncode == 0
    except (OSError, subprocess.TimeoutExpired):
        return False


def generate_swatch(meshquilt, spec, path):
    argv = [meshquilt, "swatch", spec["kind"], *spec.get("args", []), "-o", path, "--quiet"]
    r = subprocess.run(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    if r.returncode != 0:
        raise JobFailed("swatch generation failed: %s: %s" %
                        (" ".join(argv[1:]), last_line(r.stderr.decode(errors="replace"))))


def mesh_counts(meshquilt, path):
    """Faces, vertices and elements of a mesh file, from 'meshquilt info'."""
    r = subprocess.run([meshquilt, "info", path], stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    counts = {}
    if r.returncode != 0:
        return counts
    for line in r.stdout.decode(errors="replace").splitlines():
        key, _, value = line.partition(":")
        key = key.strip()
        if key in ("faces", "vertices", "elements"):
            try:
                counts[key] = int(value.split()[0])
            except (ValueError, IndexError):
                pass
    return counts


def substitute(argv, values):
    return [a.format(**values) for a in argv]


def median(xs):
    return statistics.median(xs) if xs else None


def run_job_once(meshquilt, argv, workdir, tag, keep_output=False):
    out = os.path.join(workdir, tag + ".obj")
    stats_path = os.path.join(workdir, tag + ".json")
    if os.path.exists(stats_path):
        os.remove(stats_path)
    full = [meshquilt, *argv, "-o", out, "--stats", stats_path, "--quiet"]
    code, wall, rss, err = run_measured(full, cwd=REPO)
    if code != 0:
        raise JobFailed("exit %d: %s" % (code, last_line(err)))
    with open(stats_path) as f:
        stats = json.load(f)
    for p in (stats_path,) if keep_output else (out, stats_path):
        if os.path.exists(p):
            os.remove(p)
    return {"wall_seconds": wall, "max_rss_kib": rss, "stats": stats, "argv": full,
            "output_path": out}


def measure_floor(job_floor, job, values, output, runs):
    """The job's floor (bench/job_floor.cpp): reading its inputs, one closest-point query per
    output vertex against its base (or plane), writing its output again; medians of `runs`."""
    argv = [job_floor, "--swatch", values["swatch"], "--output", output, "--runs", str(runs)]
    if "base" in values:
        argv += ["--base", values["base"]]
    else:
        argv += ["--plane", values["length"], values["width"]]
    p = subprocess.run(argv, capture_output=True, text=True)
    if p.returncode != 0:
        raise JobFailed("job_floor exit %d: %s" % (p.returncode, last_line(p.stderr)))
    return json.loads(last_line(p.stdout))


def summarize_runs(runs):
    """Medians over runs of the wall time, the internal wall time and each stage's time."""
    stages = {}
    for r in runs:
        for stage, s in r["stats"].get("stage_seconds", {}).items():
            stages.setdefault(stage, []).append(s)
    last = runs[-1]["stats"]
    return {
        "runs": len(runs),
        "wall_seconds": median([r["wall_seconds"] for r in runs]),
        "wall_seconds_all": [round(r["wall_seconds"], 4) for r in runs],
        "internal_wall_seconds": median([r["stats"].get("wall_seconds", 0.0) for r in runs]),
        "stage_seconds": {k: median(v) for k, v in stages.items()},
        "max_rss_kib": max(r["max_rss_kib"] for r in runs),
        "output": last.get("output", {}),
        "iterations": last.get("iterations"),
        "device": last.get("device"),
        "threads": last.get("threads"),
    }


def finish_result(result, measured):
    """Medians of the measured runs and the ratios to the paper's figures and to the floor."""
    result["status"] = "ok"
    result.update(summarize_runs(measured))
    minutes = result["paper"].get("minutes")
    if minutes and result["wall_seconds"] > 0:
        result["paper_over_ours"] = minutes * 60.0 / result["wall_seconds"]
    floor = result.get("floor", {}).get("floor_seconds")
    if floor:
        result["over_floor"] = result["wall_seconds"] / floor
    paper_faces = result["paper"].get("output_faces")
    if paper_faces and result["output"].get("faces"):
        result["output_faces_over_paper"] = result["output"]["faces"] / paper_faces
    return result


def run_job(meshquilt, job, runs, workdir, available, job_floor=None, other=None):
    """Runs `job` `runs` times; with `other` (a second meshquilt) that binary's run follows each
    of meshquilt's (A B A B ...), so both see the same drift of the machine's speed. Returns
    meshquilt's result, and other's (None without it)."""
    result = {"name": job["name"], "paper_name": job.get("paper_name", job["name"]),
              "paper": job.get("paper", {})}
    required = job.get("requires")
    if required and not available(required):
        result["status"] = "skipped"
        result["reason"] = "needs the %s command" % required
        log("%-12s skipped: needs the %s command" % (job["name"], required))
        return result, (dict(result) if other else None)
    swatch = os.path.join(workdir, job["name"] + "_swatch.obj")
    values = {"swatch": swatch}
    try:
        generate_swatch(meshquilt, job["swatch"], swatch)
        result["swatch_command"] = "meshquilt swatch %s %s" % (
            job["swatch"]["kind"], " ".join(job["swatch"].get("args", [])))
        result["swatch"] = mesh_counts(meshquilt, swatch)
        if "base" in job:
            base = os.path.normpath(os.path.join(REPO, job["base"]))
            if not os.path.exists(base):
                raise JobFailed("base mesh not found: %s" % base)
            values["base"] = base
            result["base_path"] = job["base"]
            result["base"] = mesh_counts(meshquilt, base)
        if "size" in job:
            values["length"], values["width"] = (repr(float(x)) for x in job["size"])
        argv = substitute(job["argv"], values)
        shown = dict(values, swatch="SWATCH.obj", base=job.get("base", ""))
        result["command"] = "meshquilt " + " ".join(substitute(job["argv"], shown))
        measured, measured_other = [], []
        for i in range(runs):
            last = i == runs - 1
            r = run_job_once(meshquilt, argv, workdir, "%s_%d" % (job["name"], i),
                             keep_output=last and job_floor is not None)
            log("%-12s run %d/%d: %.2f s, %d MiB, %s faces" %
                (job["name"], i + 1, runs, r["wall_seconds"], r["max_rss_kib"] // 1024,
                 r["stats"].get("output", {}).get("faces")))
            measured.append(r)
            if other:
                o = run_job_once(other, argv, workdir, "%s_%d_vs" % (job["name"], i))
                log("%-12s run %d/%d (--vs): %.2f s, %d MiB" %
                    (job["name"], i + 1, runs, o["wall_seconds"], o["max_rss_kib"] // 1024))
                measured_other.append(o)
            if last and job_floor is not None:
                try:
                    result["floor"] = measure_floor(job_floor, job, values, r["output_path"],
                                                    runs)
                finally:
                    for ext in (".obj", ".mtl"):
                        p = os.path.splitext(r["output_path"])[0] + ext
                        if os.path.exists(p):
                            os.remove(p)
    except JobFailed as e:
        result["status"] = "failed"
        result["error"] = str(e)
        log("%-12s FAILED: %s" % (job["name"], e))
        return result, (dict(result) if other else None)
    other_result = None
    if other:
        other_result = finish_result(
            {k: v for k, v in result.items() if k not in ("status",)}, measured_other)
    return finish_result(result, measured), other_result


def calibrate(meshquilt, spec, workdir):
    """Median of N runs of a fixed tiny job (internal wall time, seconds), and a fixed pure-Python
    workload timed in-process (independent of meshquilt's code, for cross-commit comparisons)."""
    swatch = os.path.join(workdir, "calibration_swatch.obj")
    generate_swatch(meshquilt, spec["swatch"], swatch)
    argv = substitute(spec["argv"], {"swatch": swatch})
    shown = substitute(spec["argv"], {"swatch": "SWATCH.obj"})
    times = []
    for i in range(spec.get("runs", 5)):
        r = run_job_once(meshquilt, argv, workdir, "calibration_%d" % i)
        times.append(r["stats"].get("wall_seconds", r["wall_seconds"]))
    py = []
    for _ in range(5):
        start = time.perf_counter()
        acc = 0.0
        for k in range(1, 4000000):
            acc += math.sqrt(k) * 1e-3 / k
        py.append(time.perf_counter() - start)
    return {"seconds": median(times), "seconds_all": [round(t, 4) for t in times],
            "python_seconds": median(py),
            "swatch_command": "meshquilt swatch %s %s" % (spec["swatch"]["kind"],
                                                         " ".join(spec["swatch"].get("args", []))),
            "command": "meshquilt " + " ".join(shown),
            "description": spec.get("description", "")}


def cpu_model():
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.lower().startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def opencl_devices():
    exe = shutil.which("clinfo")
    if not exe:
        return None
    try:
        r = subprocess.run([exe, "-l"], stdout=subprocess.PIPE, stderr=subprocess.DEVNULL,
                           timeout=30)
        return r.stdout.decode(errors="replace").strip() or None
    except (OSError, subprocess.TimeoutExpired):
        return None


def git_commit():
    try:
        head = subprocess.run(["git", "-C", REPO, "rev-parse", "HEAD"], stdout=subprocess.PIPE,
                              stderr=subprocess.DEVNULL, check=True).stdout.decode().strip()
        dirty = subprocess.run(["git", "-C", REPO, "diff", "--quiet", "HEAD", "--"],
                               stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL).returncode
        return head + ("-dirty" if dirty else "")
    except (OSError, subprocess.CalledProcessError):
        return None


def machine_info():
    try:
        affinity = len(os.sched_getaffinity(0))
    except AttributeError:
        affinity = None
    try:
        load = os.getloadavg()
    except OSError:
        load = None
    return {"cpu": cpu_model(), "cores": os.cpu_count(), "usable_cores": affinity,
            "load_average_at_start": load, "system": platform.platform(),
            "hostname": platform.node()}


def find_meshquilt(build):
    for base in (os.getcwd(), REPO):
        exe = os.path.join(base, build, "meshquilt") if not os.path.isabs(build) else \
            os.path.join(build, "meshquilt")
        if os.path.isfile(exe) and os.access(exe, os.X_OK):
            return os.path.abspath(exe)
    return None


def scale_sizes(size, factor):
    s = math.sqrt(factor)
    return [x * s for x in size]


def scaled_argv(job, factor):
    """The job's argv with k times the output area: plane sizes times sqrt(k), or a surface's
    --scale (the swatch's size relative to the base) divided by sqrt(k)."""
    argv = list(job["argv"])
    values = {}
    if "size" in job:
        length, width = scale_sizes(job["size"], factor)
        values = {"length": "%.6g" % length, "width": "%.6g" % width}
    elif "--scale" in argv:
        i = argv.index("--scale") + 1
        argv[i] = "%.6g" % (float(argv[i]) / math.sqrt(factor))
    else:
        raise JobFailed("--scaling needs a plane job with a 'size' or a surface job with "
                        "--scale (got %s)" % job["name"])
    return argv, values


def run_scaling(meshquilt, job, runs, workdir):
    swatch = os.path.join(workdir, job["name"] + "_swatch.obj")
    generate_swatch(meshquilt, job["swatch"], swatch)
    base_path = os.path.join(REPO, job["base"]) if "base" in job else None
    points = []
    for factor in (1, 2, 4):
        template, values = scaled_argv(job, factor)
        argv = substitute(template, dict(values, swatch=swatch, base=base_path or ""))
        measured = []
        for i in range(runs):
            r = run_job_once(meshquilt, argv, workdir, "%s_x%d_%d" % (job["name"], factor, i))
            log("%-12s x%d run %d/%d: %.2f s, %d MiB" % (job["name"], factor, i + 1, runs,
                                                        r["wall_seconds"],
                                                        r["max_rss_kib"] // 1024))
            measured.append(r)
        s = summarize_runs(measured)
        shown = substitute(template, dict(values, swatch="SWATCH.obj", base=job.get("base", "")))
        s.update({"area_factor": factor, "command": "meshquilt " + " ".join(shown)})
        if "size" in job:
            s["size"] = [float(values["length"]), float(values["width"])]
        points.append(s)
    base = points[0]
    for p in points:
        p["time_growth"] = p["wall_seconds"] / base["wall_seconds"]
        p["memory_growth"] = p["max_rss_kib"] / base["max_rss_kib"]
        if base["output"].get("faces"):
            p["faces_growth"] = p["output"].get("faces", 0) / base["output"]["faces"]
    # Exponent k in time ~ area^k from the 1x and 4x points.
    exponent = math.log(points[-1]["wall_seconds"] / base["wall_seconds"]) / math.log(4)
    return {"job": job["name"], "points": points, "time_exponent": exponent}


def main(argv=None):
    ap = argparse.ArgumentParser(
        description="Run the Table 1 benchmark jobs (bench/jobs.json) with a built meshquilt.",
        epilog="Curved-surface jobs are skipped until 'meshquilt surface --help' succeeds.")
    ap.add_argument("--jobs", help="comma-separated job names (default: all)")
    ap.add_argument("--runs", type=int, default=3, help="runs per job; medians are reported "
                    "(default: 3)")
    ap.add_argument("--build", default="build", help="build directory holding meshquilt "
                    "(relative to the current directory or the repository; default: build)")
    ap.add_argument("--jobs-file", default=os.path.join(REPO, "bench", "jobs.json"))
    ap.add_argument("--scaling", metavar="JOB",
                    help="run a plane job at 1x, 2x and 4x the domain area instead")
    ap.add_argument("--no-calibration", action="store_true",
                    help="skip the calibration measurement")
    ap.add_argument("--no-floor", action="store_true",
                    help="skip each job's floor (job_floor in the build directory: reading the "
                    "inputs, one closest-point query per output vertex, writing the output)")
    ap.add_argument("--vs", metavar="BUILD",
                    help="a second build directory (the baseline): its meshquilt runs after each "
                    "run of this one, A B A B, on the same machine in the same minutes; its "
                    "result goes to --vs-output, for bench/compare.py")
    ap.add_argument("--vs-output", metavar="FILE", help="result JSON of the --vs build")
    ap.add_argument("-o", "--output", help="result JSON (default: stdout)")
    args = ap.parse_args(argv)
    if bool(args.vs) != bool(args.vs_output):
        ap.error("--vs and --vs-output go together")
    if args.runs < 1:
        ap.error("--runs must be at least 1")

    meshquilt = find_meshquilt(args.build)
    if not meshquilt:
        log("run_jobs: no executable meshquilt in '%s' (build it first: cmake --build %s)" %
            (args.build, args.build))
        return 2
    other = None
    if args.vs:
        other = find_meshquilt(args.vs)
        if not other:
            log("run_jobs: no executable meshquilt in '%s'" % args.vs)
            return 2
    job_floor = None
    if not args.no_floor:
        job_floor = os.path.join(os.path.dirname(meshquilt), "job_floor")
        if not os.access(job_floor, os.X_OK):
            log("run_jobs: no job_floor beside meshquilt (build it: cmake --build %s --target "
                "job_floor); floors not measured" % args.build)
            job_floor = None
    with open(args.jobs_file) as f:
        spec = json.load(f)
    jobs = {j["name"]: j for j in spec["jobs"]}
    if args.scaling:
        if args.scaling not in jobs:
            ap.error("unknown job '%s' (known: %s)" % (args.scaling, ", ".join(jobs)))
        selected = []
    elif args.jobs:
        names = [n.strip() for n in args.jobs.split(",") if n.strip()]
        unknown = [n for n in names if n not in jobs]
        if unknown:
            ap.error("unknown job(s) %s (known: %s)" % (", ".join(unknown), ", ".join(jobs)))
        selected = [jobs[n] for n in names]
    else:
        selected = spec["jobs"]

    commands = {}

    def available(command):
        if command not in commands:
            commands[command] = has_command(meshquilt, command)
        return commands[command]

    result = {
        "schema": SCHEMA,
        "date": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        "commit": git_commit(),
        "machine": machine_info(),
        "meshquilt": meshquilt,
        "runs": args.runs,
        "opencl_devices": opencl_devices(),
    }
    failed = False
    with tempfile.TemporaryDirectory(prefix="meshquilt-bench-") as workdir:
        try:
            if not args.no_calibration and "calibration" in spec:
                result["calibration"] = calibrate(meshquilt, spec["calibration"], workdir)
                log("calibration: %.3f s (python %.3f s)" % (result["calibration"]["seconds"],
                                                             result["calibration"]["python_seconds"]))
            if args.scaling:
                result["scaling"] = run_scaling(meshquilt, jobs[args.scaling], args.runs, workdir)
            result["jobs"] = []
            other_jobs = []
            for job in selected:
                r, o = run_job(meshquilt, job, args.runs, workdir, available, job_floor, other)
                failed |= r["status"] == "failed"
                result["jobs"].append(r)
                if o is not None:
                    other_jobs.append(o)
        except JobFailed as e:
            log("run_jobs: %s" % e)
            return 1
    devices = sorted({j.get("device") for j in result.get("jobs", []) if j.get("device")})
    if args.scaling:
        devices = sorted({p.get("device") for p in result["scaling"]["points"] if p.get("device")})
    result["device"] = ", ".join(devices) if devices else None
    text = json.dumps(result, indent=1, sort_keys=False) + "\n"
    if args.output:
        write_atomically(args.output, text)
    else:
        sys.stdout.write(text)
    if other:
        paired = dict(result, meshquilt=other, jobs=other_jobs, paired_with=meshquilt)
        paired.pop("calibration", None)  # measured with meshquilt's binary only
        write_atomically(args.vs_output, json.dumps(paired, indent=1) + "\n")
    print_table(result)
    return 1 if failed else 0


def write_atomically(path, text):
    tmp = path + ".tmp"
    with open(tmp, "w") as f:
        f.write(text)
    os.replace(tmp, path)


def print_table(result):
    rows = result.get("jobs", [])
    if rows:
        log("%-12s %9s %9s %9s %8s %8s %10s %10s %7s %8s" % (
            "job", "ours s", "paper min", "paper/us", "floor s", "x floor", "faces", "paper F",
            "F ratio", "MiB"))
        for r in rows:
            if r["status"] != "ok":
                log("%-12s %s" % (r["name"], r["status"] + ": " + r.get("reason",
                                                                         r.get("error", ""))))
                continue
            p = r["paper"]
            floor = r.get("floor", {}).get("floor_seconds")
            log("%-12s %9.2f %9s %9.1f %8s %8s %10s %10s %7.2f %8d" % (
                r["name"], r["wall_seconds"], p.get("minutes"), r.get("paper_over_ours", 0),
                "%.2f" % floor if floor else "-",
                "%.1f" % r["over_floor"] if "over_floor" in r else "-",
                r["output"].get("faces"), p.get("output_faces"),
                r.get("output_faces_over_paper", 0), r["max_rss_kib"] // 1024))
    if "scaling" in result:
        s = result["scaling"]
        log("scaling %s (time ~ area^%.2f):" % (s["job"], s["time_exponent"]))
        for p in s["points"]:
            log("  x%d area: %.2f s (x%.2f), %d MiB (x%.2f), %s faces" % (
                p["area_factor"], p["wall_seconds"], p["time_growth"], p["max_rss_kib"] // 1024,
                p["memory_growth"], p["output"].get("faces")))


if __name__ == "__main__":
    sys.exit(main())
