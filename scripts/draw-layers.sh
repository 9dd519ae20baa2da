#!/usr/bin/env bash
# Redraws the picture of optique's libraries (docs/layers.dot, docs/layers.svg)
# from the layering the build records (build/layers.txt). Run it after changing a
# library's dependencies; the unit test Layers.PictureIsCurrent says when to.
#
#   scripts/draw-layers.sh [BUILD_DIR]
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="${1:-$root/build}"
[ -f "$build/layers.txt" ] || { echo "draw-layers: no $build/layers.txt (configure the build first)" >&2; exit 2; }
command -v dot >/dev/null || apt-get install -y graphviz >/dev/null
python3 "$root/tests/layers/draw_layers.py" "$build/layers.txt" "$root" >"$root/docs/layers.dot"
dot -Tsvg "$root/docs/layers.dot" -o "$root/docs/layers.svg"
echo "wrote docs/layers.dot and docs/layers.svg"
