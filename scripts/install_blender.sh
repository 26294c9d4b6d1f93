#!/usr/bin/env bash
# Installs Debian's Blender and python3-numpy when missing: the add-on's tests run in real
# Blender (issue 15), and the tests' artist bases are exported by it (issue 23).
set -euo pipefail
missing=()
for p in blender python3-numpy; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed' || missing+=("$p")
done
[ ${#missing[@]} -eq 0 ] && exit 0
SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"
echo "install_blender: installing ${missing[*]}"
$SUDO apt-get update -qq
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
