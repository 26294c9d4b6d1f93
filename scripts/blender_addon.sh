#!/usr/bin/env bash
# Zips the Blender add-on (blender/meshquilt) for Edit > Preferences > Add-ons > Install.
#   bash scripts/blender_addon.sh [OUT.zip]     (default: build/meshquilt_blender.zip)
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-build/meshquilt_blender.zip}
mkdir -p "$(dirname "$out")"
out=$(realpath "$out")
rm -f "$out"
(cd blender && python3 - "$out" <<'PY'
import os, sys, zipfile
# Fixed order and timestamps: the same sources give the same zip.
with zipfile.ZipFile(sys.argv[1], "w", zipfile.ZIP_DEFLATED) as z:
    for root, dirs, files in sorted(os.walk("meshquilt")):
        dirs[:] = sorted(d for d in dirs if d != "__pycache__")
        for f in sorted(files):
            if f.endswith(".py"):
                info = zipfile.ZipInfo(os.path.join(root, f), date_time=(2026, 1, 1, 0, 0, 0))
                info.compress_type = zipfile.ZIP_DEFLATED
                info.external_attr = 0o644 << 16
                z.writestr(info, open(os.path.join(root, f), "rb").read())
PY
)
echo "blender_addon: wrote $out"
