"""A screenshot of the add-on's panel in Blender's UI (README). Blender draws its UI only with a
display, so this runs under a virtual one (scripts/blender_panel_screenshot.sh does all of it):

    xvfb-run -s "-screen 0 1600x1000x24" blender --factory-startup --enable-event-simulate \
        EMPTY.blend --python scripts/blender_panel_screenshot.py -- ENGINE ADDON_DIR OUT.png

(a .blend on the command line keeps the splash screen away; --enable-event-simulate lets the
script click the sidebar's meshquilt tab, which Blender 3.4's Python cannot select).

It enables the add-on from ADDON_DIR (the repository's blender/), quilts the sample chain mail
over a sphere through the add-on's Run, opens the sidebar on the meshquilt tab and saves the
window.
"""

import os
import sys

import bpy

engine_path, addon_dir, out = sys.argv[sys.argv.index("--") + 1:][:3]
sys.path.insert(0, addon_dir)
import meshquilt  # noqa: E402

meshquilt.register()
bpy.context.preferences.addons.new().module = "meshquilt"
bpy.context.preferences.addons["meshquilt"].preferences.engine_path = engine_path

for obj in list(bpy.data.objects):
    bpy.data.objects.remove(obj)
bpy.ops.mesh.primitive_uv_sphere_add(radius=1, segments=48, ring_count=24)
base = bpy.context.active_object
s = bpy.context.scene.meshquilt
s.base, s.sample, s.scale = base, "chainmail", 0.25
bpy.ops.meshquilt.run()
bpy.ops.meshquilt.estimate()  # the size line: faces, memory and time before a run
result = bpy.data.objects[base.name + "_quilt"]
bpy.context.view_layer.objects.active = result
result.select_set(True)


def frame():
    for window in bpy.context.window_manager.windows:
        for area in window.screen.areas:
            if area.type != "VIEW_3D":
                continue
            space = area.spaces[0]
            space.show_region_ui = True
            space.shading.type = "SOLID"
            space.shading.color_type = "MATERIAL"
            region = next(r for r in area.regions if r.type == "WINDOW")
            with bpy.context.temp_override(window=window, area=area, region=region):
                bpy.ops.view3d.view_selected()
    return None


def click_tab():
    # The tab strip is the sidebar's right edge; "meshquilt" is its fourth tab.
    for window in bpy.context.window_manager.windows:
        for area in window.screen.areas:
            if area.type != "VIEW_3D":
                continue
            ui = next(r for r in area.regions if r.type == "UI")
            x = ui.x + ui.width - 10
            y = ui.y + ui.height - int(TAB_OFFSET * bpy.context.preferences.system.ui_scale)
            print("[screenshot] sidebar", ui.x, ui.y, ui.width, ui.height, "click", x, y, flush=True)
            window.event_simulate(type="MOUSEMOVE", value="NOTHING", x=x, y=y)
            window.event_simulate(type="LEFTMOUSE", value="PRESS", x=x, y=y)
            window.event_simulate(type="LEFTMOUSE", value="RELEASE", x=x, y=y)
    return None


TAB_OFFSET = 178


def shoot():
    bpy.ops.screen.screenshot(filepath=os.path.abspath(out))
    print("[screenshot] wrote %s" % out, flush=True)
    bpy.ops.wm.quit_blender()


bpy.app.timers.register(frame, first_interval=1.0)
bpy.app.timers.register(click_tab, first_interval=4.0)
bpy.app.timers.register(click_tab, first_interval=5.0)
bpy.app.timers.register(shoot, first_interval=8.0)
