"""The Blender add-on in real Blender, headless (issue 15). Run by scripts/test_blender.sh:

    blender -b --factory-startup --python-exit-code 1 --python tests/blender/test_addon.py -- \
        ENGINE ADDON_ZIP WORK_DIR

Installs the zipped add-on as a user would, then: registration; Run on a generated sphere with
the sample chain mail (an object parented to the base, element ids, one material per kind);
Cancel (the engine stops, no object, no files left); an engine error reported; the engine's OBJ
and .glb outputs through Blender's own importers with per-element data intact; selecting an
element by id; the result following its twisted base frame by frame (exactly the quilted result
at rest), stopping with the engine's message when the base's connectivity changes, baked into
shape keys that play without the engine, and elements removed from the saved quilt; a
command-line result through File > Import; the engine's estimate for the panel; the memory
limit refusing a job in the artist's words; the structure report on a result and selecting its
distorted elements; Detail in the engine's command, its estimate and the panel's faces per
element; a Preview replaced by the Run after it.
"""

import glob
import json
import math
import os
import struct
import sys
import time
import traceback

import bpy
import numpy as np

ENGINE, ZIP, WORK = sys.argv[sys.argv.index("--") + 1:][:3]
os.makedirs(WORK, exist_ok=True)
failures = []


def check(condition, message):
    if not condition:
        raise AssertionError(message)


def reported(operator, **properties):
    """The error an operator reports (its RuntimeError's text); fails when it reports none."""
    try:
        operator(**properties)
    except RuntimeError as e:
        return str(e)
    raise AssertionError("%s reported nothing" % operator.idname_py())


def test(fn):
    # MESHQUILT_BLENDER_TESTS=word: only the tests whose names contain it (and the install).
    only = os.environ.get("MESHQUILT_BLENDER_TESTS", "")
    if only and only not in fn.__name__ and fn.__name__ != "test_installs_and_registers":
        return fn
    start = time.monotonic()
    try:
        fn()
        print("[blender] PASS %s (%.1f s)" % (fn.__name__, time.monotonic() - start), flush=True)
    except Exception:
        failures.append(fn.__name__)
        print("[blender] FAIL %s\n%s" % (fn.__name__, traceback.format_exc()), flush=True)
    return fn


def new_scene():
    bpy.ops.wm.read_factory_settings(use_empty=True)
    enable_addon()
    return bpy.context.scene


def enable_addon():
    bpy.ops.preferences.addon_enable(module="meshquilt")
    bpy.context.preferences.addons["meshquilt"].preferences.engine_path = ENGINE


def sphere(name="Sphere", radius=1.0):
    bpy.ops.mesh.primitive_uv_sphere_add(radius=radius, segments=48, ring_count=24)
    obj = bpy.context.active_object
    obj.name = name
    return obj


def small_sphere(name="Sphere"):
    """A UV sphere of 16 x 8 segments: the engine quilts it in a few seconds at a large scale."""
    bpy.ops.mesh.primitive_uv_sphere_add(radius=1.0, segments=16, ring_count=8)
    obj = bpy.context.active_object
    obj.name = name
    return obj


class FakeLayout:
    """Records what a panel draws (labels and operators), for draw() tested headless."""

    def __init__(self, texts):
        self.texts = texts

    def label(self, text="", **kw):
        self.texts.append(text)

    def operator(self, idname, text=None, **kw):
        self.texts.append("op:%s" % idname)

    def prop(self, *args, **kw):
        self.texts.append("prop:%s" % (args[1] if len(args) > 1 else kw.get("property", "")))

    def row(self, **kw):
        return self

    column = box = split = row
    prop_search = prop


def drawn_panel():
    """The texts the meshquilt panel draws now; the engine must not run meanwhile."""
    import subprocess
    import meshquilt
    texts = []
    saved = subprocess.Popen, subprocess.run

    def refuse(*args, **kw):
        raise AssertionError("the panel ran a process while drawing")
    subprocess.Popen = subprocess.run = refuse
    try:
        panel = type("P", (), {"layout": FakeLayout(texts)})()
        meshquilt.MESHQUILT_PT_panel.draw(panel, bpy.context)
    finally:
        subprocess.Popen, subprocess.run = saved
    return texts


def face_ids(obj):
    ids = np.empty(len(obj.data.polygons), dtype=np.int32)
    obj.data.attributes["element_id"].data.foreach_get("value", ids)
    return ids


@test
def test_installs_and_registers():
    bpy.ops.preferences.addon_install(filepath=ZIP, overwrite=True)
    enable_addon()
    check("meshquilt" in bpy.context.preferences.addons, "add-on not enabled")
    check(hasattr(bpy.types.Scene, "meshquilt"), "scene settings not registered")
    for op in ("run", "preview", "cancel", "select_element", "bake", "clear_bake",
               "remove_selected", "estimate", "select_distorted"):
        check(hasattr(bpy.ops.meshquilt, op), "operator meshquilt.%s missing" % op)
    check(hasattr(bpy.ops.import_mesh, "meshquilt_ply"), "import operator missing")
    import meshquilt
    check(meshquilt._menu_import in bpy.types.TOPBAR_MT_file_import._dyn_ui_initialize(),
          "not in File > Import")
    prefs = bpy.context.preferences.addons["meshquilt"].preferences
    check(prefs.max_memory > 0.1, "memory limit %g GiB" % prefs.max_memory)
    check(hasattr(bpy.types, "MESHQUILT_PT_panel"), "panel not registered")
    s = bpy.context.scene.meshquilt
    check(s.stretch is True, "distortion minimisation must be on by default")
    import meshquilt.follow
    check(bpy.app.handlers.frame_change_post.count(meshquilt.follow.on_frame_change) == 1,
          "frame change handler not registered once")


@test
def test_run_on_a_sphere_with_sample_chain_mail():
    scene = new_scene()
    base = sphere()
    s = scene.meshquilt
    s.base = base
    s.swatch_source = "SAMPLE"
    s.sample = "chainmail"
    s.scale = 0.25
    before = set(bpy.data.objects)
    check(bpy.ops.meshquilt.run() == {"FINISHED"}, "run did not finish")
    added = [o for o in bpy.data.objects if o not in before]
    check(len(added) == 1, "expected one new object, got %d" % len(added))
    obj = added[0]
    check(obj.parent == base, "result not parented to the base")
    me = obj.data
    check(len(me.polygons) > 1000, "only %d faces" % len(me.polygons))
    check("element_id" in me.attributes and me.attributes["element_id"].domain == "FACE",
          "no element_id face attribute")
    check([m.name for m in me.materials] == ["ring"], "materials %s" % [m.name for m in me.materials])
    ids = face_ids(obj)
    # Ids number the loose parts 0..n-1: as many ids as rings, each ring one connected piece.
    n = int(ids.max()) + 1
    check(len(np.unique(ids)) == n, "element ids are not 0..%d" % (n - 1))
    check(n > 50, "only %d rings" % n)
    check(all(p.use_smooth for p in me.polygons[:100]), "not smooth shaded")
    check(me.validate() is False, "Blender had to repair the mesh")
    # Lies on the sphere's shell: every vertex within the shell of radius 1.
    V = np.empty(3 * len(me.vertices))
    me.vertices.foreach_get("co", V)
    r = np.linalg.norm(V.reshape(-1, 3), axis=1)
    check(r.min() > 0.9 and r.max() < 1.3, "vertices at radius %.3f..%.3f" % (r.min(), r.max()))
    # Selecting one element by id selects exactly its faces.
    bpy.context.view_layer.objects.active = obj
    check(bpy.ops.meshquilt.select_element(element=7) == {"FINISHED"}, "select failed")
    sel = np.empty(len(me.polygons), dtype=bool)
    me.polygons.foreach_get("select", sel)
    check(np.array_equal(sel, ids == 7), "selection is not element 7")


def ivy_swatch_object(scene, name):
    """The engine's ivy swatch as an object of the scene named `name`, read by the add-on's
    reader: two materials, vine and leaf."""
    import meshquilt
    from meshquilt import engine, exchange
    path = os.path.join(WORK, "%s.ply" % name)
    check(engine.swatch_job(ENGINE, "ivy", path).wait(60) == "done", "swatch failed")
    me = exchange.build_mesh(bpy, name, exchange.read_ply(path), meshquilt.material_for)
    obj = bpy.data.objects.new(name, me)
    scene.collection.objects.link(obj)
    return obj


@test
def test_object_swatch_kinds_come_from_its_materials():
    scene = new_scene()
    base = sphere()
    # A swatch object with two materials: the engine's ivy.
    swatch = ivy_swatch_object(scene, "ivy")
    me = swatch.data
    check([m.name for m in me.materials] == ["vine", "leaf"], "swatch materials %s"
          % [m.name for m in me.materials])
    # A material name with a space: the result reuses the swatch's own material.
    me.materials[1].name = "Leaf Green"
    s = scene.meshquilt
    s.base, s.swatch_source, s.swatch, s.scale = base, "OBJECT", swatch, 0.5
    s.stretch = False
    check(bpy.ops.meshquilt.run() == {"FINISHED"}, "run did not finish")
    obj = bpy.data.objects["Sphere_quilt"]
    names = sorted(m.name for m in obj.data.materials)
    check(names == ["Leaf Green", "vine"], "result materials %s" % names)
    check(obj.data.materials["Leaf Green"] == me.materials[1], "the swatch's material not reused")


@test
def test_guidance_by_an_objects_axis_and_by_a_vertex_attribute():
    scene = new_scene()
    base = sphere()
    s = scene.meshquilt
    s.base, s.sample, s.scale, s.stretch = base, "weave", 0.5, False
    bpy.ops.object.empty_add()
    guide = bpy.context.active_object
    guide.rotation_euler = (0.0, 1.2, 0.3)
    s.guidance, s.guide_object, s.guide_axis = "AXIS", guide, "X"
    check(bpy.ops.meshquilt.run() == {"FINISHED"}, "axis guidance run failed")
    bpy.data.objects.remove(bpy.data.objects["Sphere_quilt"])
    # A vector per vertex: the tangent of circles around z.
    attribute = base.data.attributes.new("guide", "FLOAT_VECTOR", "POINT")
    V = np.empty(3 * len(base.data.vertices))
    base.data.vertices.foreach_get("co", V)
    V = V.reshape(-1, 3)
    T = np.stack([-V[:, 1], V[:, 0], np.zeros(len(V))], axis=1)
    attribute.data.foreach_set("vector", T.ravel())
    s.guidance, s.guide_attribute = "ATTRIBUTE", "guide"
    check(bpy.ops.meshquilt.run() == {"FINISHED"}, "attribute guidance run failed")
    check("Sphere_quilt" in bpy.data.objects, "no result")
    s.guide_attribute = "missing"
    message = reported(bpy.ops.meshquilt.run)
    check("no vertex vector attribute" in message, "reported: %s" % message)


@test
def test_cancel_stops_the_engine_and_adds_nothing():
    scene = new_scene()
    base = sphere()
    s = scene.meshquilt
    s.base, s.sample, s.scale = base, "chainmail", 0.1  # 6,000 rings: about 20 s
    import meshquilt
    before = set(bpy.data.objects)
    run = meshquilt.Run(bpy.context, s)
    start = time.monotonic()
    # Until the engine has reported progress twice (it is well into the job).
    lines = 0
    last = None
    while run.step() == "running" and lines < 2:
        if run.job is not None and (run.job.stage, run.job.fraction) != last:
            last = (run.job.stage, run.job.fraction)
            lines += 1
        if time.monotonic() - start > 120:
            run.cancel()
            check(False, "no progress within 120 s")
        time.sleep(0.02)
    if run.state != "running":
        run.cleanup()
        check(False, "finished before it could be cancelled: %s" % run.state)
    process = run.job._process
    t = time.monotonic()
    run.cancel()
    check(process.poll() is not None, "engine still running after cancel")
    check(time.monotonic() - t < 10, "cancel took %.1f s" % (time.monotonic() - t))
    check(run.state == "cancelled", "state %s" % run.state)
    check(set(bpy.data.objects) == before, "cancel left an object")
    check(not os.path.exists(run.dir), "temporary directory left")


@test
def test_engine_error_is_reported():
    scene = new_scene()
    bpy.ops.mesh.primitive_plane_add()
    flat = bpy.context.active_object
    for v in flat.data.vertices:
        v.co = (0.0, 0.0, 0.0)  # a base of zero size: the engine refuses it by name
    s = scene.meshquilt
    s.base = flat
    import meshquilt
    run = meshquilt.Run(bpy.context, s)
    start = time.monotonic()
    while run.step() == "running":
        check(time.monotonic() - start < 60, "no answer within 60 s")
        time.sleep(0.05)
    check(run.state == "failed", "state %s" % run.state)
    check("size" in run.error or "degenerate" in run.error, "message: %r" % run.error)
    run.cleanup()
    before = set(bpy.data.objects)
    # The operator reports the engine's message as an error (a RuntimeError for a script).
    message = reported(bpy.ops.meshquilt.run)
    check("zero size" in message, "reported: %s" % message)
    check(set(bpy.data.objects) == before, "a failed run added an object")
    # A missing engine is an error too, not a crash.
    bpy.context.preferences.addons["meshquilt"].preferences.engine_path = "/nonexistent/meshquilt"
    os.environ.pop("MESHQUILT_ENGINE", None)
    path = os.environ.get("PATH", "")
    os.environ["PATH"] = "/nonexistent"
    try:
        message = reported(bpy.ops.meshquilt.run)
        check("engine not found" in message, "reported: %s" % message)
    finally:
        os.environ["PATH"] = path
        enable_addon()


@test
def test_refusals_the_panel_can_cause_are_in_the_artists_words():
    import meshquilt

    def refused(settings):
        run = meshquilt.Run(bpy.context, settings)
        try:
            start = time.monotonic()
            while run.step() == "running":
                check(time.monotonic() - start < 60, "no answer within 60 s")
                time.sleep(0.05)
            check(run.state == "failed", "state %s" % run.state)
            return run.error
        finally:
            run.cleanup()

    scene = new_scene()
    s = scene.meshquilt
    bpy.ops.mesh.primitive_plane_add()
    line = bpy.context.active_object
    line.name = "Flattened"
    for i, v in enumerate(line.data.vertices):
        v.co = (float(i), 0.0, 0.0)  # every face flat to a line
    s.base, s.sample, s.scale = line, "chainmail", 0.3
    message = refused(s)
    check("Flattened has no area" in message and "pick a base" in message, message)
    # A flat swatch object (a plane has no thickness).
    bpy.ops.mesh.primitive_plane_add()
    flat = bpy.context.active_object
    flat.name = "FlatSwatch"
    s.base, s.swatch_source, s.swatch = small_sphere(), "OBJECT", flat
    message = refused(s)
    check("FlatSwatch is flat" in message and "Solidify" in message, message)
    # On a strip narrower than a ring none fits: the fix is a smaller Scale, in the panel's
    # word, not the engine's --scale.
    s.swatch_source = "SAMPLE"
    bpy.ops.mesh.primitive_plane_add()
    strip = bpy.context.active_object
    strip.name = "Strip"
    for v in strip.data.vertices:
        v.co.y *= 0.05
    s.base, s.scale = strip, 0.5
    message = refused(s)
    check("fits on Strip" in message and "lower Scale" in message and "--" not in message,
          message)
    # Ivy as large as a tetrahedron leaves it mostly bare (the engine's own refusal).
    from meshquilt import engine
    tet = os.path.join(WORK, "tet.obj")
    with open(tet, "w") as f:
        f.write("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 3 4\nf 1 4 2\nf 2 4 3\n")
    swatch = os.path.join(WORK, "ivy_for_tet.obj")  # the command line's default seed
    job = engine.Job(ENGINE, ["swatch", "ivy", "-o", swatch, "--quiet"], progress=False)
    check(job.wait(60) == "done", "no swatch: %s" % job.error)
    job = engine.Job(ENGINE, ["surface", "--base", tet, "--swatch", swatch, "--scale", "0.9",
                              "-o", os.path.join(WORK, "tet_out.ply")])
    check(job.wait(120) == "failed" and "covered" in job.error, "%s: %s" % (job.state, job.error))
    message = engine.artist_message(job.error, 0.9, 8.0, "Tetrahedron")
    import re
    check(re.search(r"only [0-9]+% of Tetrahedron would be covered", message) and
          "lower Scale" in message and "--" not in message, message)


@test
def test_a_killed_or_crashed_engine_is_reported_in_words():
    """An engine ended by a signal (the kernel's out-of-memory killer sends SIGKILL) is reported
    as killed, with what to change, not as "exited with code -9" (issue 26)."""
    from meshquilt import engine
    for sig, words in ((9, "was killed (SIGKILL)"), (11, "crashed (SIGSEGV)")):
        fake = os.path.join(WORK, "engine_killed_%d" % sig)
        with open(fake, "w") as f:
            f.write("#!/bin/sh\nkill -%d $$\n" % sig)
        os.chmod(fake, 0o755)
        job = engine.surface_job(fake, "base.ply", "swatch.ply", os.path.join(WORK, "k.obj"), 0.1)
        check(job.wait(30) == "failed", "state %s" % job.state)
        check(words in job.error, "message: %r" % job.error)
    check("memory" in engine.killed_message(9), engine.killed_message(9))


@test
def test_import_a_command_line_result_with_element_ids_and_materials():
    """File > Import > meshquilt result (.ply): a result the engine wrote on the command line
    comes in with its element ids and a material per kind (issue 26)."""
    import subprocess
    scene = new_scene()
    from meshquilt import exchange
    base_obj = small_sphere()
    V, T, _ = exchange.mesh_arrays(base_obj.data)
    base = os.path.join(WORK, "import_base.ply")
    exchange.write_ply(base, V, T)
    sw, out = os.path.join(WORK, "import_weave.ply"), os.path.join(WORK, "cli result.ply")
    subprocess.run([ENGINE, "swatch", "weave", "-o", sw, "--quiet"], check=True)
    subprocess.run([ENGINE, "surface", "--base", base, "--swatch", sw, "--scale", "0.7",
                    "--no-stretch-opt", "-o", out, "--quiet"], check=True, timeout=120)
    header = open(out, "rb").read(4096).split(b"end_header")[0].decode("ascii", "replace")
    elements = int(header.split("comment meshquilt: ")[1].split()[0])
    before = set(bpy.data.objects)
    check(bpy.ops.import_mesh.meshquilt_ply(filepath=out) == {"FINISHED"}, "import failed")
    added = [o for o in bpy.data.objects if o not in before]
    check(len(added) == 1 and added[0].name == "cli result", "added %s" % added)
    obj = added[0]
    check(bpy.context.active_object == obj, "the import is not the active object")
    check(obj.data.attributes["element_id"].domain == "FACE", "no element_id face attribute")
    ids = face_ids(obj)
    check(len(np.unique(ids)) == elements and ids.max() == elements - 1,
          "%d ids for %d elements" % (len(np.unique(ids)), elements))
    check(sorted(m.name for m in obj.data.materials) == ["thread_x", "thread_y"],
          "materials %s" % [m.name for m in obj.data.materials])
    check(obj.data.validate() is False, "Blender had to repair the mesh")
    # Not a PLY: an error in words, no object.
    bad = os.path.join(WORK, "not_a_result.ply")
    open(bad, "w").write("hello\n")
    message = reported(bpy.ops.import_mesh.meshquilt_ply, filepath=bad)
    check("cannot read not_a_result.ply" in message, "reported: %s" % message)


@test
def test_estimate_for_the_current_settings_is_stored_for_the_panel():
    scene = new_scene()
    import meshquilt
    s = scene.meshquilt
    s.base, s.sample, s.scale = small_sphere(), "chainmail", 0.4
    check(s.estimate_key != meshquilt.estimate_key(bpy.context, s), "an estimate before asking")
    check(bpy.ops.meshquilt.estimate() == {"FINISHED"}, "estimate failed")
    check(s.estimate_key == meshquilt.estimate_key(bpy.context, s), "estimate not current")
    check(1e4 < s.estimate_faces < 1e7 and s.estimate_gib > 0 and s.estimate_seconds > 0
          and s.estimate_fits, "estimate %d faces %g GiB %g s fits %s" % (
              s.estimate_faces, s.estimate_gib, s.estimate_seconds, s.estimate_fits))
    text = meshquilt.estimate_text(s)
    check(text.startswith("~") and "faces" in text and "GiB" in text, "text %r" % text)
    check(text in drawn_panel(), "the panel does not show %r: %s" % (text, drawn_panel()))
    faces = s.estimate_faces
    s.scale = 0.2  # a setting changed: the panel no longer shows the old estimate
    check(s.estimate_key != meshquilt.estimate_key(bpy.context, s), "stale estimate kept")
    check("Size: not estimated" in drawn_panel(), "stale estimate shown")
    bpy.ops.meshquilt.estimate()
    check(s.estimate_faces > 2 * faces, "scale 0.2: %d faces, 0.4: %d" % (s.estimate_faces,
                                                                           faces))
    check(not [o for o in bpy.data.objects if o.name.endswith("_quilt")], "estimate added")


@test
def test_memory_limit_refuses_the_job_in_the_artists_words():
    scene = new_scene()
    import meshquilt
    s = scene.meshquilt
    s.base, s.sample, s.scale = small_sphere(), "chainmail", 0.4
    prefs = bpy.context.preferences.addons["meshquilt"].preferences
    prefs.max_memory = 0.01  # the engine's smallest: about 27,000 faces
    try:
        bpy.ops.meshquilt.estimate()
        check(not s.estimate_fits, "the estimate fits a limit of 10 MiB")
        before = set(bpy.data.objects)
        start = time.monotonic()
        message = reported(bpy.ops.meshquilt.run)
        check("memory limit of" in message and "raise Scale" in message and
              "lower Detail" in message and "Memory limit" in message and
              "--max" not in message, "reported: %s" % message)
        check(time.monotonic() - start < 15, "refused after %.1f s" % (time.monotonic() - start))
        check(set(bpy.data.objects) == before, "a refused run added an object")
        # The engine's face limit (--max-faces) binding below the memory limit: the memory
        # limit is not what to raise.
        faces = meshquilt.engine.refusal_message(
            "at --scale 0.01 the texture would have about 2.5e+07 faces, more than the limit "
            "of 2e+07 (--max-faces, or --max-memory at 400 bytes a face); use a larger "
            "--scale", 0.01, 12.0)
        check("limit of 20,000,000 faces" in faces and "lower Detail" in faces and
              "Memory limit" not in faces,
              "reported: %s" % faces)
        # Sized by Element size: that is the setting named.
        sized = meshquilt.engine.artist_message(
            "meshquilt surface: error: at --element-size 0.05 the texture would have about "
            "2.5e+07 faces, more than the limit of 2e+07 (--max-faces, or --max-memory at 400 "
            "bytes a face); use a larger --element-size", 0.01, 12.0, element_size=0.05)
        check("at Element size 0.05" in sized and "raise Element size" in sized and
              "Scale" not in sized, "reported: %s" % sized)
    finally:
        enable_addon()
        prefs.max_memory = meshquilt._DEFAULT_LIMIT_GIB


def quilted_small_sphere():
    scene = new_scene()
    s = scene.meshquilt
    s.base, s.sample, s.scale = small_sphere(), "chainmail", 0.5
    check(bpy.ops.meshquilt.run() == {"FINISHED"}, "run did not finish")
    return scene, bpy.data.objects["Sphere_quilt"]


@test
def test_structure_report_is_stored_on_the_result():
    scene, obj = quilted_small_sphere()
    report = obj.get("meshquilt_report")
    check(report is not None, "no report on the result")
    ids = face_ids(obj)
    check(report["elements"] == len(np.unique(ids)), "%d elements for %d ids"
          % (report["elements"], len(np.unique(ids))))
    check(50 <= report["links_kept"] <= 100, "links kept %g%%" % report["links_kept"])
    check(90 <= report["coverage"] <= 100, "coverage %g%%" % report["coverage"])
    distorted = list(obj["meshquilt_distorted_ids"])
    check(report["distorted"] == len(distorted) and all(0 <= i <= ids.max() for i in distorted),
          "distorted %d: %s" % (report["distorted"], distorted))
    bpy.context.view_layer.objects.active = obj
    texts = drawn_panel()
    for text in ("Elements: %d" % report["elements"], "Coverage: %.0f%%" % report["coverage"],
                 "Links kept: %.0f%%" % report["links_kept"],
                 "Over 1.5x size: %d" % report["distorted"]):
        check(text in texts, "the panel does not show %r: %s" % (text, texts))


@test
def test_the_engines_structure_warnings_are_shown_on_the_result():
    """A result whose structure the engine's own check finds short (issue 23) carries the
    warnings into the panel's Structure box; one within the limits carries none."""
    import subprocess
    import meshquilt
    scene = new_scene()
    from meshquilt import exchange
    base_obj = small_sphere()
    V, T, _ = exchange.mesh_arrays(base_obj.data)
    base = os.path.join(WORK, "check_base.ply")
    exchange.write_ply(base, V, T)
    sw = os.path.join(WORK, "check_sheet.obj")
    subprocess.run([ENGINE, "swatch", "chainmail", "--rows", "2", "--cols", "4", "-o", sw,
                    "--quiet"], check=True)
    reports = {}
    for method in ("patches", "global"):
        out, stats = (os.path.join(WORK, "check_%s.%s" % (method, e)) for e in ("ply", "json"))
        done = subprocess.run([ENGINE, "surface", "--base", base, "--swatch", sw, "--scale",
                               "0.3", "--method", method, "-o", out, "--stats", stats,
                               "--quiet"], capture_output=True, text=True, timeout=120)
        check(done.returncode == 0, done.stderr)
        reports[method] = exchange.structure_report(stats)
    warned = reports["patches"].get("warnings", "")
    check("of interior rings keep their swatch's links" in warned and "(gaps)" in warned,
          "patches: %r" % warned)
    check("warnings" not in reports["global"], "global: %r" % reports["global"])
    obj = bpy.data.objects.new("Checked", bpy.data.meshes.new("Checked"))
    obj.data.attributes.new("element_id", "INT", "FACE")  # what the panel knows a result by
    scene.collection.objects.link(obj)
    meshquilt.store_report(obj, reports["patches"])
    bpy.context.view_layer.objects.active = obj
    texts = drawn_panel()
    for warning in warned.split("; "):
        check(warning in texts, "the panel does not show %r: %s" % (warning, texts))


@test
def test_select_distorted_selects_their_faces_and_follows_removals():
    scene, obj = quilted_small_sphere()
    import meshquilt
    ids = face_ids(obj)
    if not obj["meshquilt_distorted_ids"]:
        # This sphere quilts without distortion; the ids as a run over a bent base stores them.
        obj["meshquilt_distorted_ids"] = [2, 5, 9]
        obj["meshquilt_report"]["distorted"] = 3
    distorted = list(obj["meshquilt_distorted_ids"])
    bpy.context.view_layer.objects.active = obj
    check(bpy.ops.meshquilt.select_distorted() == {"FINISHED"}, "select failed")
    sel = np.empty(len(obj.data.polygons), dtype=bool)
    obj.data.polygons.foreach_get("select", sel)
    check(np.array_equal(sel, np.isin(ids, distorted)), "selection is not the distorted elements")
    # Removing elements numbers the rest again: the stored ids move with them.
    obj["meshquilt_distorted_ids"] = [2, 5, 9]
    elements = obj["meshquilt_report"]["elements"]
    meshquilt._report_after_removal(obj, np.array([2, 3]))
    check(list(obj["meshquilt_distorted_ids"]) == [3, 7], "ids %s"
          % list(obj["meshquilt_distorted_ids"]))
    check(obj["meshquilt_report"]["distorted"] == 2 and
          obj["meshquilt_report"]["elements"] == elements - 2, "report %s"
          % obj["meshquilt_report"].to_dict())


def engine_output(name):
    """A small job written by the engine itself (OBJ with groups, .glb), for the importers."""
    from meshquilt import engine
    sw = os.path.join(WORK, "weave.ply")
    check(engine.swatch_job(ENGINE, "weave", sw).wait(60) == "done", "swatch failed")
    base = os.path.join(WORK, "base.ply")
    from meshquilt import exchange
    u, v = np.meshgrid(np.linspace(0, 1, 21), np.linspace(0, 1, 21))
    V = np.stack([u.ravel(), v.ravel(), np.zeros(u.size)], axis=1)
    idx = np.arange(441).reshape(21, 21)
    a, b, c, d = idx[:-1, :-1].ravel(), idx[:-1, 1:].ravel(), idx[1:, 1:].ravel(), idx[1:, :-1].ravel()
    exchange.write_ply(base, V, np.concatenate([np.stack([a, b, c], 1), np.stack([a, c, d], 1)]))
    out = os.path.join(WORK, name)
    job = engine.surface_job(ENGINE, base, sw, out, 0.3, stretch=False)
    check(job.wait(120) == "done", "engine failed: %s" % job.error)
    return out


@test
def test_obj_split_by_objects_gives_one_object_per_element():
    new_scene()
    path = engine_output("weave_quilt.obj")
    elements = sum(1 for line in open(path) if line.startswith("o "))
    # Blender 3.4's OBJ importer (File > Import > Wavefront) makes one object per "o".
    bpy.ops.wm.obj_import(filepath=path)
    objs = [o for o in bpy.data.objects if o.type == "MESH"]
    check(len(objs) == elements, "%d objects for %d elements" % (len(objs), elements))
    kinds = {o.name.rsplit("_", 1)[0] for o in objs}
    check(kinds == {"thread_x", "thread_y"}, "object kinds %s" % kinds)
    for o in objs:
        mats = [m.name for m in o.data.materials]
        check(len(mats) == 1 and o.name.startswith(mats[0]), "%s has materials %s" % (o.name, mats))
        check(o.data.polygons[0].use_smooth or any(l.normal for l in o.data.loops[:1]),
              "no normals on %s" % o.name)


@test
def test_glb_imports_with_materials_and_has_the_element_id_attribute():
    new_scene()
    path = engine_output("weave_quilt.glb")
    data = open(path, "rb").read()
    json_length = struct.unpack("<I", data[12:16])[0]
    gltf = json.loads(data[20:20 + json_length])
    prims = gltf["meshes"][0]["primitives"]
    for p in prims:
        check("_ELEMENT_ID" in p["attributes"], "no _ELEMENT_ID attribute")
        check(gltf["accessors"][p["attributes"]["_ELEMENT_ID"]]["count"] ==
              gltf["accessors"][p["attributes"]["POSITION"]]["count"], "id count differs")
    # Debian 12's Blender 3.4 importer fails in its default "NORMALS" shading mode (it uses
    # numpy.bool, gone in numpy 1.24); "SMOOTH" takes the file's normals as they are.
    bpy.ops.import_scene.gltf(filepath=path, import_shading="SMOOTH")
    objs = [o for o in bpy.data.objects if o.type == "MESH"]
    check(len(objs) == 1, "%d objects" % len(objs))
    mats = sorted(m.name for m in objs[0].data.materials)
    check(mats == ["thread_x", "thread_y"], "materials %s" % mats)
    faces = sum(gltf["accessors"][p["indices"]]["count"] // 3 for p in prims)
    check(len(objs[0].data.polygons) == faces, "%d faces for %d" % (len(objs[0].data.polygons), faces))


def positions(obj, evaluated=False):
    """The object's vertex positions: its mesh's, or evaluated (shape keys applied)."""
    if evaluated:
        ev = obj.evaluated_get(bpy.context.evaluated_depsgraph_get())
        me = ev.to_mesh()
        try:
            V = np.empty(3 * len(me.vertices))
            me.vertices.foreach_get("co", V)
        finally:
            ev.to_mesh_clear()
        return V.reshape(-1, 3)
    V = np.empty(3 * len(obj.data.vertices))
    obj.data.vertices.foreach_get("co", V)
    return V.reshape(-1, 3)


def small_chainmail_path():
    """A chain mail of 16 rings of 64 faces (`swatch chainmail --detail 6`), made once."""
    from meshquilt import engine
    path = os.path.join(WORK, "small_chainmail.ply")
    if not os.path.exists(path):
        job = engine.Job(ENGINE, ["swatch", "chainmail", "-o", path, "--rows", "4", "--cols",
                                  "4", "--detail", "6", "--quiet"], progress=False)
        check(job.wait(60) == "done", "swatch failed: %s" % job.error)
    return path


def twisting_grid_quilt():
    """A 12 x 12 grid twisted about y by a Simple Deform modifier keyed from 0 (frame 0, the
    rest) to 90 degrees (frame 24), quilted at rest with a small chain mail (16 rings of 64 faces): about
    60 rings, 4,000 faces. Returns the scene, the base and the result."""
    scene = new_scene()
    import meshquilt
    from meshquilt import exchange
    swatch = bpy.data.objects.new("mail", exchange.build_mesh(
        bpy, "mail", exchange.read_ply(small_chainmail_path()), meshquilt.material_for))
    scene.collection.objects.link(swatch)
    bpy.ops.mesh.primitive_grid_add(x_subdivisions=13, y_subdivisions=13, size=2)
    base = bpy.context.active_object
    base.name = "Grid"
    bend = base.modifiers.new("twist", "SIMPLE_DEFORM")
    bend.deform_method, bend.deform_axis = "TWIST", "Y"
    bend.angle = 0.0
    bend.keyframe_insert("angle", frame=0)
    bend.angle = math.radians(90)
    bend.keyframe_insert("angle", frame=24)
    scene.frame_start, scene.frame_end = 1, 24
    scene.frame_set(0)
    s = scene.meshquilt
    s.base, s.swatch_source, s.swatch, s.scale, s.stretch = base, "OBJECT", swatch, 0.4, False
    check(bpy.ops.meshquilt.run() == {"FINISHED"}, "run did not finish")
    return scene, base, bpy.data.objects["Grid_quilt"]


@test
def test_follow_base_places_the_result_on_the_deformed_base_every_frame():
    scene, base, obj = twisting_grid_quilt()
    b = obj.meshquilt
    check(b.base == base, "result not bound to its base")
    quilt = bpy.path.abspath(b.quilt)
    check(quilt.endswith(".mqq") and os.path.isfile(quilt), "no saved quilt at %r" % b.quilt)
    rest, ids, faces = positions(obj), face_ids(obj), len(obj.data.polygons)
    check(faces > 1000, "only %d faces" % faces)
    # The handler leaves results that do not follow alone.
    scene.frame_set(12)
    check(np.array_equal(positions(obj), rest), "a result not following moved")
    b.follow = True  # placed at once on the base as it is (twisted at frame 12)
    bent = positions(obj)
    check(np.abs(bent - rest).max() > 0.05, "the result did not move with the base")
    for frame in (6, 18, 24):
        scene.frame_set(frame)
        V = positions(obj)
        check(np.abs(V - bent).max() > 1e-3, "frame %d: the result did not move" % frame)
        check(len(obj.data.polygons) == faces, "frame %d: %d faces for %d"
              % (frame, len(obj.data.polygons), faces))
        check(np.array_equal(face_ids(obj), ids), "frame %d: element ids changed" % frame)
        bent = V
    # Back at the rest pose: the synthesis's own positions, exactly.
    scene.frame_set(0)
    check(np.array_equal(positions(obj), rest), "frame 0 differs from the quilted result by %g"
          % np.abs(positions(obj) - rest).max())
    check(b.follow and b.status == "", "status: %r" % b.status)
    # Moving the base object carries the result by the parenting; the shape is unchanged.
    base.location = (3.0, 0.0, 0.0)
    scene.frame_set(0)
    check(np.array_equal(positions(obj), rest), "moving the base object changed the shape")
    check(abs(obj.matrix_world.translation.x - 3.0) < 1e-6, "the result did not go with its base")


@test
def test_follow_stops_with_the_engines_message_when_the_base_connectivity_changes():
    scene, base, obj = twisting_grid_quilt()
    obj.meshquilt.follow = True
    scene.frame_set(5)
    moved = positions(obj)
    base.modifiers.new("subdivide", "SUBSURF").levels = 1
    scene.frame_set(6)
    b = obj.meshquilt
    check(not b.follow, "still following a base of other connectivity")
    check("the quilt was made on one of" in b.status and "meshquilt embed" in b.status,
          "status: %r" % b.status)
    check(np.array_equal(positions(obj), moved), "the result changed")
    # Switching it on again reports the same at once; without the modifier it follows again.
    b.follow = True
    check(not b.follow and "the quilt was made on" in b.status, "status: %r" % b.status)
    base.modifiers.remove(base.modifiers["subdivide"])
    b.follow = True
    check(b.follow and b.status == "", "status: %r" % b.status)


@test
def test_bake_keeps_every_frame_in_shape_keys_and_plays_without_the_engine():
    scene, base, obj = twisting_grid_quilt()
    rest, faces = positions(obj), len(obj.data.polygons)
    # The followed positions at frame 12, for the bake to match.
    obj.meshquilt.follow = True
    scene.frame_set(12)
    followed = positions(obj)
    scene.frame_set(0)
    bpy.context.view_layer.objects.active = obj
    start = time.monotonic()
    check(bpy.ops.meshquilt.bake() == {"FINISHED"}, "bake failed")
    print("[blender]   bake of 24 frames: %.1f s" % (time.monotonic() - start), flush=True)
    b = obj.meshquilt
    check(b.baked and not b.follow, "baked %s, follow %s" % (b.baked, b.follow))
    key = obj.data.shape_keys
    check(key is not None and not key.use_relative, "no absolute shape keys")
    check(len(key.key_blocks) == 24, "%d shape keys" % len(key.key_blocks))
    # Playback needs no engine.
    prefs = bpy.context.preferences.addons["meshquilt"].preferences
    prefs.engine_path = "/nonexistent/meshquilt"
    path = os.environ.get("PATH", "")
    os.environ["PATH"] = "/nonexistent"
    try:
        previous = None
        for frame in range(1, 25):
            scene.frame_set(frame)
            V = positions(obj, evaluated=True)
            check(len(V) == len(rest) and len(obj.data.polygons) == faces,
                  "frame %d: connectivity changed" % frame)
            if previous is not None:
                check(np.abs(V - previous).max() > 1e-4, "frame %d equals the one before" % frame)
            if frame == 12:
                check(np.allclose(V, followed, atol=1e-5), "frame 12 differs from following by %g"
                      % np.abs(V - followed).max())
            previous = V
        check(b.status == "", "status: %r" % b.status)
    finally:
        os.environ["PATH"] = path
        prefs.engine_path = ENGINE
    check(bpy.ops.meshquilt.clear_bake() == {"FINISHED"}, "clear bake failed")
    check(obj.data.shape_keys is None and not b.baked, "bake not cleared")


@test
def test_remove_selected_elements_removes_them_from_the_quilt():
    scene, base, obj = twisting_grid_quilt()
    ids = face_ids(obj)
    elements = len(np.unique(ids))
    old_quilt = obj.meshquilt.quilt
    bpy.context.view_layer.objects.active = obj
    obj.select_set(True)
    bpy.ops.meshquilt.select_element(element=3)
    bpy.ops.meshquilt.select_element(element=7, extend=True)
    bpy.ops.meshquilt.select_element(element=elements - 1, extend=True)
    removed_faces = int(np.isin(ids, [3, 7, elements - 1]).sum())
    scene.frame_set(10)  # the base twisted: the rest placed on it as it is now
    bpy.ops.object.mode_set(mode="EDIT")
    check(bpy.ops.meshquilt.remove_selected() == {"FINISHED"}, "remove failed")
    check(obj.mode == "EDIT", "edit mode not restored")
    bpy.ops.object.mode_set(mode="OBJECT")
    after = face_ids(obj)
    check(len(np.unique(after)) == elements - 3, "%d elements for %d - 3"
          % (len(np.unique(after)), elements))
    check(int(after.max()) == elements - 4, "ids are not 0..%d" % (elements - 4))
    check(len(obj.data.polygons) == len(ids) - removed_faces, "%d faces for %d"
          % (len(obj.data.polygons), len(ids) - removed_faces))
    check(obj.meshquilt.quilt != old_quilt, "the saved quilt was not replaced")
    check([m.name for m in obj.data.materials] == ["ring"], "materials %s"
          % [m.name for m in obj.data.materials])
    check(obj.data.validate() is False, "Blender had to repair the mesh")
    # Placed on the twisted base, and still following it.
    V = positions(obj)
    obj.meshquilt.follow = True
    check(np.array_equal(positions(obj), V), "not placed on the base of frame 10")
    scene.frame_set(0)
    check(np.abs(positions(obj) - V).max() > 0.05, "does not follow after the removal")
    bpy.ops.object.select_all(action="DESELECT")
    bpy.ops.object.mode_set(mode="EDIT")
    bpy.ops.mesh.select_all(action="DESELECT")
    message = reported(bpy.ops.meshquilt.remove_selected)
    check("select faces" in message, "reported: %s" % message)
    bpy.ops.object.mode_set(mode="OBJECT")


@test
def test_overall_progress_never_decreases_and_reaches_one():
    from meshquilt import engine
    # Per-stage fractions that fall back to 0 at every new stage, a stage seen twice, one the
    # table does not know and a stage skipped (no stretch optimisation).
    lines = []
    for stage in ("parameterization", "tiling", "placement", "quilting", "shell map",
                  "embedding", "embedding", "new stage", "placement check", "ring separation",
                  "coverage", "writing"):
        lines += ["progress %s %.4f 1.00 -1.00" % (stage, f) for f in (0.0, 0.3, 0.7, 1.0)]
    p, last = engine.Progress(), 0.0
    for line in lines:
        w = line.split()
        value = p.update(" ".join(w[1:-3]), float(w[-3]))
        check(value >= last, "overall fell from %.3f to %.3f at %r" % (last, value, line))
        check(value < 1.0, "1 before the job ended")
        last = value
    check(last > 0.9, "only %.2f at the last stage's end" % last)
    check(engine.time_left(10.0, 0.01) is None, "time left guessed below 3%")
    check(abs(engine.time_left(10.0, 0.25) - 30.0) < 1e-9, "time left")
    # A Job reading the same lines from a process: multi-word stages parsed, 1 once done.
    script = "; ".join("echo '%s' >&2" % line for line in lines)
    job = engine.Job("/bin/sh", ["-c", script])
    check(job.wait(10) == "done", "job %s: %s" % (job.state, job.error))
    check(job.stage == "writing" and job.overall == 1.0, "%s %.3f" % (job.stage, job.overall))
    check(job._stderr_tail == [], "progress lines taken as messages: %s" % job._stderr_tail[:2])
    check(job.status_text().startswith("meshquilt: 100%"), job.status_text())


@test
def test_overall_progress_follows_the_time_at_a_previews_detail():
    from meshquilt import engine
    # Seconds per stage as the engine reported them (scripts: first progress line of each stage
    # to the next's) for chain mail with the global layout at --scale 0.1 on bases the weights
    # were not fitted to, at a Preview's detail (0.1) and at full detail.
    runs = {
        ("bunny", 0.1): [0.16, 0, .05, .18, .08, .03, .07, .49, .07, .18, .86, .12, .01, .23, .1],
        ("bunny", 1.0): [.15, 0, .51, .7, .35, .2, .09, 4.29, .14, 1.41, 2.84, .81, .52, 1.76,
                         1.28],
        ("cup", 0.1): [.24, 0, .08, .22, .11, .04, .08, .82, .1, .17, .9, .13, .03, .22, .23],
        ("cup", 1.0): [.25, 0, .81, 1.09, .56, .33, .07, 6.71, .24, 1.66, 3.15, .78, .93, 3.42,
                       2.27],
    }
    stages = [name for name, _, _ in engine.STAGE_WEIGHTS["global"]]
    for (base, detail), seconds in runs.items():
        p, elapsed, worst = engine.Progress(detail), 0.0, 0.0
        for stage, t in zip(stages, seconds):
            p.update(stage, 0.0)
            p.update(stage, 1.0)
            elapsed += t
            worst = max(worst, abs(p.overall - elapsed / sum(seconds)))
        # The full run's weights on a Preview were 0.16-0.17 off (the embedding's share).
        check(worst < 0.08, "%s at detail %g: overall off the time by %.3f"
              % (base, detail, worst))


@test
def test_run_shows_cancel_at_once_before_any_progress():
    scene = new_scene()
    s = scene.meshquilt
    s.base, s.sample, s.scale = small_sphere(), "chainmail", 0.5
    import meshquilt
    check("op:meshquilt.run" in drawn_panel(), "no Run before starting")
    # Headless Blender runs INVOKE_DEFAULT as execute (blocking): the modal operator's start
    # is called as invoke calls it, without the modal handler (which needs the event loop).
    op = meshquilt.MESHQUILT_OT_run
    fake = type("Op", (), {"report": lambda self, *a: None, "_start": op._start,
                           "_begin": op._begin, "_end": op._end, "_finish": op._finish,
                           "preview": False})()
    started = fake._begin(bpy.context)
    run = meshquilt._running.get("run")
    try:
        check(started is not None and run is started, "not running after invoke")
        check(run.job is None or run.job.stage == "starting", "a progress line came first")
        texts = drawn_panel()
        check("op:meshquilt.cancel" in texts and "op:meshquilt.run" not in texts,
              "panel shows %s" % texts)
        check(any(t.startswith("meshquilt: 0%") for t in texts), "no progress: %s" % texts)
    finally:
        if run is not None:
            run.cancel()
            fake._end(bpy.context, run)
        meshquilt._running.clear()
    check("op:meshquilt.run" in drawn_panel(), "no Run after the end")


@test
def test_element_size_in_scene_units_is_passed_to_the_engine():
    scene = new_scene()
    s = scene.meshquilt
    base = small_sphere()
    base.scale = (2.0, 2.0, 2.0)  # world units: the exported base has radius 2
    s.base, s.sample, s.scale = base, "chainmail", 0.25
    bpy.context.view_layer.update()
    texts = drawn_panel()
    diagonal = 2.0 * 2.0 * math.sqrt(3.0)  # the 16 x 8 sphere's box is [-1, 1]^3, scaled 2x
    shown = [t for t in texts if t.startswith("At this Scale")]
    import re
    value = re.search(r"([0-9.]+) ?m?$", shown[0]) if shown else None
    check(value and abs(float(value.group(1)) - 0.25 * diagonal) < 0.01,
          "shown %s for %.3f" % (shown, 0.25 * diagonal))
    s.element_size = 2.0
    check("Element size used instead of Scale" in drawn_panel(), "element size not shown")
    import meshquilt
    run = meshquilt.Run(bpy.context, s)
    args = []
    while run.step() == "running":
        if run.job is not None and run.job.args[1] == "surface":
            args = run.job.args
        time.sleep(0.05)
    try:
        check(run.state == "done", "run %s: %s" % (run.state, run.error))
        i = args.index("--element-size")
        check(float(args[i + 1]) == 2.0 and "--scale" not in args, "args %s" % args)
        check(abs(run.scale - 2.0 / diagonal) < 0.01, "scale %.3f" % run.scale)
        obj = run.import_result(bpy.context)
        check(len(obj.data.polygons) > 100, "only %d faces" % len(obj.data.polygons))
    finally:
        run.cleanup()


@test
def test_detail_reaches_the_engine_command_and_its_estimate():
    scene = new_scene()
    import meshquilt
    s = scene.meshquilt
    s.base, s.sample, s.scale = small_sphere(), "chainmail", 0.4

    def surface_args(preview=False):
        """The surface job's command for the current settings (started and stopped at once)."""
        run = meshquilt.Run(bpy.context, s, preview=preview)
        try:
            job = run.jobs[run.preparation]()
            job.cancel()
            return job.args
        finally:
            run.cleanup()

    def detail(args):
        return args[args.index("--detail") + 1] if "--detail" in args else None

    check(s.detail == 100 and detail(surface_args()) is None, "at 100%%: %s" % surface_args())
    check(detail(surface_args(preview=True)) == "0.1", "Preview at 100%%: %s"
          % detail(surface_args(preview=True)))
    check(bpy.ops.meshquilt.estimate() == {"FINISHED"}, "estimate failed")
    full = s.estimate_faces
    s.detail = 25
    check(detail(surface_args()) == "0.25", "at 25%%: %s" % surface_args())
    # A tenth of 25% would leave 29 of a ring's 1152 faces: the Preview keeps 48.
    check(abs(float(detail(surface_args(preview=True))) - 48 / 1152) < 1e-5, "Preview at 25%%: "
          "%s" % detail(surface_args(preview=True)))
    check(s.estimate_key != meshquilt.estimate_key(bpy.context, s), "stale estimate kept")
    check(bpy.ops.meshquilt.estimate() == {"FINISHED"}, "estimate failed")
    check(0.2 < s.estimate_faces / full < 0.35, "25%%: %d faces, 100%%: %d"
          % (s.estimate_faces, full))


@test
def test_the_panel_shows_the_faces_per_element_detail_gives():
    scene = new_scene()
    import meshquilt
    from meshquilt import engine, exchange
    s = scene.meshquilt
    s.base, s.sample = small_sphere(), "chainmail"
    check("About 1152 faces per ring" in drawn_panel(), "panel: %s" % drawn_panel())
    s.detail = 10
    check("About 116 faces per ring (of 1152)" in drawn_panel(), "panel: %s" % drawn_panel())
    s.detail = 1  # the engine keeps 24 faces of an element at least
    check(meshquilt.detail_text(bpy.context, s) == "About 24 faces per ring (of 1152)",
          meshquilt.detail_text(bpy.context, s))
    # The samples' faces per element are the engine's swatches' own.
    for kind, (faces, _) in meshquilt.SAMPLE_ELEMENTS.items():
        path = os.path.join(WORK, "detail_%s.ply" % kind)
        check(engine.swatch_job(ENGINE, kind, path).wait(60) == "done", "swatch failed")
        counts = np.bincount(exchange.read_ply(path).face_element)
        check(int(np.median(counts[counts > 0])) == faces, "%s: median %g faces, table %d"
              % (kind, np.median(counts[counts > 0]), faces))
    # An object swatch: its connected parts counted (16 rings of 64 faces).
    swatch = bpy.data.objects.new("mail", exchange.build_mesh(
        bpy, "mail", exchange.read_ply(small_chainmail_path()), meshquilt.material_for))
    scene.collection.objects.link(swatch)
    s.swatch_source, s.swatch, s.detail = "OBJECT", swatch, 50
    check("About 32 faces per element (of 64)" in drawn_panel(), "panel: %s" % drawn_panel())


@test
def test_preview_then_run_leave_one_result_for_the_base():
    scene = new_scene()
    s = scene.meshquilt
    base = small_sphere()
    s.base, s.sample, s.scale = base, "chainmail", 0.5

    def results():
        return [o for o in bpy.data.objects if o.meshquilt.base == base]

    start = time.monotonic()
    check(bpy.ops.meshquilt.preview() == {"FINISHED"}, "preview did not finish")
    print("[blender]   preview: %.1f s" % (time.monotonic() - start), flush=True)
    check(len(results()) == 1 and results()[0].get("meshquilt_preview"), "results %s"
          % results())
    preview = results()[0]
    name, faces, ids = preview.name, len(preview.data.polygons), face_ids(preview)
    check(preview.parent == base and "meshquilt_report" in preview, "not a result like Run's")
    # A tenth of a ring's 1152 faces (a few rings kept finer so that none intersects).
    per_element = np.median(np.bincount(ids))
    check(110 <= per_element <= 200, "median %g faces per ring" % per_element)
    bpy.context.view_layer.objects.active = preview
    check("Preview (low detail) - Run for the full result" in drawn_panel(), "panel: %s"
          % drawn_panel())
    bpy.ops.object.mode_set(mode="EDIT")  # an artist looking at the preview's faces
    start = time.monotonic()
    check(bpy.ops.meshquilt.run() == {"FINISHED"}, "run did not finish")
    print("[blender]   run: %.1f s" % (time.monotonic() - start), flush=True)
    check(len(results()) == 1, "%d results for the base" % len(results()))
    check(all(o.mode == "OBJECT" for o in bpy.data.objects), "left in %s"
          % [o.mode for o in bpy.data.objects])
    full = results()[0]
    check(full.name == name and not full.get("meshquilt_preview"), "%s, preview %s"
          % (full.name, full.get("meshquilt_preview")))
    check(faces < 0.3 * len(full.data.polygons), "preview %d faces, full %d"
          % (faces, len(full.data.polygons)))
    full_ids = face_ids(full)
    n = int(full_ids.max()) + 1
    # The same layout; a coarse ring's chords meet a neighbour sooner where this small sphere
    # bends the shell hard, so a few more are removed (92-96% of the full run's rings here).
    check(len(np.unique(full_ids)) == n and 0.85 * n <= len(np.unique(ids)) <= n,
          "full: %d ids (0..%d), preview %d elements" % (len(np.unique(full_ids)), n - 1,
                                                         len(np.unique(ids))))
    check(not [m for m in bpy.data.meshes if m.users == 0], "the preview's mesh left behind")
    bpy.context.view_layer.objects.active = full
    check("Preview (low detail) - Run for the full result" not in drawn_panel(),
          "the full result shown as a preview")
    # A Preview after the full result takes its place too.
    check(bpy.ops.meshquilt.preview() == {"FINISHED"}, "second preview did not finish")
    check(len(results()) == 1 and results()[0].get("meshquilt_preview"), "results %s"
          % results())


@test
def test_run_after_run_replaces_the_result_unless_earlier_ones_are_kept():
    scene = new_scene()
    s = scene.meshquilt
    base = small_sphere()
    s.base, s.sample, s.scale, s.detail = base, "chainmail", 0.5, 10

    def results():
        return sorted(o.name for o in bpy.data.objects if o.meshquilt.base == base)

    check(bpy.ops.meshquilt.run() == {"FINISHED"}, "run did not finish")
    first = results()
    s.seed = 2
    check(bpy.ops.meshquilt.run() == {"FINISHED"}, "second run did not finish")
    check(results() == first, "after a second Run: %s (was %s)" % (results(), first))
    check(not [m for m in bpy.data.meshes if m.users == 0], "the replaced mesh left behind")
    # Kept: the next Run goes beside it and becomes the base's latest result.
    s.keep_results = True
    check(bpy.ops.meshquilt.run() == {"FINISHED"}, "third run did not finish")
    check(len(results()) == 2, "kept: %s" % results())
    latest = base.meshquilt.result
    check(latest.name not in first, "the latest result is %s" % latest.name)
    # A Preview still replaces the latest result, never the kept one; its overall progress
    # takes the Preview's detail.
    import meshquilt
    from meshquilt import engine
    details, plain = [], engine.Progress

    class Spy(plain):
        def __init__(self, detail=1.0):
            details.append(detail)
            super().__init__(detail)

    engine.Progress = Spy
    try:
        check(bpy.ops.meshquilt.preview() == {"FINISHED"}, "preview did not finish")
    finally:
        engine.Progress = plain
    check(len(results()) == 2 and base.meshquilt.result.get("meshquilt_preview") and
          first[0] in results(), "after the preview: %s" % results())
    low = meshquilt.preview_share(0.1, meshquilt.SAMPLE_ELEMENTS["chainmail"][0])
    check(low < 0.1 and low in details, "preview detail %g, progress at %s" % (low, details))



def element_heights(base):
    """The z of each element's centre (the mean of its faces' centres) in the base's latest
    result."""
    obj = base.meshquilt.result
    me = obj.data
    centres = np.empty(3 * len(me.polygons))
    me.polygons.foreach_get("center", centres)
    ids = face_ids(obj)
    centres = centres.reshape(-1, 3)
    n = int(ids.max()) + 1
    count = np.bincount(ids, minlength=n)
    z = np.bincount(ids, centres[:, 2], n) / np.maximum(count, 1)
    return z[count > 0]


def sphere_with_top_cap(name, group_name):
    """A new scene's settings and a small sphere whose cap above z 0.2 is the vertex group
    `group_name` (weight 1), set up for the sample chain mail at Scale 0.25, Detail 10%."""
    s = new_scene().meshquilt
    base = small_sphere(name)
    group = base.vertex_groups.new(name=group_name)
    group.add([v.index for v in base.data.vertices if v.co.z > 0.2], 1.0, "REPLACE")
    s.base, s.sample, s.scale, s.detail = base, "chainmail", 0.25, 10
    return s, base


def leaf_and_vine_vertices(obj):
    """An ivy result's vertices of leaf faces, and those of vine faces only (by material)."""
    names = [m.name for m in obj.data.materials]
    material = np.empty(len(obj.data.polygons), dtype=np.int32)
    obj.data.polygons.foreach_get("material_index", material)
    loops = np.empty(3 * len(obj.data.polygons), dtype=np.int32)
    obj.data.polygons.foreach_get("vertices", loops)
    loops = loops.reshape(-1, 3)
    leaf = np.zeros(len(obj.data.vertices), dtype=bool)
    leaf[loops[material == names.index("leaf")].ravel()] = True
    vine = np.zeros(len(obj.data.vertices), dtype=bool)
    vine[loops[material == names.index("vine")].ravel()] = True
    vine &= ~leaf
    check(leaf.any() and vine.any(), "no leaves or no vine")
    return leaf, vine


@test
def test_wind_turns_the_ivys_leaves_in_a_loop_of_shape_keys():
    scene = new_scene()
    base = sphere()
    s = scene.meshquilt
    s.base, s.swatch_source, s.sample, s.scale, s.stretch = base, "SAMPLE", "chainmail", 0.5, False
    check("prop:wind_frames" not in drawn_panel(), "Wind offered for chain mail")
    s.sample, s.wind_frames = "ivy", 6
    check("prop:wind_frames" in drawn_panel(), "panel: %s" % drawn_panel())
    start = time.monotonic()
    check(bpy.ops.meshquilt.run() == {"FINISHED"}, "wind run did not finish")
    print("[blender]   ivy in a wind of 6 frames: %.1f s" % (time.monotonic() - start), flush=True)
    obj = base.meshquilt.result
    key = obj.data.shape_keys
    check(key is not None and not key.use_relative and len(key.key_blocks) == 7,
          "expected 6 absolute shape keys and frame 0 again, got %s"
          % (len(key.key_blocks) if key else None))
    check(obj.get("meshquilt_frames") == 6 and obj.get("meshquilt_loop") and
          not obj.meshquilt.quilt, "bound to its base")
    bpy.context.view_layer.objects.active = obj
    check("In the wind: 6 frames a loop" in drawn_panel(), "panel: %s" % drawn_panel())
    rest, first = positions(obj), scene.frame_start
    V = []
    for frame in range(first, first + 13):
        scene.frame_set(frame)
        V.append(positions(obj, evaluated=True))
    scene.frame_set(first)
    # Frame 0 is the still result (the engine's frame 0 is its static output byte for byte);
    # the loop comes back to it every 6 frames and moves at every frame between.
    check(np.allclose(V[0], rest, atol=1e-6), "frame 0 is not the still result")
    check(np.allclose(V[6], V[0], atol=1e-5) and np.allclose(V[12], V[0], atol=1e-5),
          "the wind does not loop")
    for k in range(1, 6):
        check(np.abs(V[k] - V[k - 1]).max() > 1e-4, "frame %d equals the one before" % k)
    # The leaves turn, the vine holds still (the wind's default), and faces stay as they are.
    leaf, vine = leaf_and_vine_vertices(obj)
    moved = np.linalg.norm(V[3] - V[0], axis=1)
    check(moved[vine].max() < 1e-5, "the vine moved %g" % moved[vine].max())
    check(moved[leaf].max() > 1e-3, "the leaves moved only %g" % moved[leaf].max())
    # Wind needs the swatch as generated; a Preview shows the still layout.
    s.detail = 50
    message = reported(bpy.ops.meshquilt.run)
    check("set Detail to 100%" in message, message)
    check(bpy.ops.meshquilt.preview() == {"FINISHED"}, "preview did not finish")
    preview = base.meshquilt.result
    check(preview.data.shape_keys is None and preview.get("meshquilt_frames") is None,
          "a Preview in the wind")
    s.detail, s.wind_frames = 100, 0


@test
def test_swatch_motion_follows_an_animated_swatch_object():
    scene = new_scene()
    base = sphere()
    import meshquilt
    from meshquilt import engine, exchange
    swatch = ivy_swatch_object(scene, "Vine")
    s = scene.meshquilt
    s.base, s.swatch_source, s.swatch, s.scale, s.stretch = base, "OBJECT", swatch, 0.5, False
    check("prop:swatch_motion" in drawn_panel(), "panel: %s" % drawn_panel())
    s.swatch_motion = True
    scene.frame_start, scene.frame_end = 1, 5
    # A swatch that does not move: said before any work.
    message = reported(bpy.ops.meshquilt.run)
    check("Vine does not move over frames 1-5" in message, message)
    # A gust lifting the leaves (a shape key keyed from 0 at frame 1 to 1 at frame 5).
    swatch.shape_key_add(name="Basis", from_mix=False)
    gust = swatch.shape_key_add(name="gust", from_mix=False)
    leaf = np.flatnonzero(leaf_and_vine_vertices(swatch)[0])
    V = positions(swatch)
    lift = 0.05 * (V.max(0) - V.min(0)).max()
    for v in leaf:
        gust.data[int(v)].co.z += lift
    for frame, value in ((1, 0.0), (5, 1.0)):
        gust.value = value
        gust.keyframe_insert("value", frame=frame)
    scene.frame_set(3)
    start = time.monotonic()
    check(bpy.ops.meshquilt.run() == {"FINISHED"}, "swatch motion run did not finish")
    print("[blender]   ivy following its swatch's 5 frames: %.1f s"
          % (time.monotonic() - start), flush=True)
    check(scene.frame_current == 3, "the run left the scene at frame %d" % scene.frame_current)
    obj = base.meshquilt.result
    key = obj.data.shape_keys
    check(key is not None and len(key.key_blocks) == 5 and not obj.get("meshquilt_loop"),
          "expected 5 shape keys and no loop, got %s" % (len(key.key_blocks) if key else None))
    bpy.context.view_layer.objects.active = obj
    check("Following the swatch's motion: 5 frames" in drawn_panel(), "panel: %s"
          % drawn_panel())
    frames = []
    for frame in range(1, 6):
        scene.frame_set(frame)
        frames.append(positions(obj, evaluated=True))
    check(np.allclose(frames[0], positions(obj), atol=1e-6), "frame 1 is not the still result")
    moved = np.linalg.norm(frames[4] - frames[0], axis=1)
    # The leaves rise with the gust; the vine, which the gust does not move, holds still.
    leaf, vine = leaf_and_vine_vertices(obj)
    print("[blender]   gust: leaves moved up to %.4f, vine %.2g (swatch lift %.4f, unscaled)"
          % (moved[leaf].max(), moved[vine].max(), lift), flush=True)
    check(moved[leaf].max() > 1e-3, "the leaves moved only %g" % moved[leaf].max())
    check(moved[vine].max() < 1e-5, "the vine moved %g" % moved[vine].max())
    check(np.linalg.norm(frames[2] - frames[0], axis=1).max() < moved.max(),
          "frame 3 moved as far as frame 5")
    # A swatch the engine lays out as threads (the weave: one-period pieces welded into threads)
    # follows too: the whole swatch lifted by a fifth of its thickness moves the result alike.
    weave_path = os.path.join(WORK, "weave_motion.ply")
    check(engine.swatch_job(ENGINE, "weave", weave_path).wait(60) == "done", "no weave")
    weave = bpy.data.objects.new("Weave", exchange.build_mesh(
        bpy, "Weave", exchange.read_ply(weave_path), meshquilt.material_for))
    scene.collection.objects.link(weave)
    weave.shape_key_add(name="Basis", from_mix=False)
    up = weave.shape_key_add(name="up", from_mix=False)
    W = positions(weave)
    for point in up.data:
        point.co.z += 0.2 * (W[:, 2].max() - W[:, 2].min())
    for frame, value in ((1, 0.0), (5, 1.0)):
        up.value = value
        up.keyframe_insert("value", frame=frame)
    s.swatch, s.scale = weave, 0.2
    check(bpy.ops.meshquilt.run() == {"FINISHED"}, "weave motion run did not finish")
    obj = base.meshquilt.result
    scene.frame_set(1)
    first = positions(obj, evaluated=True)
    scene.frame_set(5)
    moved = np.linalg.norm(positions(obj, evaluated=True) - first, axis=1)
    typical = float(np.median(moved))
    share = float(np.mean(np.abs(moved - typical) < 0.1 * typical))
    print("[blender]   weave lifted: median motion %.4f, %.1f%% of vertices within 10%% of it"
          % (typical, 100 * share), flush=True)
    check(typical > 0 and share > 0.9, "weave motion %g, %.3f alike" % (typical, share))
    s.swatch_motion = False


@test
def test_a_vertex_group_masks_the_texture():
    s, base = sphere_with_top_cap("Masked", "Top")
    # Through a Subdivision modifier (the evaluated mesh's weights).
    base.modifiers.new("Subdivision", "SUBSURF").levels = 1
    import meshquilt

    check(bpy.ops.meshquilt.run() == {"FINISHED"}, "unmasked run did not finish")
    everywhere = element_heights(base)
    s.mask_group = "Top"
    check("op:meshquilt.run" in drawn_panel(), "panel: %s" % drawn_panel())
    check(bpy.ops.meshquilt.run() == {"FINISHED"}, "masked run did not finish")
    masked = element_heights(base)
    ring = 0.25 * 2 * math.sqrt(3) / 3  # the 3 x 3 sample's side at Scale 0.25, over 3
    # Whole elements kept by where most of their vertices lie: none beyond about one ring
    # below the group's border (z 0.2, pulled in a little by the subdivision).
    check(masked.min() > 0.1 - ring, "an element at z %.2f (ring %.2f)" % (masked.min(), ring))
    # The cap above z 0.2 is 40% of a sphere's area.
    share = len(masked) / len(everywhere)
    print("[blender]   mask: %d of %d elements, lowest at z %.2f (ring %.2f)"
          % (len(masked), len(everywhere), masked.min(), ring), flush=True)
    check(0.3 < share < 0.6, "%d of %d elements kept" % (len(masked), len(everywhere)))
    check(np.sum(everywhere < -0.5) > 10, "the unmasked run did not cover the bottom")
    # A missing group and a group that sets nothing: said before any work, in the panel's terms.
    s.mask_group = "Nope"
    message = reported(bpy.ops.meshquilt.run)
    check("no vertex group named 'Nope'" in message, message)
    weak = base.vertex_groups.new(name="Weak")
    weak.add([0, 1, 2], 0.3, "REPLACE")
    s.mask_group = "Weak"
    message = reported(bpy.ops.meshquilt.run)
    check("sets no vertex" in message and "clear Mask" in message, message)
    s.mask_group = ""


@test
def test_a_vertex_group_sets_the_element_size():
    # Full size over the top cap (weight 1), Smallest (a half) elsewhere.
    s, base = sphere_with_top_cap("Sized", "Big")
    check(bpy.ops.meshquilt.run() == {"FINISHED"}, "one-size run did not finish")
    plain = element_heights(base)
    s.size_group = "Big"
    check("op:meshquilt.run" in drawn_panel(), "panel: %s" % drawn_panel())
    check(bpy.ops.meshquilt.run() == {"FINISHED"}, "sized run did not finish")
    sized = element_heights(base)
    # Below the cap the elements are half as large: about four times as many there, while
    # the cap keeps about its count.
    low, low_plain = np.sum(sized < -0.2), np.sum(plain < -0.2)
    high, high_plain = np.sum(sized > 0.5), np.sum(plain > 0.5)
    print("[blender]   size group: %d elements below, %d one-size; %d on the cap, %d one-size"
          % (low, low_plain, high, high_plain), flush=True)
    check(low > 2.5 * low_plain, "%d elements below the cap, %d at one size" % (low, low_plain))
    check(high < 2.0 * max(high_plain, 1), "%d on the cap, %d at one size" % (high, high_plain))
    # Apples (the local patches) follow the group too: smaller below the cap.
    s.sample = "apples"
    check(bpy.ops.meshquilt.run() == {"FINISHED"}, "sized apples did not finish")
    apples = element_heights(base)
    print("[blender]   size group, apples: %d elements below, %d on the cap"
          % (np.sum(apples < -0.2), np.sum(apples > 0.2)), flush=True)
    # Below z -0.2 and above 0.2 are caps of equal area: half the size, about four times the
    # apples (twice asked, for the apples' own spread of sizes).
    check(np.sum(apples < -0.2) > 2 * np.sum(apples > 0.2), "apples: too few below the cap")
    # Ivy (vines) follows the group as well: stems closer, leaves smaller below the cap.
    s.sample = "ivy"
    check(bpy.ops.meshquilt.run() == {"FINISHED"}, "sized ivy did not finish")
    ivy = element_heights(base)
    print("[blender]   size group, ivy: %d elements below, %d on the cap"
          % (np.sum(ivy < -0.2), np.sum(ivy > 0.2)), flush=True)
    check(np.sum(ivy < -0.2) > 2 * np.sum(ivy > 0.2), "ivy: too few below the cap")
    s.size_group = ""


@test
def test_results_are_built_with_the_mesh_apis_of_blender_4():
    # What 4.x changed in what build_mesh uses (checked against the 4.0-4.3 API references):
    # MeshPolygon.loop_total read-only from 4.0 (sizes follow from loop_start), and
    # Mesh.use_auto_smooth / auto_smooth_angle removed in 4.1, where Mesh.set_sharp_from_angle
    # marks the sharp edges instead. A stand-in for those APIs over this Blender's mesh.
    import types
    from meshquilt import exchange, material_for
    sharp = []

    class Polygons:
        def __init__(self, real):
            self.real = real

        def foreach_set(self, name, values):
            check(name != "loop_total", "loop_total set: read-only in Blender 4")
            self.real.foreach_set(name, values)
            if name == "loop_start":  # as 4.x derives the sizes
                sizes = np.diff(np.append(values, 3 * len(values)))
                self.real.foreach_set("loop_total", sizes.astype(np.int32))

        def __getattr__(self, name):
            return getattr(self.real, name)

    class Mesh:
        def __init__(self, real):
            object.__setattr__(self, "real", real)

        def __getattr__(self, name):
            check(name not in ("use_auto_smooth", "auto_smooth_angle"), name + " read")
            return Polygons(self.real.polygons) if name == "polygons" else \
                getattr(self.real, name)

        def __setattr__(self, name, value):
            check(name not in ("use_auto_smooth", "auto_smooth_angle"), name + " set")
            setattr(self.real, name, value)

        def set_sharp_from_angle(self, angle):
            sharp.append(angle)

    made = []

    def new_mesh(name):
        made.append(bpy.data.meshes.new(name))
        return Mesh(made[-1])

    fake = types.SimpleNamespace(
        app=types.SimpleNamespace(version=(4, 2, 0)),
        data=types.SimpleNamespace(meshes=types.SimpleNamespace(new=new_mesh)))
    result = exchange.read_ply(small_chainmail_path())
    me = exchange.build_mesh(fake, "mail4", result, material_for)
    real = made[0]
    check(real.validate() is False, "the mesh built the 4.x way is invalid")
    check(len(real.polygons) == len(result.F) and all(p.loop_total == 3 for p in real.polygons),
          "faces %d of %d" % (len(real.polygons), len(result.F)))
    check(sharp == [math.radians(60)], "sharp edges by angle: %s" % sharp)
    check(me.real is real, "not the mesh made")


@test
def test_a_mesh_goes_to_the_engine_the_same_whatever_its_face_order():
    # The same quads (each with its own material index) in two polygon orders: the triangles
    # sent to the engine, and their materials, come out identical (Blender's loop triangles of
    # one UV sphere came in a different order from run to run, and so did the result).
    from meshquilt import exchange
    verts = [(x, y, 0.1 * x * y) for y in range(4) for x in range(4)]
    quads = [(y * 4 + x, y * 4 + x + 1, y * 4 + x + 5, y * 4 + x + 4)
             for y in range(3) for x in range(3)]
    arrays = []
    for order in (list(range(9)), [4, 8, 0, 7, 2, 5, 1, 6, 3]):
        me = bpy.data.meshes.new("order")
        me.from_pydata(verts, [], [quads[i] for i in order])
        me.materials.append(None)
        me.materials.append(None)
        for p, i in zip(me.polygons, order):
            p.material_index = i % 2
        arrays.append(exchange.mesh_arrays(me))
        bpy.data.meshes.remove(me)
    (V0, T0, M0), (V1, T1, M1) = arrays
    check(np.array_equal(V0, V1) and np.array_equal(T0, T1) and np.array_equal(M0, M1),
          "triangles %s / %s" % (T0[:3].tolist(), T1[:3].tolist()))
    check(len(T0) == 18 and set(M0.tolist()) == {0, 1}, "%d triangles, materials %s"
          % (len(T0), sorted(set(M0.tolist()))))

@test
def test_follow_base_goes_on_after_the_file_is_opened_again():
    # File > Open keeps the add-on enabled without registering it again: the frame handler must
    # be persistent to outlive the file it was added in (a later edit had moved its decorator).
    scene, base, obj = twisting_grid_quilt()
    obj.meshquilt.follow = True
    name = obj.name
    path = os.path.join(WORK, "follow_reopened.blend")
    bpy.ops.wm.save_as_mainfile(filepath=path)
    bpy.ops.wm.open_mainfile(filepath=path)
    import meshquilt.follow
    check(bpy.app.handlers.frame_change_post.count(meshquilt.follow.on_frame_change) == 1,
          "the frame handler went with the file")
    scene, obj = bpy.context.scene, bpy.data.objects[name]
    scene.frame_set(6)
    before = positions(obj)
    scene.frame_set(18)
    check(np.abs(positions(obj) - before).max() > 1e-3, "the result no longer follows its base")


print("[blender] %d failed: %s" % (len(failures), ", ".join(failures) or "none"), flush=True)
if failures:
    sys.exit(1)
