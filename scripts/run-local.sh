#!/usr/bin/env bash
# The main job: installs, builds, and runs a local cluster on loopback (one master,
# one node process per projector) with a default installation, writing its
# outputs to a folder it names.
#   scripts/run-local.sh [CONFIG] [FRAMES] [OUT]
set -euo pipefail
cd "$(dirname "$0")/.."
config="${1:-configs/powerwall-2x2.json}"
frames="${2:-300}"
out="${3:-out/$(basename "$config" .json)}"
bash scripts/install-deps.sh
bash scripts/build.sh
build_dir="${OPTIQUE_BUILD_DIR:-build}"
"$build_dir/bin/optique-master" --config "$config" --local --frames "$frames" --capture-every 60 --out "$out"
"$build_dir/bin/optique-master" render-reference --config "$config" --frame 240 --supersample 4 --out "$out"
echo
echo "outputs in $out/:"
echo "  nodes/<projector>/frame-NNNNNN.png|.exr  what each projector showed (every 60th frame; .exr is linear light)"
echo "  screens/<screen>/frame-NNNNNN.png|.exr  what each screen received from its projectors (composed from the captures)"
echo "  reference/<screen>/frame-000240.png|.exr what a viewer should see on each whole screen at frame 240"
echo "  run.json (sync summary), frames.csv (per frame and node), master.log, logs/"
