#!/usr/bin/env bash
# Re-renders the README's gallery into docs/ and prints each job's structure figures (the
# captions quote them). Needs a Release build (bash scripts/setup.sh) and ../shared/data.
#   bash scripts/gallery.sh [WORKDIR]      (default WORKDIR: out/gallery)
set -euo pipefail
cd "$(dirname "$0")/.."
mq=build/meshquilt
data=../shared/data/base
work=${1:-out/gallery}
mkdir -p "$work" docs

# job NAME BASE SCALE SWATCH_ARGS...: the swatch, the quilt with stats, the structure figures.
job() {
  local name=$1 base=$2 scale=$3
  shift 3
  $mq swatch "$@" -o "$work/${name}_swatch.obj" --quiet
  $mq surface --base "$base" --swatch "$work/${name}_swatch.obj" --scale "$scale" \
    -o "$work/$name.obj" --stats "$work/$name.json" --quiet
  echo "== $name: meshquilt swatch $* ; surface --base $base --scale $scale"
  $mq info "$work/$name.obj" --links --intersections --swatch "$work/${name}_swatch.obj" \
    --base "$base" --scale "$scale" | tee "$work/$name.txt"
}

# The planes: the default chain mail sheet and the plain weave over 20 x 20.
for kind in chainmail weave; do
  $mq swatch $kind -o "$work/plane_${kind}_swatch.obj" --quiet
  $mq plane --swatch "$work/plane_${kind}_swatch.obj" --size 20 20 -o "$work/plane_$kind.obj" --quiet
  echo "== plane_$kind: meshquilt swatch $kind ; plane --size 20 20"
  $mq info "$work/plane_$kind.obj" --links --intersections --swatch "$work/plane_${kind}_swatch.obj" \
    | tee "$work/plane_$kind.txt"
  $mq render "$work/plane_$kind.obj" -o "docs/plane_$kind.png" --quiet
done

job spot data/spot_6k.obj 0.08 chainmail --rows 3 --cols 3 --detail 16
job bunny_link $data/bunny_igl_7k.off 0.099 chainmail --rows 2 --cols 4
job armor $data/knight_decimated_1k.off 0.13 chainmail --rows 5 --cols 6
job cup_weave $data/cup_mug_11k.off 0.145 weave --rows 4 --cols 4 --detail 8

$mq render "$work/spot.obj" --color links --base data/spot_6k.obj -o docs/spot_links.png --quiet
$mq render "$work/bunny_link.obj" --color links --base $data/bunny_igl_7k.off \
  -o docs/bunny_link.png --quiet
$mq render "$work/armor.obj" --color links --base $data/knight_decimated_1k.off \
  -o docs/armor_links.png --quiet
# One ring's scale: under one of the knight's arms, where it meets the body (a cone there).
$mq render "$work/armor.obj" --color links --crop 0.39 0.65 0.49 0.07 --azimuth 0 --elevation 20 \
  -o docs/armor_shoulder_crop.png --width 640 --height 480 --quiet
$mq render "$work/cup_weave.obj" --base $data/cup_mug_11k.off --azimuth 120 --elevation 60 \
  -o docs/cup_weave.png --quiet

# The pair: the Spot quilt beside rigid copies of one of its rings scattered at the same count
# (what an instancing tool gives), the same close-up of the flank, coloured by links.
scale=$(python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['swatch_scale'])" \
  "$work/spot.json")
count=$(awk '/^elements:/ {print $2; exit}' "$work/spot.txt")
python3 scripts/scatter_copies.py data/spot_6k.obj "$work/spot_swatch.obj" "$scale" "$count" \
  "$work/spot_scatter.obj" --seed 1
echo "== spot_scatter: $count rigid copies"
$mq info "$work/spot_scatter.obj" --links --intersections --swatch "$work/spot_swatch.obj" \
  --base data/spot_6k.obj --scale 0.08 | tee "$work/spot_scatter.txt"
crop="0.0 0.1 0.0 0.45"
$mq render "$work/spot.obj" --color links --base data/spot_6k.obj --crop $crop \
  -o docs/spot_quilt_crop.png --width 640 --height 480 --quiet
$mq render "$work/spot_scatter.obj" --color links --base data/spot_6k.obj --crop $crop \
  -o docs/spot_scatter_crop.png --width 640 --height 480 --quiet
# Issue 23: bases an artist makes (Blender's primitives, exported by headless Blender: the build's
# blender_bases target) and close-ups at the scale of one element, coloured by shape against the
# swatch (render --color shape: green even, yellow/orange/red larger or stretched, blue smaller,
# magenta degenerate).
cmake --build build --target blender_bases > /dev/null
blender=build/blender_bases
job uv_sphere $blender/uv_sphere_32x16.obj 0.08 chainmail --rows 3 --cols 3 --detail 16
job cube $blender/cube.obj 0.08 chainmail --rows 3 --cols 3 --detail 16
$mq render "$work/uv_sphere.obj" --color shape --swatch "$work/uv_sphere_swatch.obj" \
  --base $blender/uv_sphere_32x16.obj --scale 0.08 -o docs/uv_sphere_shape.png --quiet
# The cube's corner (2, 1, 0.5): rings over both edges and the corner.
$mq render "$work/cube.obj" --color shape --swatch "$work/cube_swatch.obj" \
  --base $blender/cube.obj --scale 0.08 --crop 2 1 0.5 0.7 --up z --azimuth 30 --elevation 30 \
  -o docs/cube_corner_shape.png --width 640 --height 480 --quiet
# Spot's left horn (narrower than a ring).
$mq render "$work/spot.obj" --color shape --swatch "$work/spot_swatch.obj" --base data/spot_6k.obj \
  --scale 0.08 --crop 0.12 0.88 -0.26 0.25 --azimuth 60 --elevation 20 \
  -o docs/spot_horn_shape.png --width 640 --height 480 --quiet
# A thread crossing the cup, from the side.
$mq render "$work/cup_weave.obj" --base $data/cup_mug_11k.off --crop 0 -10.9 3 5 --azimuth 0 \
  --elevation 10 -o docs/cup_thread_crop.png --width 640 --height 480 --quiet
# The ivy wall (vines grown along the field).
$mq swatch ivy --count 2 --length 2 -o "$work/ivy_swatch.obj" --quiet
$mq surface --base $data/ivy_brick_wall_84.obj --swatch "$work/ivy_swatch.obj" --scale 0.016 \
  -o "$work/ivy_wall.obj" --stats "$work/ivy_wall.json" --quiet
echo "== ivy_wall: meshquilt swatch ivy --count 2 --length 2 ; surface --base $data/ivy_brick_wall_84.obj --scale 0.016"
$mq info "$work/ivy_wall.obj" --links --intersections --swatch "$work/ivy_swatch.obj" \
  --base $data/ivy_brick_wall_84.obj --scale 0.016 | tee "$work/ivy_wall.txt"
$mq render "$work/ivy_wall.obj" -o docs/ivy_wall.png --quiet
echo "gallery: pictures in docs/, meshes and figures in $work/"
