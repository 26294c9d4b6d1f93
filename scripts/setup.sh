#!/usr/bin/env bash
# Fresh Debian 12 machine: installs what is missing, builds in Release, runs the default job.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install_deps.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release
cmake --build build -j"$(nproc)"
mkdir -p out
mq=build/meshquilt
# The default job: a generated 4-in-1 chain mail swatch quilted over a plane, and a picture.
$mq swatch chainmail -o out/chainmail_swatch.obj
$mq info out/chainmail_swatch.obj
$mq plane --swatch out/chainmail_swatch.obj --size 30 30 -o out/chainmail_plane.obj \
  --stats out/chainmail_plane.json
# The structure measure: links per ring against the swatch's, density (issue 13).
$mq info out/chainmail_plane.obj --links --swatch out/chainmail_swatch.obj
$mq render out/chainmail_plane.obj -o out/chainmail_plane.png
# ... and over a shipped base mesh (Keenan Crane's Spot, CC0), through the shell map.
$mq swatch chainmail --rows 3 --cols 3 --detail 16 -o out/chainmail_small.obj
$mq surface --base data/spot_6k.obj --swatch out/chainmail_small.obj --scale 0.08 \
  -o out/spot_chainmail.obj --stats out/spot_chainmail.json
$mq info out/spot_chainmail.obj --links --swatch out/chainmail_small.obj --base data/spot_6k.obj \
  --scale 0.08
$mq render out/spot_chainmail.obj -o out/spot_chainmail.png
# Each ring coloured by its link count (green: 4, as in the swatch), the cow drawn under it.
$mq render out/spot_chainmail.obj --color links --base data/spot_6k.obj -o out/spot_links.png
echo "setup: done; results in out/ (chainmail_plane.*, spot_chainmail.*, spot_links.png)"
