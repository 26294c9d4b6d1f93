#!/usr/bin/env bash
# The README's screenshot of the add-on's panel (docs/blender_panel.png): Blender draws its UI
# only with a display, so this runs it under a virtual one (Xvfb, installed when missing; as root).
# Usage: bash scripts/blender_panel_screenshot.sh [ENGINE] [OUT.png]
set -euo pipefail
cd "$(dirname "$0")/.."
engine=$(realpath "${1:-build/meshquilt}")
out=$(realpath -m "${2:-docs/blender_panel.png}")
repo=$PWD
if ! command -v xvfb-run > /dev/null; then
  DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends xvfb xauth
fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# A .blend on the command line keeps the splash screen away.
blender -b --factory-startup --python-expr \
  "import bpy; bpy.ops.wm.save_as_mainfile(filepath='$work/empty.blend')" > /dev/null
(cd "$work" && xvfb-run -s "-screen 0 1600x1000x24" blender --factory-startup \
  --enable-event-simulate "$work/empty.blend" --python "$repo/scripts/blender_panel_screenshot.py" \
  -- "$engine" "$repo/blender" "$out")
