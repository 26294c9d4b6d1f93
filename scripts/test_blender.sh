#!/usr/bin/env bash
# The Blender add-on tested in real Blender, headless (issue 15): installs Blender (Debian's
# package) when missing, zips the add-on and runs tests/blender/test_addon.py against the
# engine of build/ (or $1).
set -euo pipefail
cd "$(dirname "$0")/.."
engine=$(realpath "${1:-build/meshquilt}")
# Blender runs on the system Python; the add-on moves meshes with numpy.
missing=()
for p in blender python3-numpy; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed' || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  SUDO=""
  [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  echo "test_blender: installing ${missing[*]}"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi
bash scripts/blender_addon.sh build/meshquilt_blender.zip
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# The add-on is installed into a throw-away user scripts directory, not the user's own.
export BLENDER_USER_SCRIPTS="$work/scripts" BLENDER_USER_CONFIG="$work/config"
blender -b --factory-startup --python-exit-code 1 --python tests/blender/test_addon.py -- \
  "$engine" "$(realpath build/meshquilt_blender.zip)" "$work/out" 2>&1 |
  grep -E '^\[blender\]|Error|error:|Traceback|File "' || true
# grep hides Blender's own chatter; the exit status is Blender's.
exit "${PIPESTATUS[0]}"
