"""meshquilt for Blender: covers a mesh with a swatch's geometric texture by mesh quilting.

A panel in the 3D view's sidebar (tab "meshquilt") picks the base and the swatch (an object or a
sample kind), the scale, the guidance and the seed; Run quilts in the background with progress
and time remaining in the status bar (Esc or Cancel stops it), and brings the result in as a new
object parented to the base, with a material per kind of element and the integer face
attributes `element_id` and `kind`.

Every run also saves its quilt (follow.py): the result can then follow its base (its evaluated
mesh, re-placed by the engine without a new synthesis when the frame changes), be baked over the
scene's frame range into shape keys, and lose the elements selected in it.
"""

bl_info = {
    "name": "meshquilt",
    "author": "meshquilt developers",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "location": "3D View > Sidebar > meshquilt",
    "description": "Geometric texture (chain mail, weave, ivy) over a mesh by mesh quilting",
    "category": "Mesh",
}

import math
import os
import shutil
import tempfile
import time

import bpy
import numpy as np
from bpy_extras.io_utils import ImportHelper

from . import engine, exchange, follow

_running = {}  # the one active Run, under key "run", while the modal operator works


def _mesh_poll(self, obj):
    return obj.type == "MESH"


# The memory limit's default: half the machine's memory (Blender and the rest keep the other).
_MACHINE_GIB = engine.machine_memory_gib()
_DEFAULT_LIMIT_GIB = round(0.5 * _MACHINE_GIB, 1) if _MACHINE_GIB > 0 else 8.0


class MeshquiltPreferences(bpy.types.AddonPreferences):
    bl_idname = __name__
    engine_path: bpy.props.StringProperty(
        name="Engine", subtype="FILE_PATH", default="",
        description="The meshquilt executable (empty: $MESHQUILT_ENGINE or meshquilt on PATH)")
    max_memory: bpy.props.FloatProperty(
        name="Memory limit (GiB)", default=_DEFAULT_LIMIT_GIB, min=0.01, soft_min=0.5,
        precision=2,
        description="Refuse a job the engine estimates to need more memory, before any work "
        "(default: half of this machine's memory)")

    def draw(self, context):
        self.layout.prop(self, "engine_path")
        self.layout.prop(self, "max_memory")


class MeshquiltSettings(bpy.types.PropertyGroup):
    base: bpy.props.PointerProperty(name="Base", type=bpy.types.Object, poll=_mesh_poll,
                                    description="The mesh to cover")
    swatch_source: bpy.props.EnumProperty(
        name="Swatch", items=[("SAMPLE", "Sample", "A generated sample swatch"),
                              ("OBJECT", "Object", "A mesh object of the scene; its material "
                               "names become the kinds of its elements")], default="SAMPLE")
    swatch: bpy.props.PointerProperty(name="Swatch object", type=bpy.types.Object,
                                      poll=_mesh_poll)
    sample: bpy.props.EnumProperty(
        name="Sample", items=[("chainmail", "Chain mail", "4-in-1 rings"),
                              ("weave", "Weave", "Plain weave threads"),
                              ("apples", "Apples", "A layer of apples"),
                              ("ivy", "Ivy", "A vine with leaves")], default="chainmail")
    scale: bpy.props.FloatProperty(
        name="Scale", default=0.1, min=0.001, max=1.0, soft_min=0.01, soft_max=0.3,
        description="The swatch's longer side as a fraction of the base's bounding-box diagonal")
    element_size: bpy.props.FloatProperty(
        name="Element size", default=0.0, min=0.0, soft_max=10.0, subtype="DISTANCE",
        unit="LENGTH", description="The swatch's longer side in scene units, whatever the "
        "base's size (0: use Scale)")
    guidance: bpy.props.EnumProperty(
        name="Guidance", items=[("NONE", "None", "A smooth field the engine chooses"),
                                ("AXIS", "Object axis", "An object's axis, projected on the "
                                 "surface"),
                                ("ATTRIBUTE", "Vertex attribute", "A vector attribute of the "
                                 "base's vertices")], default="NONE")
    guide_object: bpy.props.PointerProperty(name="Guide", type=bpy.types.Object)
    guide_axis: bpy.props.EnumProperty(name="Axis", items=[("X", "X", ""), ("Y", "Y", ""),
                                                           ("Z", "Z", "")], default="Z")
    guide_attribute: bpy.props.StringProperty(name="Attribute", default="guide")
    stretch: bpy.props.BoolProperty(
        name="Minimise distortion", default=True,
        description="Minimise the shell map's stretch (slower, less distorted elements)")
    seed: bpy.props.IntProperty(name="Seed", default=1, min=0)
    mask_group: bpy.props.StringProperty(
        name="Mask", default="",
        description="A vertex group of the base: texture only where its weight is 0.5 or more, "
        "whole elements kept at the border (empty: the whole base)")
    size_group: bpy.props.StringProperty(
        name="Size", default="",
        description="A vertex group of the base: elements at the full size where its weight is "
        "1, at Smallest where it is 0 (or the vertex is not in it); every sample (empty: one "
        "size)")
    smallest_size: bpy.props.FloatProperty(
        name="Smallest", default=0.5, min=0.125, max=1.0, subtype="FACTOR",
        description="The element size where the Size group's weight is 0, as a share of the "
        "full size")
    keep_results: bpy.props.BoolProperty(
        name="Keep earlier results", default=False,
        description="Run adds its result beside the base's earlier one instead of replacing "
        "it (a Preview always replaces the base's latest result)")
    detail: bpy.props.IntProperty(
        name="Detail", default=100, min=1, max=100, subtype="PERCENTAGE",
        description="The share of each swatch element's faces kept, each element simplified "
        "on its own; the layout is the same as at 100%. Lower is faster and lighter")
    wind_frames: bpy.props.IntProperty(
        name="Wind", default=0, min=0, max=250,
        description="The Ivy sample's leaves turning in a looping wind of this many frames (0: "
        "still): one shape key a frame, played from the scene's start frame. Needs Detail 100%")
    swatch_motion: bpy.props.BoolProperty(
        name="Swatch motion", default=False,
        description="The swatch object's own animation (shape keys, armature, modifiers) over "
        "the scene's frame range, followed by the result: one shape key a frame. Any swatch, "
        "at Detail 100%")
    # The engine's last estimate (meshquilt.estimate) and the settings it was made for.
    estimate_key: bpy.props.StringProperty(options={"SKIP_SAVE"})
    estimate_faces: bpy.props.IntProperty(name="Estimated faces", options={"SKIP_SAVE"})
    estimate_gib: bpy.props.FloatProperty(name="Estimated memory (GiB)", options={"SKIP_SAVE"})
    estimate_seconds: bpy.props.FloatProperty(name="Estimated time (s)", options={"SKIP_SAVE"})
    estimate_fits: bpy.props.BoolProperty(name="Within the memory limit", options={"SKIP_SAVE"})
    estimate_error: bpy.props.StringProperty(options={"SKIP_SAVE"})


def swatch_frames(settings, preview=False):
    """The swatch frames a run follows (docs/animation.md): Wind for the Ivy sample, the scene's
    frame range for a swatch object with Swatch motion, else 0 (a Preview shows the still
    layout)."""
    if preview:
        return 0
    if settings.swatch_source == "OBJECT":
        scene = settings.id_data
        return scene.frame_end - scene.frame_start + 1 if settings.swatch_motion else 0
    return settings.wind_frames if settings.sample == "ivy" else 0


def estimate_key(context, settings):
    """The settings an estimate depends on, as a string cheap enough for draw(): the base (its
    mesh's size, modifiers and placement), the swatch, scale, seed, guidance, detail, mask, size
    group and the limit."""
    base = settings.base
    if base is None or base.type != "MESH":
        return ""
    parts = [base.name, len(base.data.vertices), len(base.data.polygons),
             [(m.name, m.show_viewport) for m in base.modifiers],
             [round(x, 5) for row in base.matrix_world for x in row]]
    if settings.swatch_source == "OBJECT":
        sw = settings.swatch
        parts += ["object", sw.name if sw else "", len(sw.data.polygons) if sw else 0]
    else:
        parts += ["sample", settings.sample]
    parts += [round(settings.scale, 6), round(settings.element_size, 6), settings.seed,
              settings.stretch, settings.guidance, settings.detail, settings.mask_group,
              settings.size_group, round(settings.smallest_size, 4), swatch_frames(settings)]
    if settings.guidance == "AXIS" and settings.guide_object is not None:
        parts += [settings.guide_object.name, settings.guide_axis,
                  [round(x, 4) for x in settings.guide_object.matrix_world.to_3x3().col[
                      "XYZ".index(settings.guide_axis)]]]
    elif settings.guidance == "ATTRIBUTE":
        parts.append(settings.guide_attribute)
    parts.append(round(_preferences(context).max_memory, 3))
    return repr(parts)


def estimate_text(settings):
    """The estimate in the panel: 'about 388k faces, 0.3 GiB, 2 s'."""
    n = settings.estimate_faces
    faces = "%.1fM" % (n / 1e6) if n >= 1e6 else "%dk" % round(n / 1e3) if n >= 1e4 else str(n)
    t = settings.estimate_seconds
    time_text = "%d s" % max(1, round(t)) if t < 90 else "%d min" % round(t / 60)
    return "~%s faces, %.1f GiB, %s" % (faces, settings.estimate_gib, time_text)


_diagonals = {}  # estimate_key's base part -> the evaluated base's world diagonal


def base_diagonal(context, base):
    """The bounding-box diagonal of the base as exported (evaluated, in world space), the
    length Scale is a fraction of; cached while the base is unchanged (cheap for draw())."""
    key = repr([base.name, len(base.data.vertices), len(base.data.polygons),
                [(m.name, m.show_viewport) for m in base.modifiers],
                [round(x, 5) for row in base.matrix_world for x in row]])
    if key not in _diagonals:
        evaluated = base.evaluated_get(context.evaluated_depsgraph_get())
        V = np.empty(3 * len(evaluated.data.vertices))
        evaluated.data.vertices.foreach_get("co", V)
        W = np.array(base.matrix_world)
        V = V.reshape(-1, 3) @ W[:3, :3].T + W[:3, 3]
        _diagonals.clear()
        _diagonals[key] = float(np.linalg.norm(V.max(0) - V.min(0))) if len(V) else 0.0
    return _diagonals[key]


# The sample swatches as `meshquilt swatch KIND` makes them: median faces per element (checked
# against the engine by the tests) and what the panel calls an element.
SAMPLE_ELEMENTS = {"chainmail": (1152, "ring"), "weave": (1940, "thread"),
                   "apples": (352, "apple"), "ivy": (192, "element")}
ENGINE_MIN_FACES = 24  # core/mesh/element_detail.h: no element is simplified below this
# A Preview's detail: a tenth of the setting's, but about 48 faces per element at least (a
# coarser ring no longer reads as a ring).
PREVIEW_SHARE, PREVIEW_MIN_FACES = 0.1, 48

_element_faces = {}  # the swatch object's key -> its median faces per element


def element_faces(context, settings):
    """The swatch's median faces per element and the panel's word for an element ("ring"): a
    sample's from SAMPLE_ELEMENTS, an object's counted over its connected parts (cached while it
    is unchanged: cheap for draw()); 0 faces without a swatch."""
    if settings.swatch_source == "SAMPLE":
        return SAMPLE_ELEMENTS[settings.sample]
    sw = settings.swatch
    if sw is None or sw.type != "MESH":
        return 0, "element"
    key = repr([sw.name, len(sw.data.vertices), len(sw.data.polygons),
                [(m.name, m.show_viewport) for m in sw.modifiers]])
    if key not in _element_faces:
        evaluated = sw.evaluated_get(context.evaluated_depsgraph_get())
        me = evaluated.to_mesh()
        try:
            T = exchange.mesh_arrays(me)[1]
            counts = exchange.part_face_counts(T, len(me.vertices))
        finally:
            evaluated.to_mesh_clear()
        _element_faces.clear()
        _element_faces[key] = int(np.median(counts)) if len(counts) else 0
    return _element_faces[key], "element"


def detail_faces(faces, share):
    """An element's faces at a detail share, as the engine sets its target (element_detail)."""
    return max(math.ceil(share * faces), min(faces, ENGINE_MIN_FACES))


def detail_text(context, settings):
    """'About 116 faces per ring (of 1152)': what Detail leaves of the swatch's elements."""
    faces, word = element_faces(context, settings)
    if faces <= 0:
        return ""
    kept = detail_faces(faces, settings.detail / 100.0)
    text = "About %d faces per %s" % (kept, word)
    return text if kept == faces else text + " (of %d)" % faces


def preview_share(share, faces):
    """A Preview's detail for the setting's share and the swatch's faces per element: never
    above the setting."""
    low = PREVIEW_SHARE * share
    if faces > 0:
        low = max(low, PREVIEW_MIN_FACES / faces)
    return min(share, low)


def _preferences(context):
    return context.preferences.addons[__name__].preferences


def _follow_changed(self, context):
    obj = self.id_data
    if not self.follow:
        return
    if self.baked:
        follow.clear_bake(obj)
    try:
        follow.place(obj, context.evaluated_depsgraph_get(), context, force=True)
    except (engine.EngineError, OSError, ValueError, KeyError) as e:
        follow.stop_following(obj, str(e))


class MeshquiltBinding(bpy.types.PropertyGroup):
    """A result's tie to its base (Object.meshquilt): its saved quilt and how it follows; on a
    base, the result the panel made last."""
    quilt: bpy.props.StringProperty(
        name="Saved quilt", subtype="FILE_PATH",
        description="The quilt saved by the run that made this object (meshquilt embed places "
        "it on the base moved)")
    base: bpy.props.PointerProperty(name="Base", type=bpy.types.Object,
                                    description="The object this result was quilted over")
    base_matrix: bpy.props.FloatVectorProperty(
        name="Base matrix", size=16, description="The base's world matrix when it was quilted")
    follow: bpy.props.BoolProperty(
        name="Follow base", default=False, update=_follow_changed,
        description="Place the result again on the base's evaluated mesh (modifiers, armature, "
        "shape keys) whenever the frame changes, without a new synthesis")
    baked: bpy.props.BoolProperty(
        name="Baked", default=False,
        description="The result's positions over the frame range are stored in shape keys")
    status: bpy.props.StringProperty(name="Status", default="")
    result: bpy.props.PointerProperty(
        name="Result", type=bpy.types.Object,
        description="On a base: its latest result from Run or Preview, which the next one "
        "replaces (a Run with Keep earlier results set replaces only a Preview)")


class Run:
    """One quilting run: inputs exported, the engine jobs in turn, the result imported. Both the
    modal operator (UI) and the blocking one (scripts) drive it through step()."""

    def __init__(self, context, settings, preview=False):
        prefs = _preferences(context)
        self.engine = engine.find_engine(prefs.engine_path)
        self.max_memory = prefs.max_memory
        self.scale = settings.scale
        base = settings.base
        if base is None or base.type != "MESH":
            raise engine.EngineError("pick a base mesh object")
        if settings.swatch_source == "OBJECT" and (settings.swatch is None or
                                                   settings.swatch.type != "MESH"):
            raise engine.EngineError("pick a swatch mesh object, or a sample swatch")
        if settings.guidance == "AXIS" and settings.guide_object is None:
            raise engine.EngineError("pick the object whose axis guides the texture")
        self.base = base
        self.dir = tempfile.mkdtemp(prefix="meshquilt-")
        self.result_path = os.path.join(self.dir, "result.ply")
        depsgraph = context.evaluated_depsgraph_get()
        base_path = os.path.join(self.dir, "base.ply")
        field = field_file = None
        self.topology = {}
        V, T = self._export(depsgraph, base, base_path, topology=self.topology)[:2]
        # Element size (scene units; the base is exported in world space, so these are its
        # units): the engine's --element-size; Scale stands for it where a scale is needed.
        self.element_size = settings.element_size
        # Detail: the share of each swatch element's faces kept; a Preview takes less.
        self.preview = preview
        self.keep_results = settings.keep_results
        self.detail = settings.detail / 100.0
        if preview:
            self.detail = preview_share(self.detail, element_faces(context, settings)[0])
        if self.element_size > 0:
            diagonal = float(np.linalg.norm(V.max(0) - V.min(0)))
            if diagonal <= 0:
                raise engine.EngineError("%s is flat to a point: no element size fits it"
                                         % base.name)
            self.scale = self.element_size / diagonal
        self.base_matrix = np.array(base.matrix_world)
        # Swatch frames (docs/animation.md): the sample's looping wind or the swatch object's
        # motion over the scene's frames; the engine writes one output a frame with frame 0's
        # faces, kept as shape keys. Such a result is not bound to its base (re-placing it
        # would drop the motion).
        self.frames = swatch_frames(settings, preview)
        self.loop = settings.swatch_source == "SAMPLE"
        if self.frames and self.detail < 1:
            raise engine.EngineError(
                "Wind moves the ivy as it is generated: set Detail to 100%, or Wind to 0"
                if self.loop else "Swatch motion follows the swatch as it is: set Detail to "
                "100%, or clear Swatch motion")
        self.output = os.path.join(self.dir, "result_%05d.ply") if self.frames else \
            self.result_path
        if self.frames:
            self.result_path = self.output % 0
        # The quilt saved for following the base.
        self.quilt_path = None if self.frames else os.path.join(self.dir, "quilt.mqq")
        if settings.guidance == "AXIS":
            axis = {"X": 0, "Y": 1, "Z": 2}[settings.guide_axis]
            field = tuple(settings.guide_object.matrix_world.to_3x3().col[axis])
        elif settings.guidance == "ATTRIBUTE":
            field_file = os.path.join(self.dir, "field.txt")
            self._export_field(depsgraph, base, settings.guide_attribute, field_file, len(V))
        mask_file = None
        if settings.mask_group:
            mask_file = os.path.join(self.dir, "mask.txt")
            self._export_mask(depsgraph, base, settings.mask_group, mask_file, len(V))
        size_file = None
        if settings.size_group:
            size_file = os.path.join(self.dir, "sizes.txt")
            self._export_sizes(depsgraph, base, settings.size_group, settings.smallest_size,
                               size_file, len(V))
        self.jobs = []
        self.material_names = {}  # the engine's kind name -> the swatch's material name
        self.swatch_name = settings.swatch.name if settings.swatch_source == "OBJECT" else \
            "the sample %s" % settings.sample
        if settings.swatch_source == "OBJECT":
            swatch_path = os.path.join(self.dir, "swatch.ply")
            if self.frames:
                made = os.path.join(self.dir, "swatch_%05d.ply")
                kinds = self._export_motion(context, settings.swatch, made, self.frames)
                swatch_path = made % 0
            else:
                kinds = self._export(depsgraph, settings.swatch, swatch_path, with_kinds=True)[2]
            self.material_names = {_engine_kind_name(k): k for k in kinds}
        else:
            swatch_path = os.path.join(self.dir, "swatch_%s.ply" % settings.sample)
            made = swatch_path
            if self.frames:
                made = os.path.join(self.dir, "swatch_%s_%%05d.ply" % settings.sample)
                swatch_path = made % 0
            self.jobs.append(lambda: engine.swatch_job(self.engine, settings.sample, made,
                                                       settings.seed, frames=self.frames))
        self.preparation = len(self.jobs)  # the jobs before the surface job
        self.paths = (base_path, swatch_path)
        self.stats_path = os.path.join(self.dir, "stats.json")
        self.elements_path = os.path.join(self.dir, "elements.csv")
        self.options = dict(seed=settings.seed, stretch=settings.stretch, field=field,
                            field_file=field_file, max_memory=self.max_memory,
                            element_size=self.element_size, detail=self.detail, mask=mask_file,
                            size_map=size_file)
        if self.frames:
            self.options.update(swatch_frames=made, frames=(0, self.frames - 1))
        self.jobs.append(lambda: engine.surface_job(
            self.engine, base_path, swatch_path, self.output, self.scale,
            save_quilt=self.quilt_path, stats=self.stats_path, **self.options))
        # The structure measured against the swatch for the report (optional: a failure
        # there leaves the result and the rest of the report).
        self.jobs.append(lambda: engine.info_job(
            self.engine, self.result_path, swatch_path, base_path, self.elements_path,
            self.scale))
        self.optional_jobs = 1
        self.total = len(self.jobs)
        self.job = None
        self.state = "running"
        self.error = ""
        self.result = None
        self.started = time.monotonic()
        self.overall = 0.0

    @staticmethod
    def _export(depsgraph, obj, path, with_kinds=False, topology=None):
        evaluated = obj.evaluated_get(depsgraph)
        me = evaluated.to_mesh()
        try:
            V, T, M = exchange.mesh_arrays(me)
            if topology is not None:
                topology["T"] = T
                topology["loops"], topology["totals"] = follow.topology(me)
            kinds = None
            if with_kinds:
                kinds = [slot.material.name if slot.material else "element"
                         for slot in obj.material_slots] or ["element"]
                M = np.clip(M, 0, len(kinds) - 1)
        finally:
            evaluated.to_mesh_clear()
        if len(T) == 0:
            raise engine.EngineError("%s has no faces" % obj.name)
        W = np.array(obj.matrix_world)
        V = V @ W[:3, :3].T + W[:3, 3]
        exchange.write_ply(path, V, T, kinds, M if kinds else None)
        return V, T, kinds or []

    @staticmethod
    def _export_motion(context, swatch, pattern, count):
        """The swatch object as evaluated at each of the scene's frames from its start (its
        shape keys, armature, modifiers and placement), one file a frame; returns its kinds.
        Refuses a swatch whose mesh changes over the frames, or that does not move."""
        scene = context.scene
        was = scene.frame_current, scene.frame_subframe
        first = scene.frame_start
        rest, moved, kinds = None, False, []
        # Results following their bases stay where they are while the frames are stepped.
        follow.set_stepping(True)
        try:
            for i in range(count):
                scene.frame_set(first + i)
                V, T, kinds = Run._export(context.evaluated_depsgraph_get(), swatch, pattern % i,
                                          with_kinds=True)
                if rest is None:
                    rest = V, T
                elif len(V) != len(rest[0]) or not np.array_equal(T, rest[1]):
                    raise engine.EngineError(
                        "the swatch %s changes its mesh over frames %d-%d, not only where its "
                        "vertices are: Swatch motion needs the same mesh in every frame"
                        % (swatch.name, first, first + count - 1))
                else:
                    moved = moved or not np.allclose(V, rest[0], rtol=0, atol=1e-9)
        finally:
            scene.frame_set(was[0], subframe=was[1])
            follow.set_stepping(False)
        if not moved:
            raise engine.EngineError("the swatch %s does not move over frames %d-%d: animate "
                                     "it, or clear Swatch motion"
                                     % (swatch.name, first, first + count - 1))
        return kinds

    @staticmethod
    def _export_field(depsgraph, obj, name, path, count):
        evaluated = obj.evaluated_get(depsgraph)
        attribute = evaluated.data.attributes.get(name)
        if attribute is None or attribute.domain != "POINT" or \
                attribute.data_type != "FLOAT_VECTOR":
            raise engine.EngineError(
                "%s has no vertex vector attribute named '%s'" % (obj.name, name))
        vectors = np.empty(3 * len(attribute.data), dtype=np.float64)
        attribute.data.foreach_get("vector", vectors)
        vectors = vectors.reshape(-1, 3) @ np.array(obj.matrix_world)[:3, :3].T
        if len(vectors) != count:
            raise engine.EngineError("the guidance attribute has %d values for %d vertices"
                                     % (len(vectors), count))
        np.savetxt(path, vectors, fmt="%.9g")

    @staticmethod
    def _group_weights(depsgraph, obj, name, count, setting):
        """The weights of the vertex group `name` of the evaluated base, one per exported
        vertex (0 where a vertex is not in the group); `setting` names the panel's row."""
        group = obj.vertex_groups.get(name)
        if group is None:
            raise engine.EngineError("%s has no vertex group named '%s' (the %s)"
                                     % (obj.name, name, setting))
        evaluated = obj.evaluated_get(depsgraph)
        me = evaluated.to_mesh()
        try:
            weights = np.zeros(len(me.vertices))
            for v in me.vertices:
                for g in v.groups:
                    if g.group == group.index:
                        weights[v.index] = g.weight
                        break
        finally:
            evaluated.to_mesh_clear()
        if len(weights) != count:
            raise engine.EngineError("the %s has %d weights for %d vertices"
                                     % (setting, len(weights), count))
        return np.clip(weights, 0.0, 1.0)

    @staticmethod
    def _export_mask(depsgraph, obj, name, path, count):
        """The Mask group's weights as the engine's --mask file."""
        weights = Run._group_weights(depsgraph, obj, name, count, "Mask")
        if not (weights >= 0.5).any():
            raise engine.EngineError(
                "the Mask '%s' sets no vertex of %s (no weight of 0.5 or more): assign vertices "
                "to it with a weight of 0.5 or more, or clear Mask" % (name, obj.name))
        np.savetxt(path, weights, fmt="%.6g",
                   header="meshquilt mask: vertex group '%s' of %s" % (name, obj.name))

    @staticmethod
    def _export_sizes(depsgraph, obj, name, smallest, path, count):
        """The Size group's weights w as the engine's --size-map file: smallest + (1 -
        smallest) w per vertex (the full size at weight 1)."""
        weights = Run._group_weights(depsgraph, obj, name, count, "Size group")
        np.savetxt(path, smallest + (1.0 - smallest) * weights, fmt="%.6g",
                   header="meshquilt size map: vertex group '%s' of %s" % (name, obj.name))

    def artist_message(self, error):
        """The engine's error in the panel's terms for this run's objects and settings."""
        return engine.artist_message(error, self.scale, self.max_memory, self.base.name,
                                     self.swatch_name, self.element_size)

    def step(self):
        """Advances the run; returns its state ("running", "done", "failed", "cancelled")."""
        if self.state != "running":
            return self.state
        if self.job is None:
            self.job = self.jobs.pop(0)()
        state = self.job.poll()
        if state == "failed" and len(self.jobs) < self.optional_jobs:
            state = "done"  # an optional job: the run goes on without what it adds
        if state == "failed":
            self.state, self.error = "failed", self.artist_message(self.job.error)
        elif state == "cancelled":
            self.state = "cancelled"
        elif state == "done":
            self.job = None
            if not self.jobs:
                self.state = "done"
        return self.state

    def estimate(self):
        """The engine's estimate for these settings (blocking: runs a sample swatch's job
        first); the run's surface job is then not started. Returns engine.estimate's dict."""
        for _ in range(self.preparation):
            job = self.jobs.pop(0)()
            if job.wait(60) != "done":
                raise engine.EngineError(job.error)
        self.preparation = 0
        return engine.estimate(self.engine, self.paths[0], self.paths[1], self.output,
                               self.scale, **self.options)

    # Shares of the whole run: the sample swatch before, the structure measure after.
    PREPARATION_SHARE, INFO_SHARE = 0.03, 0.03

    def fraction(self):
        """The run's overall fraction: monotone, 1 once done (the surface job's stages by
        their typical shares, engine.Progress; the jobs around it a small share each)."""
        if self.state == "done":
            self.overall = 1.0
            return 1.0
        surface = self.total - self.optional_jobs - 1  # its index among the jobs
        index = self.total - len(self.jobs) - (1 if self.job else 0)  # jobs finished
        share = 1.0 - self.INFO_SHARE - (self.PREPARATION_SHARE if surface else 0.0)
        before = self.PREPARATION_SHARE * min(index, surface) / surface if surface else 0.0
        if index > surface:
            value = before + share
        elif index == surface and self.job is not None:
            value = before + share * self.job.overall
        else:
            value = before
        self.overall = max(self.overall, min(value, 0.99))
        return self.overall

    def status_text(self):
        detail = self.job.stage if self.job is not None and self.job.stage != "starting" \
            else "starting"
        return engine.progress_text(self.fraction(), time.monotonic() - self.started, detail)

    def cancel(self):
        if self.job is not None:
            self.job.cancel()
        self.state = "cancelled"
        self.cleanup()

    def import_result(self, context):
        result = exchange.read_ply(self.result_path)
        # One result per base: a Preview replaces the base's latest result, and so does a Run
        # unless the artist keeps earlier results (then it replaces only a Preview).
        replaced = self.base.meshquilt.result
        if replaced is not None and (replaced.meshquilt.base != self.base or (
                self.keep_results and not self.preview and
                not replaced.get("meshquilt_preview"))):
            replaced = None
        name = replaced.name if replaced is not None else "%s_quilt" % self.base.name
        # The swatch's own materials for its kinds (the engine's names replace spaces).
        me = exchange.build_mesh(bpy, name, result, lambda kind, look: material_for(
            self.material_names.get(kind, kind), look))
        users = replaced.users_collection if replaced is not None else \
            self.base.users_collection
        collection = users[0] if users else context.scene.collection
        if replaced is not None:
            if replaced.mode != "OBJECT":
                bpy.ops.object.mode_set(mode="OBJECT")  # not left in a mode with it gone
            old = replaced.data
            bpy.data.objects.remove(replaced)
            if old.users == 0:
                bpy.data.meshes.remove(old)
            me.name = name
        obj = bpy.data.objects.new(name, me)
        collection.objects.link(obj)
        obj.meshquilt.base = self.base
        self.base.meshquilt.result = obj
        if self.preview:
            obj["meshquilt_preview"] = True
        # The result is in world coordinates: parented without moving.
        obj.parent = self.base
        obj.matrix_parent_inverse = self.base.matrix_world.inverted()
        if self.quilt_path and os.path.exists(self.quilt_path):
            follow.bind(obj, self.base, self.quilt_path, self.topology["T"],
                        self.topology["loops"], self.topology["totals"], self.base_matrix)
        if self.frames:
            frames = [result.V] + [exchange.read_ply(self.output % k).V
                                   for k in range(1, self.frames)]
            if any(len(V) != len(result.V) for V in frames):
                raise engine.EngineError("the result's frames do not match its first")
            follow.keep_frames(obj, frames, context.scene.frame_start, loop=self.loop)
            obj["meshquilt_frames"] = self.frames
            obj["meshquilt_loop"] = self.loop
        try:
            store_report(obj, exchange.structure_report(self.stats_path, self.elements_path))
        except (OSError, ValueError, KeyError) as e:
            print("meshquilt: no structure report: %s" % e)
        self.result = obj
        return obj

    def cleanup(self):
        shutil.rmtree(self.dir, ignore_errors=True)


def store_report(obj, report):
    """The structure report on the result object, as custom properties (meshquilt_report:
    elements, links_kept %, coverage %, distorted; meshquilt_distorted_ids)."""
    ids = report.pop("distorted_ids", None)
    obj["meshquilt_report"] = report
    if ids is not None:
        obj["meshquilt_distorted_ids"] = ids


def _engine_kind_name(name):
    """A kind name as the engine writes it (core/mesh/element_kinds.cpp sanitized_kind)."""
    s = "".join(c if " " < c < "\x7f" and c != "#" else "_" for c in name)
    return s or "element"


def material_for(kind, look):
    """The material of a kind: an existing one of that name (an artist's own), else a new
    Principled BSDF material with the engine's look for the kind."""
    material = bpy.data.materials.get(kind)
    if material is not None:
        return material
    material = bpy.data.materials.new(kind)
    material.use_nodes = True
    bsdf = material.node_tree.nodes.get("Principled BSDF")
    if look is not None:
        r, g, b, metallic, roughness = look
        material.diffuse_color = (r, g, b, 1.0)
        material.metallic, material.roughness = metallic, roughness
        # Inputs by name: these three kept their names in Blender 4.0's Principled BSDF (others,
        # such as Specular and Emission, were renamed); a missing one is skipped, not a
        # KeyError (the viewport colour above is set either way).
        if bsdf is not None:
            for socket, value in (("Base Color", (r, g, b, 1.0)), ("Metallic", metallic),
                                  ("Roughness", roughness)):
                if socket in bsdf.inputs:
                    bsdf.inputs[socket].default_value = value
    return material


def _redraw_panels(context):
    """Redraws the 3D views' sidebars (where the panel is) in every window."""
    for window in context.window_manager.windows:
        for area in window.screen.areas:
            if area.type == "VIEW_3D":
                for region in area.regions:
                    if region.type == "UI":
                        region.tag_redraw()


class _Quilting:
    """Run and Preview, one code path: a Preview is a Run at a lower detail (Run.preview)."""
    bl_options = {"REGISTER", "UNDO"}

    timeout: bpy.props.FloatProperty(name="Timeout", default=0.0, options={"SKIP_SAVE"},
                                     description="Scripts: cancel after this many seconds (0: none)")

    @classmethod
    def poll(cls, context):
        return "run" not in _running

    def _finish(self, context, run):
        if run.state == "done":
            try:
                obj = run.import_result(context)
            except (OSError, ValueError, KeyError) as e:
                self.report({"ERROR"}, "meshquilt: cannot read the result: %s" % e)
                return {"CANCELLED"}
            finally:
                run.cleanup()
            self.report({"INFO"}, "meshquilt: %s%s, %d faces" % (
                obj.name, " (preview)" if run.preview else "", len(obj.data.polygons)))
            # A result that lost the swatch's structure is made, and said so (issue 23).
            warnings = (obj.get("meshquilt_report") or {}).get("warnings")
            if warnings:
                self.report({"WARNING"}, "meshquilt: %s: %s" % (obj.name, warnings))
            return {"FINISHED"}
        run.cleanup()
        if run.state == "failed":
            self.report({"ERROR"}, run.error)
        else:
            self.report({"WARNING"}, "meshquilt: cancelled")
        return {"CANCELLED"}

    def _start(self, context):
        try:
            return Run(context, context.scene.meshquilt, preview=self.preview)
        except (engine.EngineError, OSError, ValueError) as e:
            self.report({"ERROR"}, str(e))
            return None

    def execute(self, context):
        # Blocking, for scripts: bpy.ops.meshquilt.run(), bpy.ops.meshquilt.preview().
        run = self._start(context)
        if run is None:
            return {"CANCELLED"}
        start = time.monotonic()
        while run.step() == "running":
            if self.timeout > 0 and time.monotonic() - start > self.timeout:
                run.cancel()
                break
            time.sleep(0.05)
        return self._finish(context, run)

    def invoke(self, context, event):
        if self._begin(context) is None:
            return {"CANCELLED"}
        context.window_manager.modal_handler_add(self)
        return {"RUNNING_MODAL"}

    def _begin(self, context):
        """The run started for the modal operator (everything but its handler)."""
        run = self._start(context)
        if run is None:
            return None
        # Running from now on: the panel shows Cancel before the engine's first line.
        _running["run"] = run
        wm = context.window_manager
        self._timer = wm.event_timer_add(0.1, window=context.window)
        wm.progress_begin(0, 100)
        wm.progress_update(0)
        context.workspace.status_text_set(run.status_text())
        _redraw_panels(context)
        return run

    def modal(self, context, event):
        run = _running.get("run")
        if event.type == "ESC" or run is None or _running.get("cancel"):
            if run is not None:
                run.cancel()
            return self._end(context, run)
        if event.type != "TIMER":
            return {"PASS_THROUGH"}
        try:
            state = run.step()
        except (engine.EngineError, OSError) as e:
            run.state, run.error = "failed", str(e)
            state = "failed"
        context.window_manager.progress_update(int(100 * run.fraction()))
        context.workspace.status_text_set(run.status_text())
        _redraw_panels(context)
        if state == "running":
            return {"PASS_THROUGH"}
        return self._end(context, run)

    def _end(self, context, run):
        wm = context.window_manager
        wm.event_timer_remove(self._timer)
        wm.progress_end()
        context.workspace.status_text_set(None)
        _running.clear()
        for area in context.screen.areas:
            area.tag_redraw()
        if run is None:
            return {"CANCELLED"}
        return self._finish(context, run)


class MESHQUILT_OT_run(_Quilting, bpy.types.Operator):
    """Quilt the swatch over the base in the background (it replaces the base's Preview)"""
    bl_idname = "meshquilt.run"
    bl_label = "Run"
    preview = False


class MESHQUILT_OT_preview(_Quilting, bpy.types.Operator):
    """The same job at low detail, fast (a tenth of Detail, at least about 48 faces per
    element): the layout of the full result, which the next Run puts in its place"""
    bl_idname = "meshquilt.preview"
    bl_label = "Preview"
    preview = True


class MESHQUILT_OT_estimate(bpy.types.Operator):
    """Ask the engine how large the job of the current settings is (faces, memory, rough
    time) without running it; shown in the panel until a setting changes"""
    bl_idname = "meshquilt.estimate"
    bl_label = "Estimate"

    @classmethod
    def poll(cls, context):
        return "run" not in _running

    def execute(self, context):
        s = context.scene.meshquilt
        key = estimate_key(context, s)
        run = None
        try:
            run = Run(context, s)
            e = run.estimate()
        except (engine.EngineError, OSError, ValueError) as e:
            message = str(e)
            if run is not None and isinstance(e, engine.EngineError):
                message = run.artist_message(message)
            s.estimate_key, s.estimate_error = key, message
            self.report({"ERROR"}, message)
            return {"CANCELLED"}
        finally:
            if run is not None:
                run.cleanup()
        s.estimate_key, s.estimate_error = key, ""
        s.estimate_faces, s.estimate_gib = e["faces"], e["bytes"] / 2.0 ** 30
        s.estimate_seconds, s.estimate_fits = e["seconds"], e["fits"]
        self.report({"INFO"}, "meshquilt: " + estimate_text(s))
        return {"FINISHED"}


class MESHQUILT_OT_import(bpy.types.Operator, ImportHelper):
    """Import a result of the meshquilt engine (a PLY it wrote): element ids and kinds as face
    attributes, a material per kind"""
    bl_idname = "import_mesh.meshquilt_ply"
    bl_label = "Import meshquilt result"
    bl_options = {"REGISTER", "UNDO"}

    filename_ext = ".ply"
    filter_glob: bpy.props.StringProperty(default="*.ply", options={"HIDDEN"})

    def execute(self, context):
        try:
            result = exchange.read_ply(self.filepath)
        except (OSError, ValueError, KeyError) as e:
            self.report({"ERROR"}, "cannot read %s as a meshquilt result (a binary PLY the "
                        "engine wrote): %s" % (os.path.basename(self.filepath), e))
            return {"CANCELLED"}
        name = os.path.splitext(os.path.basename(self.filepath))[0] or "meshquilt"
        me = exchange.build_mesh(bpy, name, result, material_for)
        obj = bpy.data.objects.new(name, me)
        context.collection.objects.link(obj)
        for other in context.selected_objects:
            other.select_set(False)
        obj.select_set(True)
        context.view_layer.objects.active = obj
        self.report({"INFO"}, "meshquilt: %s, %d elements, %d faces"
                    % (obj.name, len(np.unique(result.face_element)), len(me.polygons)))
        return {"FINISHED"}


def _menu_import(self, context):
    self.layout.operator(MESHQUILT_OT_import.bl_idname, text="meshquilt result (.ply)")


class MESHQUILT_OT_select_distorted(bpy.types.Operator):
    """Select the faces of the elements over 1.5x their swatch element's size (the run's
    structure report)"""
    bl_idname = "meshquilt.select_distorted"
    bl_label = "Select distorted"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        obj = context.active_object
        return obj is not None and obj.type == "MESH" and "element_id" in obj.data.attributes \
            and "meshquilt_distorted_ids" in obj

    def execute(self, context):
        obj = context.active_object
        editing = obj.mode == "EDIT"
        if editing:
            bpy.ops.object.mode_set(mode="OBJECT")
        try:
            me = obj.data
            ids = np.empty(len(me.polygons), dtype=np.int32)
            me.attributes["element_id"].data.foreach_get("value", ids)
            distorted = np.array(list(obj["meshquilt_distorted_ids"]), dtype=np.int32)
            chosen = np.isin(ids, distorted)
            me.vertices.foreach_set("select", np.zeros(len(me.vertices), dtype=bool))
            me.edges.foreach_set("select", np.zeros(len(me.edges), dtype=bool))
            me.polygons.foreach_set("select", chosen)
        finally:
            if editing:
                bpy.ops.object.mode_set(mode="EDIT")
        if not chosen.any():
            self.report({"INFO"}, "no element over 1.5x its swatch size")
        else:
            self.report({"INFO"}, "%d distorted elements: %d faces selected"
                        % (len(np.unique(ids[chosen])), int(chosen.sum())))
        return {"FINISHED"}


class MESHQUILT_OT_cancel(bpy.types.Operator):
    """Stop the running quilting; nothing is added to the scene"""
    bl_idname = "meshquilt.cancel"
    bl_label = "Cancel"

    @classmethod
    def poll(cls, context):
        return "run" in _running

    def execute(self, context):
        _running["cancel"] = True
        return {"FINISHED"}


class MESHQUILT_OT_select_element(bpy.types.Operator):
    """Select the faces of one element (ring, thread, leaf) of a meshquilt result by its id"""
    bl_idname = "meshquilt.select_element"
    bl_label = "Select element"
    bl_options = {"REGISTER", "UNDO"}

    element: bpy.props.IntProperty(name="Element id", default=0, min=0)
    extend: bpy.props.BoolProperty(name="Extend", default=False)

    @classmethod
    def poll(cls, context):
        obj = context.active_object
        return obj is not None and obj.type == "MESH" and "element_id" in obj.data.attributes

    def execute(self, context):
        obj = context.active_object
        editing = obj.mode == "EDIT"
        if editing:
            bpy.ops.object.mode_set(mode="OBJECT")
        me = obj.data
        ids = np.empty(len(me.polygons), dtype=np.int32)
        me.attributes["element_id"].data.foreach_get("value", ids)
        chosen = ids == self.element
        if not chosen.any():
            self.report({"ERROR"}, "%s has no element %d (ids 0 to %d)"
                        % (obj.name, self.element, int(ids.max())))
            if editing:
                bpy.ops.object.mode_set(mode="EDIT")
            return {"CANCELLED"}
        if self.extend:
            old = np.empty(len(me.polygons), dtype=bool)
            me.polygons.foreach_get("select", old)
            chosen |= old
        else:
            me.vertices.foreach_set("select", np.zeros(len(me.vertices), dtype=bool))
            me.edges.foreach_set("select", np.zeros(len(me.edges), dtype=bool))
        me.polygons.foreach_set("select", chosen)
        if editing:
            bpy.ops.object.mode_set(mode="EDIT")
        self.report({"INFO"}, "element %d: %d faces" % (self.element, int((ids == self.element).sum())))
        return {"FINISHED"}


def _bound_result(context):
    obj = context.active_object
    return obj if follow.is_bound(obj) and "element_id" in obj.data.attributes else None


class MESHQUILT_OT_bake(bpy.types.Operator):
    """Place the result on its base at every frame of the scene's range (one engine run) and
    keep the positions in shape keys: playback needs no engine"""
    bl_idname = "meshquilt.bake"
    bl_label = "Bake frames"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        return _bound_result(context) is not None and "run" not in _running

    def execute(self, context):
        obj = _bound_result(context)
        if obj.mode != "OBJECT":
            bpy.ops.object.mode_set(mode="OBJECT")
        try:
            count = follow.bake(context, obj)
        except (engine.EngineError, OSError, ValueError, KeyError) as e:
            obj.meshquilt.status = str(e)
            self.report({"ERROR"}, str(e))
            return {"CANCELLED"}
        self.report({"INFO"}, "meshquilt: %s baked over %d frames" % (obj.name, count))
        return {"FINISHED"}


class MESHQUILT_OT_clear_bake(bpy.types.Operator):
    """Remove the baked positions (the result's shape keys and their animation)"""
    bl_idname = "meshquilt.clear_bake"
    bl_label = "Clear bake"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        obj = _bound_result(context)
        return obj is not None and obj.meshquilt.baked and obj.mode == "OBJECT"

    def execute(self, context):
        follow.clear_bake(_bound_result(context))
        return {"FINISHED"}


class MESHQUILT_OT_remove_selected(bpy.types.Operator):
    """Remove the elements with a selected face from the saved quilt and place the rest on the
    base as it is now (a baked result is baked again)"""
    bl_idname = "meshquilt.remove_selected"
    bl_label = "Remove selected elements"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        return _bound_result(context) is not None and "run" not in _running

    def execute(self, context):
        obj = _bound_result(context)
        editing = obj.mode == "EDIT"
        if editing:
            bpy.ops.object.mode_set(mode="OBJECT")  # the edit-mode selection into the mesh
        try:
            me = obj.data
            selected = np.empty(len(me.polygons), dtype=bool)
            me.polygons.foreach_get("select", selected)
            ids = np.empty(len(me.polygons), dtype=np.int32)
            me.attributes["element_id"].data.foreach_get("value", ids)
            chosen = np.unique(ids[selected])
            if len(chosen) == 0:
                self.report({"ERROR"}, "select faces of the elements to remove")
                return {"CANCELLED"}
            if len(chosen) == len(np.unique(ids)):
                self.report({"ERROR"}, "that is every element: delete the object instead")
                return {"CANCELLED"}
            try:
                follow.remove_elements(context, obj, chosen)
            except (engine.EngineError, OSError, ValueError, KeyError) as e:
                obj.meshquilt.status = str(e)
                self.report({"ERROR"}, str(e))
                return {"CANCELLED"}
            _report_after_removal(obj, chosen)
        finally:
            if editing:
                bpy.ops.object.mode_set(mode="EDIT")
        self.report({"INFO"}, "meshquilt: %d elements removed from %s" % (len(chosen), obj.name))
        return {"FINISHED"}


def _report_after_removal(obj, removed):
    """The structure report after removing elements: the ids after them move down (the engine
    numbers the rest again in order); the removed are no longer counted."""
    if "meshquilt_report" not in obj:
        return
    report = obj["meshquilt_report"]
    if "elements" in report:
        report["elements"] = max(0, int(report["elements"]) - len(removed))
    if "meshquilt_distorted_ids" in obj:
        old = np.array(list(obj["meshquilt_distorted_ids"]), dtype=np.int64)
        kept = old[~np.isin(old, removed)]
        new = kept - np.searchsorted(np.sort(removed), kept)
        obj["meshquilt_distorted_ids"] = [int(i) for i in new]
        report["distorted"] = len(new)


def _draw_estimate(layout, context, s):
    """The estimate for the current settings (stored by meshquilt.estimate; draw() runs no
    engine): shown while the settings are those it was made for."""
    current = s.estimate_key and s.estimate_key == estimate_key(context, s)
    row = layout.row(align=True)
    if current and s.estimate_error:
        row.label(text="Estimate failed", icon="ERROR")
    elif current:
        # No icon when it fits: the sidebar's default width then shows the whole line.
        row.label(text=estimate_text(s), icon="NONE" if s.estimate_fits else "ERROR")
    else:
        row.label(text="Size: not estimated")
    row.operator("meshquilt.estimate", text="", icon="FILE_REFRESH")
    if current and not s.estimate_error and not s.estimate_fits:
        layout.label(text="Over the memory limit: raise Scale or lower Detail")


def _draw_report(layout, obj):
    """The run's structure report stored on the result."""
    report = obj.get("meshquilt_report")
    if report is None:
        return
    box = layout.box()
    box.label(text="Structure")
    col = box.column(align=True)
    if "elements" in report:
        col.label(text="Elements: %d" % report["elements"])
    if "links_kept" in report:
        col.label(text="Links kept: %.0f%%" % report["links_kept"])
    if "coverage" in report:
        col.label(text="Coverage: %.0f%%" % report["coverage"])
    for warning in (report.get("warnings") or "").split("; "):
        if warning:
            col.label(text=warning, icon="ERROR")
    if "distorted" in report:
        col.label(text="Over 1.5x size: %d" % report["distorted"])
        if report["distorted"]:
            box.operator("meshquilt.select_distorted", icon="RESTRICT_SELECT_OFF")


def _draw_element_size(layout, context, s):
    """What the swatch's longer side will be in scene units (Scale x the base's diagonal)."""
    if s.element_size > 0:
        layout.label(text="Element size used instead of Scale", icon="INFO")
        return
    if s.base is None or s.base.type != "MESH":
        return
    diagonal = base_diagonal(context, s.base)
    if diagonal > 0:
        unit = context.scene.unit_settings
        text = bpy.utils.units.to_string(
            unit.system, "LENGTH", s.scale * diagonal * unit.scale_length, precision=3) \
            if unit.system != "NONE" else "%.4g" % (s.scale * diagonal)
        layout.label(text="At this Scale: %s" % text)  # short: the sidebar cuts long labels


_LABEL_SHARE = 0.32  # of the sidebar's width for a setting's name: "Guidance" in full


def _labelled(layout, data, prop, text, search=None):
    """A setting with its name in a column of its own, so that the sidebar's default width shows
    the whole name ("Sam...", "Guid..." were cut off by Blender's own split); search: (data,
    collection) to pick a name from, as prop_search."""
    row = layout.split(factor=_LABEL_SHARE)
    row.label(text=text)
    if search:
        row.prop_search(data, prop, *search, text="")
    else:
        row.prop(data, prop, text="")


class MESHQUILT_PT_panel(bpy.types.Panel):
    bl_label = "meshquilt"
    bl_idname = "MESHQUILT_PT_panel"
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "meshquilt"

    def draw(self, context):
        s = context.scene.meshquilt
        layout = self.layout
        _labelled(layout, s, "base", "Base")
        layout.prop(s, "swatch_source", expand=True)
        if s.swatch_source == "OBJECT":
            _labelled(layout, s, "swatch", "Swatch")
            layout.prop(s, "swatch_motion")
        else:
            _labelled(layout, s, "sample", "Sample")
            if s.sample == "ivy":
                layout.prop(s, "wind_frames")
        layout.prop(s, "scale")
        layout.prop(s, "element_size")
        _draw_element_size(layout, context, s)
        layout.prop(s, "detail")
        text = detail_text(context, s)
        if text:
            layout.label(text=text)
        _labelled(layout, s, "guidance", "Guidance")
        if s.guidance == "AXIS":
            row = layout.row()
            row.prop(s, "guide_object")
            row.prop(s, "guide_axis", text="")
        elif s.guidance == "ATTRIBUTE":
            layout.prop(s, "guide_attribute")
        if s.base is not None and s.base.type == "MESH":
            _labelled(layout, s, "mask_group", "Mask", search=(s.base, "vertex_groups"))
            _labelled(layout, s, "size_group", "Size", search=(s.base, "vertex_groups"))
            if s.size_group:
                _labelled(layout, s, "smallest_size", "Smallest")
        layout.prop(s, "stretch")
        layout.prop(s, "seed")
        layout.prop(s, "keep_results")
        _draw_estimate(layout, context, s)
        if "run" in _running:
            run = _running["run"]
            layout.label(text=run.status_text())
            layout.operator("meshquilt.cancel", icon="CANCEL")
        else:
            row = layout.row(align=True)
            row.operator("meshquilt.run", icon="PLAY")
            row.operator("meshquilt.preview", icon="HIDE_OFF")
        obj = context.active_object
        if obj is not None and obj.type == "MESH" and "element_id" in obj.data.attributes:
            if obj.get("meshquilt_preview"):
                layout.label(text="Preview (low detail) - Run for the full result", icon="INFO")
            layout.operator("meshquilt.select_element")
            _draw_report(layout, obj)
            b = obj.meshquilt
            box = layout.box()
            if obj.get("meshquilt_frames"):
                box.label(text=("In the wind: %d frames a loop" if obj.get("meshquilt_loop")
                                else "Following the swatch's motion: %d frames")
                          % obj["meshquilt_frames"], icon="FORCE_WIND")
                return
            if not b.quilt:
                box.label(text="No saved quilt: cannot follow its base", icon="INFO")
                return
            box.label(text="Base: %s" % (b.base.name if b.base else "(gone)"))
            box.prop(b, "follow")
            row = box.row(align=True)
            row.operator("meshquilt.bake", icon="REC",
                         text="Bake frames %d-%d" % (context.scene.frame_start,
                                                      context.scene.frame_end))
            if b.baked:
                row.operator("meshquilt.clear_bake", icon="X", text="")
            box.operator("meshquilt.remove_selected", icon="TRASH", text="Remove selected")
            if b.status:
                box.label(text=b.status, icon="ERROR")


classes = (MeshquiltPreferences, MeshquiltSettings, MeshquiltBinding, MESHQUILT_OT_run,
           MESHQUILT_OT_preview, MESHQUILT_OT_estimate, MESHQUILT_OT_import,
           MESHQUILT_OT_select_distorted, MESHQUILT_OT_cancel, MESHQUILT_OT_select_element,
           MESHQUILT_OT_bake, MESHQUILT_OT_clear_bake, MESHQUILT_OT_remove_selected,
           MESHQUILT_PT_panel)


def register():
    for c in classes:
        bpy.utils.register_class(c)
    bpy.types.Scene.meshquilt = bpy.props.PointerProperty(type=MeshquiltSettings)
    bpy.types.Object.meshquilt = bpy.props.PointerProperty(type=MeshquiltBinding)
    bpy.types.TOPBAR_MT_file_import.append(_menu_import)
    follow.register()


def unregister():
    run = _running.pop("run", None)
    if run is not None:
        run.cancel()
    follow.unregister()
    bpy.types.TOPBAR_MT_file_import.remove(_menu_import)
    del bpy.types.Object.meshquilt
    del bpy.types.Scene.meshquilt
    for c in reversed(classes):
        bpy.utils.unregister_class(c)
