"""Results bound to their base (issue 25): every run's saved quilt, placed again on the base's
evaluated mesh (modifiers, armature, shape keys applied) by `meshquilt embed` without a new
synthesis: when the frame changes (Follow base), over the scene's frame range into shape keys
(Bake), and after elements are removed from it (`meshquilt edit`).

A bound result keeps, in its `meshquilt` settings, the path of its saved quilt (in a cache
directory beside the .blend file, or the system's temporary directory while the file is not
saved), its base and the base's matrix when it was quilted; the cache directory also keeps the
base's triangles as quilted (`base_faces.npz`), since Blender triangulates an n-gon by its shape
and a deformed n-gon could otherwise look like other connectivity to the engine.
"""

import hashlib
import os
import shutil
import tempfile
import uuid

import bpy
import numpy as np

from . import engine, exchange

FACES_FILE = "base_faces.npz"
JOB_TIMEOUT = 600.0

_state = {"baking": False}  # while a bake steps through the frames the handler does nothing
_placed = {}  # result object name -> fingerprint of the base positions it was last placed on


def cache_root():
    """Beside the .blend file (like Blender's own blendcache_ directories), else temporary."""
    if bpy.data.filepath:
        return os.path.join(os.path.dirname(bpy.data.filepath), "meshquilt_cache")
    return os.path.join(tempfile.gettempdir(), "meshquilt_cache")


def new_cache_dir(base_name):
    safe = "".join(c if c.isalnum() or c in "-_" else "_" for c in base_name)[:40]
    path = os.path.join(cache_root(), "%s-%s" % (safe or "base", uuid.uuid4().hex[:8]))
    os.makedirs(path)
    return path


def stored_path(path):
    """A path as kept on the object: relative to the .blend file where it can be."""
    if bpy.data.filepath:
        try:
            return bpy.path.relpath(path)
        except ValueError:  # another drive
            pass
    return path


def quilt_path(obj):
    return bpy.path.abspath(obj.meshquilt.quilt) if obj.meshquilt.quilt else ""


def is_bound(obj):
    return obj is not None and obj.type == "MESH" and bool(obj.meshquilt.quilt)


def topology(mesh):
    """The polygons' vertex lists (loop vertex indices, loop counts): Blender's connectivity."""
    loops = np.empty(len(mesh.loops), dtype=np.int32)
    mesh.loops.foreach_get("vertex_index", loops)
    totals = np.empty(len(mesh.polygons), dtype=np.int32)
    mesh.polygons.foreach_get("loop_total", totals)
    return loops, totals


def bind(obj, base, quilt, T, loops, totals, matrix):
    """Makes obj a result bound to base: the quilt file moves into a cache directory."""
    directory = new_cache_dir(base.name)
    target = os.path.join(directory, "quilt.mqq")
    shutil.move(quilt, target)
    np.savez(os.path.join(directory, FACES_FILE), T=T, loops=loops, totals=totals)
    b = obj.meshquilt
    b.quilt = stored_path(target)
    b.base = base
    b.base_matrix = [x for row in matrix for x in row]
    b.status = ""


def base_mesh(obj, depsgraph):
    """The bound base's evaluated vertices, in the frame the quilt was made in (the base's
    matrix then: moving the base object moves the result by the parenting), and the triangles
    to send: those quilted when the polygons are the same, else Blender's own (the engine
    then refuses them with its message)."""
    b = obj.meshquilt
    base = b.base
    if base is None:
        raise engine.EngineError("%s: its base object is gone" % obj.name)
    evaluated = base.evaluated_get(depsgraph)
    me = evaluated.to_mesh()
    try:
        V, T, _ = exchange.mesh_arrays(me)
        loops, totals = topology(me)
    finally:
        evaluated.to_mesh_clear()
    faces_file = os.path.join(os.path.dirname(quilt_path(obj)), FACES_FILE)
    if os.path.exists(faces_file):
        stored = np.load(faces_file)
        if np.array_equal(stored["loops"], loops) and np.array_equal(stored["totals"], totals):
            T = stored["T"]
    W = np.array(b.base_matrix, dtype=np.float64).reshape(4, 4)
    return V @ W[:3, :3].T + W[:3, 3], T


def _engine(context=None):
    prefs = (context or bpy.context).preferences.addons[__package__].preferences
    return engine.find_engine(prefs.engine_path)


def _run(job, files=None):
    """Waits for an engine job; its error (file names given as the artist's words) if any."""
    if job.wait(JOB_TIMEOUT) != "done":
        message = job.error or "meshquilt: %s" % job.state
        for path, words in (files or {}).items():
            message = message.replace(path, words)
        raise engine.EngineError(message)


def _embed(exe, quilt, base, output, frames=None):
    """embed keeping every element (a bound result keeps its faces and element ids)."""
    _run(engine.embed_job(exe, quilt, base, output, frames=frames), {base + ": ": ""})


def place(obj, depsgraph, context=None, faces=None, force=False):
    """Places the result on its base's evaluated mesh. With the same faces (faces=None: the
    mesh's own) the vertex positions are replaced in place; else the mesh is built again
    (materials kept by kind). Skips a base that has not moved since the last placement."""
    V, T = base_mesh(obj, depsgraph)
    quilt = quilt_path(obj)
    key = hashlib.blake2b(V.tobytes() + T.tobytes() + quilt.encode(), digest_size=16).digest()
    if not force and faces is None and _placed.get(obj.name_full) == key:
        return False
    me = obj.data
    in_place = faces is None
    directory = tempfile.mkdtemp(prefix="meshquilt-embed-")
    try:
        base_path = os.path.join(directory, "base.ply")
        out_path = os.path.join(directory, "result.ply")
        exchange.write_ply(base_path, V, T)
        _embed(_engine(context), quilt, base_path, out_path)
        result = exchange.read_ply(out_path)
    finally:
        shutil.rmtree(directory, ignore_errors=True)
    if in_place:
        if len(result.V) != len(me.vertices) or len(result.F) != len(me.polygons):
            raise engine.EngineError(
                "%s: the quilt has %d faces, the object %d: quilt the base again"
                % (obj.name, len(result.F), len(me.polygons)))
        me.vertices.foreach_set("co", result.V.astype(np.float32).ravel())
        me.update()
    else:
        rebuild(obj, result)
    _placed[obj.name_full] = key
    obj.meshquilt.status = ""
    return True


def rebuild(obj, result):
    """The object's mesh built again from a result of other faces: element ids and kinds from
    the result, the object's materials kept kind by kind."""
    from . import material_for
    old = obj.data
    materials = list(old.materials)
    by_kind = {kind: materials[k] for k, kind in enumerate(result.kinds) if k < len(materials)}
    me = exchange.build_mesh(bpy, old.name, result, lambda kind, look: by_kind.get(kind) or
                             material_for(kind, look))
    obj.data = me
    if old.users == 0:
        bpy.data.meshes.remove(old)
    _placed.pop(obj.name_full, None)


def clear_bake(obj):
    key = obj.data.shape_keys
    if key is not None:
        action = key.animation_data.action if key.animation_data else None
        obj.shape_key_clear()
        if action is not None and action.users == 0:
            bpy.data.actions.remove(action)
    obj.meshquilt.baked = False
    _placed.pop(obj.name_full, None)


def bake(context, obj):
    """The result over the scene's frame range: the base exported at every frame, one
    `embed --frames` run (the same faces in every frame), the positions kept as absolute shape
    keys, one a frame, with the evaluation time keyed linearly: playback needs no engine.
    Returns the number of frames."""
    scene = context.scene
    b = obj.meshquilt
    first, last = scene.frame_start, scene.frame_end
    count = last - first + 1
    exe = _engine(context)
    was = scene.frame_current, scene.frame_subframe
    directory = tempfile.mkdtemp(prefix="meshquilt-bake-")
    wm = context.window_manager
    wm.progress_begin(0, count + 1)
    set_stepping(True)
    try:
        names = {}
        for i in range(count):
            scene.frame_set(first + i)
            V, T = base_mesh(obj, context.evaluated_depsgraph_get())
            path = os.path.join(directory, "base_%05d.ply" % i)
            exchange.write_ply(path, V, T)
            names[path] = "the base at frame %d" % (first + i)
            wm.progress_update(i)
    finally:
        set_stepping(False)
        scene.frame_set(was[0], subframe=was[1])
    try:
        base_pattern = os.path.join(directory, "base_%05d.ply")
        out_pattern = os.path.join(directory, "result_%05d.ply")
        job = engine.embed_job(exe, quilt_path(obj), base_pattern, out_pattern,
                               frames=(0, count - 1))
        _run(job, names)
        frames = [exchange.read_ply(out_pattern % i).V for i in range(count)]
    finally:
        shutil.rmtree(directory, ignore_errors=True)
        wm.progress_end()
    if any(len(V) != len(obj.data.vertices) for V in frames):
        raise engine.EngineError("%s: the quilt no longer matches the object: quilt the base "
                                 "again" % obj.name)
    b.follow = False
    clear_bake(obj)
    keep_frames(obj, frames, first)
    b.baked = True
    b.status = ""
    return count


def keep_frames(obj, frames, first, loop=False):
    """The positions of each frame (#V by 3, world = the object's space here) as absolute shape
    keys, one a frame, played from scene frame `first` by keying the evaluation time linearly;
    with loop, frame 0 follows the last and the keys repeat for ever (a Cycles modifier)."""
    me = obj.data
    me.vertices.foreach_set("co", frames[0].astype(np.float32).ravel())
    for i, V in enumerate(list(frames) + ([frames[0]] if loop else [])):
        block = obj.shape_key_add(name="frame %d" % (first + i), from_mix=False)
        block.data.foreach_set("co", V.astype(np.float32).ravel())
        block.interpolation = "KEY_LINEAR"
    key = me.shape_keys
    key.use_relative = False
    for i, block in enumerate(key.key_blocks):
        key.eval_time = block.frame
        key.keyframe_insert("eval_time", frame=first + i)
    for fcurve in key.animation_data.action.fcurves:
        for point in fcurve.keyframe_points:
            point.interpolation = "LINEAR"
        if loop:
            fcurve.modifiers.new("CYCLES")
    me.update()


def remove_elements(context, obj, ids):
    """Removes the elements from the saved quilt (a new file: undo brings the old path back
    with the old mesh) and places the rest on the base's current evaluated mesh."""
    b = obj.meshquilt
    quilt = quilt_path(obj)
    ids = sorted(set(int(i) for i in ids))
    exe = _engine(context)
    element = np.empty(len(obj.data.polygons), dtype=np.int32)
    obj.data.attributes["element_id"].data.foreach_get("value", element)
    faces = int(np.count_nonzero(~np.isin(element, ids)))
    target = os.path.join(os.path.dirname(quilt), "quilt-%s.mqq" % uuid.uuid4().hex[:8])
    # Long lists in parts, highest ids first: removing an element renumbers only those after it.
    current, parts = quilt, []
    while ids:
        part = ids[-1:]
        while len(part) < len(ids) and len(engine.id_ranges(ids[-len(part) - 1:])) < 60000:
            part = ids[-len(part) - 1:]
        ids = ids[:len(ids) - len(part)]
        parts.append(part)
    try:
        for n, part in enumerate(parts):
            output = target if n == len(parts) - 1 else target + ".%d" % n
            _run(engine.edit_job(exe, current, output, part))
            if current != quilt:
                os.remove(current)
            current = output
    except engine.EngineError:
        if current != quilt and os.path.exists(current):
            os.remove(current)
        raise
    was_baked = b.baked
    if was_baked:
        clear_bake(obj)
    b.quilt = stored_path(target)
    place(obj, context.evaluated_depsgraph_get(), context, faces=faces)
    if was_baked:
        bake(context, obj)


def set_stepping(on):
    """While on, frame changes do not re-place following results (a bake, or a swatch's motion
    exported frame by frame, steps through the frames itself)."""
    _state["baking"] = on


# Persistent: File > Open keeps the add-on enabled without registering it again, and a handler
# that is not persistent goes with the file it was added in (Follow base then stopped).
@bpy.app.handlers.persistent
def on_frame_change(scene, depsgraph=None):
    """frame_change_post: every result following its base placed on it; one that cannot be
    (its base changed connectivity, the engine failed) stops following with the reason."""
    if _state["baking"]:
        return
    for obj in scene.objects:
        if obj.type != "MESH" or not obj.meshquilt.follow or not obj.meshquilt.quilt:
            continue
        try:
            place(obj, depsgraph or bpy.context.evaluated_depsgraph_get())
        except (engine.EngineError, OSError, ValueError, KeyError) as e:
            stop_following(obj, str(e))


def stop_following(obj, message):
    obj.meshquilt.status = message
    obj.meshquilt.follow = False
    print("meshquilt: %s stopped following its base: %s" % (obj.name, message))


def register():
    if on_frame_change not in bpy.app.handlers.frame_change_post:
        bpy.app.handlers.frame_change_post.append(on_frame_change)


def unregister():
    while on_frame_change in bpy.app.handlers.frame_change_post:
        bpy.app.handlers.frame_change_post.remove(on_frame_change)
    _placed.clear()
