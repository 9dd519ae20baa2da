#!/usr/bin/env bash
# The picture at the top of the README (docs/picture.jpg): what one run of the
# keystoned three-projector wall writes. Top: the signal each projector is sent
# (its own pixels, keystone undone in advance); below: the wall composed from the
# three by the screen simulator, and the reference a viewer should see (a JPEG:
# as a PNG the smooth shading is 25 times larger).
#
#   scripts/draw-readme-picture.sh [BUILD_DIR]     (needs ImageMagick's montage)
set -euo pipefail
cd "$(dirname "$0")/.."
build_dir="${1:-build}"
command -v montage >/dev/null || { echo "draw-readme-picture: needs ImageMagick (apt-get install imagemagick)" >&2; exit 2; }
config=configs/powerwall-oblique-3.json
frame=60
work="$(mktemp -d /tmp/optique-picture.XXXXXX)"
trap 'rm -rf "$work"' EXIT
"$build_dir/bin/optique-master" --config "$config" --local --frames $((frame + 1)) --capture-every "$frame" \
  --out "$work/out" --no-status >"$work/run.log" 2>&1 || { cat "$work/run.log" >&2; exit 1; }
"$build_dir/bin/optique-master" render-reference --config "$config" --frame "$frame" --supersample 4 \
  --out "$work/out" >>"$work/run.log" 2>&1 || { cat "$work/run.log" >&2; exit 1; }
name=$(printf 'frame-%06d.png' "$frame")
font=(-font DejaVu-Sans -pointsize 15)
montage "${font[@]}" -background white -geometry 416x312+6+6 -tile 3x1 \
  -label 'oblique-left: its signal' "$work/out/nodes/oblique-left/$name" \
  -label 'oblique-centre: its signal' "$work/out/nodes/oblique-centre/$name" \
  -label 'oblique-right: its signal' "$work/out/nodes/oblique-right/$name" \
  "$work/projectors.png"
montage "${font[@]}" -background white -geometry 1260x354+6+6 -tile 1x2 \
  -label 'on the wall: the three composed by the screen simulator (light adds in the overlaps)' \
  "$work/out/screens/front/$name" \
  -label 'the reference: what a viewer at the eye point should see (one render, 4x4 samples per pixel)' \
  "$work/out/reference/front/$name" \
  "$work/wall.png"
convert "$work/projectors.png" "$work/wall.png" -background white -gravity center -append \
  -strip -quality 88 docs/picture.jpg
echo "wrote docs/picture.jpg"
