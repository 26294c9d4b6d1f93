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

import os
import shutil
import tempfile

import bpy
import numpy as np

from . import engine, exchange, follow

_running = {}  # the one active Run, under key "run", while the modal operator works


def _mesh_poll(self, obj):
    return obj.type == "MESH"


class MeshquiltPreferences(bpy.types.AddonPreferences):
    bl_idname = __name__
    engine_path: bpy.props.StringProperty(
        name="Engine", subtype="FILE_PATH", default="",
        description="The meshquilt executable (empty: $MESHQUILT_ENGINE or meshquilt on PATH)")

    def draw(self, context):
        self.layout.prop(self, "engine_path")


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
    """A result's tie to its base (Object.meshquilt): its saved quilt and how it follows."""
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


class Run:
    """One quilting run: inputs exported, the engine jobs in turn, the result imported. Both the
    modal operator (UI) and the blocking one (scripts) drive it through step()."""

    def __init__(self, context, settings):
        prefs = context.preferences.addons[__name__].preferences
        self.engine = engine.find_engine(prefs.engine_path)
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
        self.base_matrix = np.array(base.matrix_world)
        # The quilt saved for following the base (not over a base the engine would simplify).
        self.quilt_path = os.path.join(self.dir, "quilt.mqq") \
            if len(T) <= follow.PROXY_MIN_FACES else None
        if settings.guidance == "AXIS":
            axis = {"X": 0, "Y": 1, "Z": 2}[settings.guide_axis]
            field = tuple(settings.guide_object.matrix_world.to_3x3().col[axis])
        elif settings.guidance == "ATTRIBUTE":
            field_file = os.path.join(self.dir, "field.txt")
            self._export_field(depsgraph, base, settings.guide_attribute, field_file, len(V))
        self.jobs = []
        self.material_names = {}  # the engine's kind name -> the swatch's material name
        if settings.swatch_source == "OBJECT":
            swatch_path = os.path.join(self.dir, "swatch.ply")
            kinds = self._export(depsgraph, settings.swatch, swatch_path, with_kinds=True)[2]
            self.material_names = {_engine_kind_name(k): k for k in kinds}
        else:
            swatch_path = os.path.join(self.dir, "swatch_%s.ply" % settings.sample)
            self.jobs.append(lambda: engine.swatch_job(self.engine, settings.sample, swatch_path,
                                                       settings.seed))
        self.jobs.append(lambda: engine.surface_job(
            self.engine, base_path, swatch_path, self.result_path, settings.scale,
            seed=settings.seed, stretch=settings.stretch, field=field, field_file=field_file,
            save_quilt=self.quilt_path))
        self.total = len(self.jobs)
        self.job = None
        self.state = "running"
        self.error = ""
        self.result = None

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

    def step(self):
        """Advances the run; returns its state ("running", "done", "failed", "cancelled")."""
        if self.state != "running":
            return self.state
        if self.job is None:
            self.job = self.jobs.pop(0)()
        state = self.job.poll()
        if state == "failed":
            self.state, self.error = "failed", self.job.error
        elif state == "cancelled":
            self.state = "cancelled"
        elif state == "done":
            self.job = None
            if not self.jobs:
                self.state = "done"
        return self.state

    def fraction(self):
        done = self.total - len(self.jobs) - (1 if self.job else 0)
        part = self.job.fraction if self.job else 0.0
        return min(1.0, (done + part) / self.total)

    def status_text(self):
        return self.job.status_text() if self.job else "meshquilt: starting"

    def cancel(self):
        if self.job is not None:
            self.job.cancel()
        self.state = "cancelled"
        self.cleanup()

    def import_result(self, context):
        result = exchange.read_ply(self.result_path)
        name = "%s_quilt" % self.base.name
        # The swatch's own materials for its kinds (the engine's names replace spaces).
        me = exchange.build_mesh(bpy, name, result, lambda kind, look: material_for(
            self.material_names.get(kind, kind), look))
        obj = bpy.data.objects.new(name, me)
        collection = self.base.users_collection[0] if self.base.users_collection else \
            context.scene.collection
        collection.objects.link(obj)
        # The result is in world coordinates: parented without moving.
        obj.parent = self.base
        obj.matrix_parent_inverse = self.base.matrix_world.inverted()
        if self.quilt_path and os.path.exists(self.quilt_path):
            follow.bind(obj, self.base, self.quilt_path, self.topology["T"],
                        self.topology["loops"], self.topology["totals"], self.base_matrix)
        self.result = obj
        return obj

    def cleanup(self):
        shutil.rmtree(self.dir, ignore_errors=True)


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
        if bsdf is not None:
            bsdf.inputs["Base Color"].default_value = (r, g, b, 1.0)
            bsdf.inputs["Metallic"].default_value = metallic
            bsdf.inputs["Roughness"].default_value = roughness
    return material


class MESHQUILT_OT_run(bpy.types.Operator):
    """Quilt the swatch over the base in the background"""
    bl_idname = "meshquilt.run"
    bl_label = "Run"
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
            self.report({"INFO"}, "meshquilt: %s, %d faces" % (obj.name, len(obj.data.polygons)))
            return {"FINISHED"}
        run.cleanup()
        if run.state == "failed":
            self.report({"ERROR"}, run.error)
        else:
            self.report({"WARNING"}, "meshquilt: cancelled")
        return {"CANCELLED"}

    def _start(self, context):
        try:
            return Run(context, context.scene.meshquilt)
        except (engine.EngineError, OSError, ValueError) as e:
            self.report({"ERROR"}, str(e))
            return None

    def execute(self, context):
        # Blocking, for scripts: bpy.ops.meshquilt.run().
        import time
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
        run = self._start(context)
        if run is None:
            return {"CANCELLED"}
        _running["run"] = run
        wm = context.window_manager
        self._timer = wm.event_timer_add(0.1, window=context.window)
        wm.progress_begin(0, 100)
        wm.modal_handler_add(self)
        return {"RUNNING_MODAL"}

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
        finally:
            if editing:
                bpy.ops.object.mode_set(mode="EDIT")
        self.report({"INFO"}, "meshquilt: %d elements removed from %s" % (len(chosen), obj.name))
        return {"FINISHED"}


class MESHQUILT_PT_panel(bpy.types.Panel):
    bl_label = "meshquilt"
    bl_idname = "MESHQUILT_PT_panel"
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "meshquilt"

    def draw(self, context):
        s = context.scene.meshquilt
        layout = self.layout
        layout.prop(s, "base")
        layout.prop(s, "swatch_source", expand=True)
        layout.prop(s, "swatch" if s.swatch_source == "OBJECT" else "sample")
        layout.prop(s, "scale")
        layout.prop(s, "guidance")
        if s.guidance == "AXIS":
            row = layout.row()
            row.prop(s, "guide_object")
            row.prop(s, "guide_axis", text="")
        elif s.guidance == "ATTRIBUTE":
            layout.prop(s, "guide_attribute")
        layout.prop(s, "stretch")
        layout.prop(s, "seed")
        if "run" in _running:
            run = _running["run"]
            layout.label(text=run.status_text())
            layout.operator("meshquilt.cancel", icon="CANCEL")
        else:
            layout.operator("meshquilt.run", icon="PLAY")
        obj = context.active_object
        if obj is not None and obj.type == "MESH" and "element_id" in obj.data.attributes:
            layout.operator("meshquilt.select_element")
            b = obj.meshquilt
            box = layout.box()
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
            box.operator("meshquilt.remove_selected", icon="TRASH")
            if b.status:
                box.label(text=b.status, icon="ERROR")


classes = (MeshquiltPreferences, MeshquiltSettings, MeshquiltBinding, MESHQUILT_OT_run,
           MESHQUILT_OT_cancel, MESHQUILT_OT_select_element, MESHQUILT_OT_bake,
           MESHQUILT_OT_clear_bake, MESHQUILT_OT_remove_selected, MESHQUILT_PT_panel)


def register():
    for c in classes:
        bpy.utils.register_class(c)
    bpy.types.Scene.meshquilt = bpy.props.PointerProperty(type=MeshquiltSettings)
    bpy.types.Object.meshquilt = bpy.props.PointerProperty(type=MeshquiltBinding)
    follow.register()


def unregister():
    run = _running.pop("run", None)
    if run is not None:
        run.cancel()
    follow.unregister()
    del bpy.types.Object.meshquilt
    del bpy.types.Scene.meshquilt
    for c in reversed(classes):
        bpy.utils.unregister_class(c)
