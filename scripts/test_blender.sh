#!/usr/bin/env bash
# The Blender add-on tested in real Blender, headless (issue 15): installs Blender (Debian's
# package) when missing, zips the add-on and runs tests/blender/test_addon.py against the
# engine of build/ (or $1). MESHQUILT_BLENDER_TESTS=word runs only the tests named with it.
set -euo pipefail
cd "$(dirname "$0")/.."
engine=$(realpath "${1:-build/meshquilt}")
bash scripts/install_blender.sh
bash scripts/blender_addon.sh build/meshquilt_blender.zip
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# The add-on is installed into a throw-away user scripts directory, not the user's own.
export BLENDER_USER_SCRIPTS="$work/scripts" BLENDER_USER_CONFIG="$work/config"
# The add-on keeps the quilts of an unsaved file in the temporary directory: this run's go too.
mkdir -p "$work/tmp"
export TMPDIR="$work/tmp"
blender -b --factory-startup --python-exit-code 1 --python tests/blender/test_addon.py -- \
  "$engine" "$(realpath build/meshquilt_blender.zip)" "$work/out" 2>&1 |
  grep -E '^\[blender\]|Error|error:|Traceback|File "' || true
# grep hides Blender's own chatter; the exit status is Blender's.
exit "${PIPESTATUS[0]}"
