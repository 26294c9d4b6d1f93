"""The one place the add-on runs the meshquilt engine.

Every engine call goes through `Job`: it starts the command-line tool in the background, reads
its machine progress lines (``--progress-lines``), and reports completion, the engine's error
message or a cancellation. A new engine command (e.g. re-embedding a saved quilt on an edited
base) is one more function that builds an argument list and returns a Job.
"""

import os
import queue
import re
import shutil
import signal
import subprocess
import threading
import time


class EngineError(Exception):
    """The engine could not be found or reported an error (its one-line message)."""


def find_engine(configured=""):
    """The meshquilt executable: the add-on preference, $MESHQUILT_ENGINE, or PATH."""
    for candidate in (configured, os.environ.get("MESHQUILT_ENGINE", ""), "meshquilt"):
        if not candidate:
            continue
        path = shutil.which(os.path.expanduser(candidate))
        if path:
            return path
    raise EngineError(
        "meshquilt engine not found: set its path in the add-on preferences "
        "(Edit > Preferences > Add-ons > meshquilt) or put meshquilt on PATH")


def _die_with_parent():
    """In the engine's process, before exec: Linux ends it with SIGTERM when Blender exits, so
    closing Blender mid-run leaves no engine behind (elsewhere the job's cancel() does)."""
    try:
        import ctypes
        PR_SET_PDEATHSIG = 1
        ctypes.CDLL(None, use_errno=True).prctl(PR_SET_PDEATHSIG, signal.SIGTERM)
    except (OSError, AttributeError):
        pass


def killed_message(signal_number):
    """The artist's words for an engine ended by a signal (a negative return code), not "-9"."""
    try:
        name = signal.Signals(signal_number).name
    except ValueError:
        name = "signal %d" % signal_number
    if signal_number == signal.SIGKILL:
        return ("the meshquilt engine was killed (%s), most often by the system when the "
                "machine's memory ran out: raise the Scale (fewer, larger elements) or use a "
                "swatch of fewer faces" % name)
    if signal_number in (signal.SIGSEGV, signal.SIGABRT, signal.SIGBUS, signal.SIGFPE,
                         signal.SIGILL):
        return ("the meshquilt engine crashed (%s): a bug in meshquilt; please report it with "
                "the base and the settings" % name)
    return "the meshquilt engine was stopped from outside (%s)" % name


# Typical seconds of a surface job's stages, in the order the engine reports them, as
# (stage, seconds at any detail, seconds more per unit of detail): a stage's weight at detail d
# (the share of each element's faces kept, a Preview's about 0.1) is a + b d. Fitted to runs
# on data/spot_6k.obj on 2 cores (2026-12-04; chain mail at --scale 0.08 with the global layout
# and with the patches at --detail 1 and 0.1, the sample ivy at --scale 0.05 at 1 and 0.25),
# each stage from its first progress line to the next stage's. A stage seen twice (embedding,
# placement check) has one weight per time. The first stage names the method.
STAGE_WEIGHTS = {
    "global": [("parameterization", .23, .01), ("tiling", 0, 0), ("placement", .03, .83),
               ("quilting", .15, .87), ("shell map", .07, .44), ("embedding", .01, .33),
               ("stretch optimization", .10, 0), ("embedding", .08, 6.96),
               ("placement check", .07, .12), ("fold repair", .02, 1.83),
               ("ring separation", .79, 2.69), ("element removal", .05, 1.20),
               ("placement check", 0, 1.13), ("coverage", 0, 3.40), ("writing", .03, 2.43)],
    "patches": [("quilting", .98, 8.90), ("shell map", .06, .28), ("embedding", .01, .16),
                ("stretch optimization", .08, .01), ("embedding", .10, 3.37),
                ("placement check", .04, .08), ("fold repair", .02, .03),
                ("ring separation", 0, 0), ("element removal", .01, .01),
                ("placement check", 0, .57), ("coverage", .06, 1.57), ("writing", .05, 1.24)],
    "vines": [("streamlines", 1.26, 4.25), ("leaves", 1.62, 9.57), ("shell map", .19, .35),
              ("embedding", .05, .20), ("stretch optimization", .17, .01),
              ("embedding", .65, 4.49), ("placement check", .17, .33), ("fold repair", 2.32, .27),
              ("ring separation", 1.84, .95), ("element removal", 1.92, .80),
              ("placement check", 0, .77), ("coverage", .22, 1.80), ("writing", .09, 1.36)],
}
FIRST_STAGE = {"parameterization": "global", "tiling": "global", "quilting": "patches",
               "streamlines": "vines", "stems": "vines", "leaves": "vines"}
UNKNOWN_STAGE_SHARE = 0.03  # a stage not in the table: this share of the job


class Progress:
    """One overall fraction of a job from the engine's per-stage progress lines: the finished
    stages' typical shares plus the current stage's share times its own fraction; it never
    decreases, stays under 1 until the job is done (finish()). `detail`: the job's (the share
    of each element's faces kept), which sets the stages' shares (STAGE_WEIGHTS)."""

    def __init__(self, detail=1.0):
        self.detail = min(1.0, max(0.0, float(detail)))
        self.sequence = None
        self.position = -1
        self.stage = None
        self.last_fraction = 0.0
        self.done = 0.0  # the finished stages' weights
        self.weight = 0.0  # the current stage's weight
        self.overall = 0.0

    def update(self, stage, fraction):
        fraction = min(1.0, max(0.0, fraction))
        if self.sequence is None:
            self.sequence = [(name, fixed + per_detail * self.detail) for name, fixed, per_detail
                             in STAGE_WEIGHTS[FIRST_STAGE.get(stage, "global")]]
            self.total = sum(w for _, w in self.sequence)
        if stage != self.stage or fraction < self.last_fraction:
            # A new stage (or the same one again: its fraction fell back).
            names = [n for n, _ in self.sequence]
            try:
                j = names.index(stage, self.position + 1)
                self.done = max(self.done + self.weight,
                                sum(w for _, w in self.sequence[:j]))
                self.position, self.weight = j, self.sequence[j][1]
            except ValueError:
                self.done += self.weight
                self.weight = UNKNOWN_STAGE_SHARE * self.total
            self.stage = stage
        self.last_fraction = fraction
        value = min(0.99, (self.done + self.weight * fraction) / self.total)
        self.overall = max(self.overall, value)
        return self.overall

    def finish(self):
        self.overall = 1.0


def time_left(elapsed, overall):
    """Seconds left from the time so far and the overall fraction (None below 3%)."""
    if overall < 0.03 or overall >= 1.0:
        return None
    return elapsed * (1.0 - overall) / overall


def progress_text(overall, elapsed, detail=""):
    """'meshquilt: 42% (ring separation), about 0:05 left'."""
    text = "meshquilt: %d%%" % int(100 * overall)
    if detail:
        text += " (%s)" % detail
    left = time_left(elapsed, overall)
    if left is not None:
        s = int(round(left))
        text += ", about %d:%02d left" % (s // 60, s % 60)
    return text


class Job:
    """One engine run in the background.

    poll() returns "running", "done", "failed" or "cancelled"; stage, fraction and remaining
    describe the latest progress line; error holds the engine's message once failed.
    """

    def __init__(self, engine, args, cwd=None, progress=True, detail=1.0):
        # --progress-lines: the synthesis commands' machine progress (the swatch generator
        # is quick and has none).
        self.args = [engine] + list(args) + (["--progress-lines"] if progress else [])
        self.stage = "starting"
        self.fraction = 0.0
        self.elapsed = 0.0
        self.remaining = -1.0
        self.error = ""
        self.state = "running"
        self.progress = Progress(detail)
        self._lines = queue.Queue()
        self._stderr_tail = []
        self._started = time.monotonic()
        try:
            self._process = subprocess.Popen(
                self.args, cwd=cwd, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                stderr=subprocess.PIPE, text=True, errors="replace",
                preexec_fn=_die_with_parent if os.name == "posix" else None)
        except OSError as e:
            raise EngineError("cannot start the meshquilt engine: %s" % e)
        self._reader = threading.Thread(target=self._read, daemon=True)
        self._reader.start()

    def _read(self):
        for line in self._process.stderr:
            self._lines.put(line.rstrip("\n"))
        self._lines.put(None)

    def _drain(self):
        while True:
            try:
                line = self._lines.get_nowait()
            except queue.Empty:
                return
            if line is None:
                continue
            self._line(line)

    def _line(self, line):
        """One stderr line: a progress line ('progress STAGE FRACTION ELAPSED REMAINING'; the
        stage may be several words, e.g. 'ring separation') or kept for the error message."""
        parts = line.split()
        if len(parts) >= 5 and parts[0] == "progress":
            try:
                fraction, elapsed, remaining = (float(x) for x in parts[-3:])
            except ValueError:
                pass
            else:
                self.stage = " ".join(parts[1:-3])
                self.fraction, self.elapsed, self.remaining = fraction, elapsed, remaining
                self.progress.update(self.stage, fraction)
                return
        if line.strip():
            self._stderr_tail = (self._stderr_tail + [line])[-20:]

    def poll(self):
        if self.state != "running":
            return self.state
        self._drain()
        code = self._process.poll()
        if code is None:
            return self.state
        self._reader.join(timeout=5)
        self._drain()
        if code == 0:
            self.state = "done"
            self.progress.finish()
        else:
            self.state = "failed"
            if code < 0:
                self.error = killed_message(-code)
            else:
                # The engine's error is its last line: "meshquilt surface: error: ..." or similar.
                self.error = self._stderr_tail[-1] if self._stderr_tail else (
                    "meshquilt exited with code %d" % code)
        return self.state

    def wait(self, timeout=None):
        """Blocks until the job ends (for scripts and tests); returns the final state."""
        deadline = None if timeout is None else time.monotonic() + timeout
        while self.poll() == "running":
            if deadline is not None and time.monotonic() > deadline:
                self.cancel()
                raise EngineError("meshquilt did not finish within %g s" % timeout)
            time.sleep(0.05)
        return self.state

    def cancel(self):
        """Stops the engine (SIGTERM: it removes its temporary files), waits for it to end."""
        if self.state != "running":
            return
        if self._process.poll() is None:
            self._process.send_signal(signal.SIGTERM)
            try:
                self._process.wait(timeout=10)
            except subprocess.TimeoutExpired:
                self._process.kill()
                self._process.wait()
        self._reader.join(timeout=5)
        self.state = "cancelled"

    @property
    def overall(self):
        """The job's overall fraction (Progress): monotone, 1 once done."""
        return self.progress.overall

    def status_text(self):
        """'meshquilt: 42% (ring separation), about 0:05 left' for Blender's status bar."""
        return progress_text(self.overall, time.monotonic() - self._started, self.stage)


def swatch_job(engine, kind, output, seed=1, frames=0):
    """Generates a sample swatch (chainmail, weave, apples, ivy); with frames > 0 (ivy only) a
    looping wind of that many frames, output a pattern with one integer field (frame 0 is the
    swatch itself)."""
    args = ["swatch", kind, "-o", output, "--seed", str(seed), "--quiet"]
    if frames > 0:
        args += ["--frames", str(int(frames))]
    return Job(engine, args, progress=False)


def surface_args(base, swatch, output, scale, seed=1, stretch=True, field=None,
                 field_file=None, threads=0, save_quilt=None, max_memory=None, stats=None,
                 element_size=0.0, detail=1.0, mask=None, size_map=None, swatch_frames=None,
                 frames=None):
    """The arguments of a surface job (surface_job; estimate with the same settings); an
    element_size > 0 (the swatch's longer side in the base's units) replaces the scale; a
    detail below 1 keeps that share of each swatch element's faces (the same layout);
    swatch_frames a pattern of the swatch's frames and frames (first, last) follow them, one
    output each (output a pattern then)."""
    size = ["--element-size", repr(float(element_size))] if element_size and \
        element_size > 0 else ["--scale", repr(float(scale))]
    args = ["surface", "--base", base, "--swatch", swatch, "-o", output] + size + \
        ["--seed", str(int(seed)), "--threads", str(int(threads))]
    if save_quilt:
        args += ["--save-quilt", save_quilt]
    if max_memory:
        args += ["--max-memory", "%.6g" % max_memory]  # a float32 property: 0.01 stays 0.01
    if stats:
        args += ["--stats", stats]
    if detail < 1:
        args += ["--detail", "%.6g" % detail]
    if not stretch:
        args.append("--no-stretch-opt")
    if field is not None:
        args += ["--field"] + [repr(float(c)) for c in field]
    if field_file:
        args += ["--field-file", field_file]
    if mask:
        args += ["--mask", mask]
    if size_map:
        args += ["--size-map", size_map]
    if swatch_frames:
        args += ["--swatch-frames", swatch_frames, "--frames", "%d-%d" % tuple(frames)]
    return args


def surface_job(engine, base, swatch, output, scale, **options):
    """Quilts the swatch over the base; options (surface_args): `field` an (x, y, z) direction
    or `field_file` a file of one vector per base vertex (at most one of them); `save_quilt`
    also saves the result over the base (.mqq) for embed_job; `max_memory` (GiB) refuses a
    larger job before any work; `stats` writes the run's figures as JSON; `detail` in (0, 1]
    keeps that share of each swatch element's faces; `mask` a file of one weight per base
    vertex (the texture only where it is 0.5 or more); `size_map` a file of one element size
    factor per base vertex."""
    return Job(engine, surface_args(base, swatch, output, scale, **options),
               detail=options.get("detail", 1.0))


def estimate(engine, base, swatch, output, scale, timeout=60, **options):
    """The engine's estimate of a surface job (--estimate: nothing is written, well under a
    second): {"faces", "bytes", "seconds", "fits"}. Blocks: for an operator, never draw()."""
    args = [engine] + surface_args(base, swatch, output, scale, **options) + \
        ["--estimate"]
    try:
        done = subprocess.run(args, stdin=subprocess.DEVNULL, capture_output=True, text=True,
                              errors="replace", timeout=timeout)
    except (OSError, subprocess.TimeoutExpired) as e:
        raise EngineError("cannot estimate the job: %s" % e)
    for line in done.stdout.splitlines():
        w = line.split()
        if len(w) == 9 and w[0] == "estimate":
            return {"faces": int(float(w[2])), "bytes": float(w[4]), "seconds": float(w[6]),
                    "fits": w[8] == "1"}
    lines = [l for l in done.stderr.splitlines() if l.strip()]
    raise EngineError(lines[-1] if lines else "meshquilt gave no estimate (exit %d)"
                      % done.returncode)


def machine_memory_gib():
    """The machine's memory in GiB (0 when it cannot be read)."""
    try:
        return os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES") / 2.0 ** 30
    except (ValueError, OSError, AttributeError):
        pass
    try:
        with open("/proc/meminfo") as f:
            for line in f:
                if line.startswith("MemTotal:"):
                    return int(line.split()[1]) / 2.0 ** 20
    except (OSError, ValueError, IndexError):
        pass
    return 0.0


def _size_setting(scale, element_size):
    """The panel's setting that sizes the elements and its value: ("Element size", "at Element
    size 0.05") when one is given, else ("Scale", "at Scale 0.1")."""
    knob = "Element size" if element_size > 0 else "Scale"
    return knob, "at %s %g" % (knob, element_size if element_size > 0 else scale)


def refusal_message(error, scale, limit_gib, element_size=0.0):
    """The artist's words for the engine refusing a job over --max-memory or --max-faces (None
    for any other error): what the job would need and what to change in Blender (the size by
    the panel's name for it: Element size when above 0, else Scale)."""
    if ("--max-memory" not in error and "--max-faces" not in error) or \
            "limit of" not in error:
        return None  # not a refusal (e.g. a value out of range)
    faces = re.search(r"about ([0-9.e+]+) faces", error)
    limit = re.search(r"limit of ([0-9.e+]+)", error)
    n = float(faces.group(1)) if faces else None
    # The engine's own rule: about 400 bytes a face. Its face limit (--max-faces, 2e7 by
    # default) can bind before the memory limit: then the memory limit is not what to raise.
    need_gib = n * 400 / 2.0 ** 30 if n is not None else None
    need = (" would make about %s faces (about %.2g GiB)" % (format(int(n), ","), need_gib)
            if n is not None else " is too large")
    knob, at = _size_setting(scale, element_size)
    if need_gib is not None and limit and need_gib <= limit_gib:
        return ("meshquilt: %s the texture%s, more than the engine's limit of %s faces: raise "
                "%s in the panel (fewer, larger elements) or lower Detail (fewer faces each)"
                % (at, need, format(int(float(limit.group(1))), ","), knob))
    return ("meshquilt: %s the texture%s, over the memory limit of %.3g GiB: raise %s in the "
            "panel (fewer, larger elements) or lower Detail (fewer faces each), or raise Memory "
            "limit in Edit > Preferences > Add-ons > meshquilt" % (at, need, limit_gib, knob))


def artist_message(error, scale, limit_gib, base="the base", swatch="the swatch",
                   element_size=0.0):
    """The artist's words for the engine's refusals that the panel's settings can cause: what
    is wrong with which object and what to change in the panel (refusal_message for the size
    and memory limits). Any other error is the engine's own line without its prefix. The size
    is named as the panel sets it: Element size when it is above 0, else Scale."""
    refused = refusal_message(error, scale, limit_gib, element_size)
    if refused:
        return refused
    text = error.split(": error: ", 1)[-1]
    knob, at = _size_setting(scale, element_size)
    smaller = "lower %s in the panel (smaller elements)" % knob
    if "has zero size" in text:
        return ("meshquilt: the base %s has zero size (all its vertices at one point): pick "
                "another base, or give it a size" % base)
    if "has no area" in text:
        return ("meshquilt: the base %s has no area (its faces are flat to lines or points): "
                "pick a base whose faces enclose area" % base)
    if "the swatch is flat" in text:
        return ("meshquilt: the swatch %s is flat: give it thickness (for example a Solidify "
                "modifier); the texture grows in a shell as thick as the swatch" % swatch)
    covered = re.match(r"only ([0-9.e+-]+)% of the base is covered, below ([0-9.e+-]+)%", text)
    if covered:
        got, needed = float(covered.group(1)), float(covered.group(2))
        if "elements were removed" in text:
            cause = "many elements met others or went inside it where its parts come close"
        elif "shell map was not built" in text:
            cause = "its shell could not be built over most of it"
        else:
            cause = "the elements are too large for its parts"
        return ("meshquilt: %s only %.0f%% of %s would be covered (%.0f%% needed): %s; %s; "
                "nothing was added" % (at, got, base, needed, cause, smaller))
    if text.startswith("the size map's largest value"):
        return "meshquilt: the Size group's sizes are too far apart: raise Smallest in the panel"
    if text.startswith("no element of the swatch could be placed"):
        return "meshquilt: %s no element of the swatch fits on %s: %s" % (at, base, smaller)
    if re.match(r"all [0-9]+ elements placed were removed", text):
        return ("meshquilt: %s every element placed on %s met another or went inside it: %s"
                % (at, base, smaller))
    return text


def info_job(engine, result, swatch, base, elements_csv, scale):
    """Measures a result's structure against its swatch (meshquilt info --links): one CSV line
    per element (its id, size ratio against its swatch element, ...)."""
    job = Job(engine, ["info", result, "--links", "--swatch", swatch, "--base", base,
                       "--scale", repr(float(scale)), "--elements", elements_csv],
              progress=False)
    job.stage = "measuring"
    return job


def embed_job(engine, quilt, base, output, frames=None, threads=0):
    """Places a saved quilt on its base with the vertices moved, without a new synthesis; with
    frames=(a, b), `base` and `output` are patterns with one frame number (%04d). No element is
    removed (--keep-elements): a result bound to its base keeps its faces and element ids in
    every frame; an element pressed into a neighbour follows the surface or shrinks instead."""
    args = ["embed", "--quilt", quilt, "--base", base, "-o", output,
            "--threads", str(int(threads))]
    if frames is not None:
        args += ["--frames", "%d-%d" % (int(frames[0]), int(frames[1]))]
    args.append("--keep-elements")
    return Job(engine, args)


def id_ranges(ids):
    """Sorted ids as the engine's list: [3, 7, 10, 11, 12] -> "3,7,10-12"."""
    parts, ids = [], sorted(set(int(i) for i in ids))
    start = prev = None
    for i in ids + [None]:
        if start is not None and i is not None and i == prev + 1:
            prev = i
            continue
        if start is not None:
            parts.append(str(start) if start == prev else "%d-%d" % (start, prev))
        start = prev = i
    return ",".join(parts)


def edit_job(engine, quilt, output, ids):
    """Removes the elements with these ids (the element_id of every output) from a saved
    quilt, writing a new one; the other elements keep their order (and are numbered again)."""
    return Job(engine, ["edit", "--quilt", quilt, "-o", output, "--ids", id_ranges(ids),
                        "--remove", "--quiet"], progress=False)
