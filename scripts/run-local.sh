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
if ! [[ "$frames" =~ ^[0-9]+$ ]] || [ "$frames" -lt 1 ]; then
  echo "run-local: FRAMES must be a whole number of at least 1, not '$frames'" >&2
  exit 2
fi
# Only what the run needs: the programs (not the tests and benches, nor the
# browser and Prometheus that only tests use).
bash scripts/install-deps.sh --run
OPTIQUE_BUILD_TARGETS="optique-master optique-node optique-node-gl optique-tools" bash scripts/build.sh
build_dir="${OPTIQUE_BUILD_DIR:-build}"
every=60
"$build_dir/bin/optique-master" --config "$config" --local --frames "$frames" --capture-every "$every" --out "$out"
# The reference is drawn for the last frame the projectors captured, so that it
# has a composite to be compared with.
last=$(((frames - 1) / every * every))
"$build_dir/bin/optique-master" render-reference --config "$config" --frame "$last" --supersample 4 --out "$out"
echo
echo "outputs in $out/:"
echo "  nodes/<projector>/frame-NNNNNN.png|.exr  what each projector showed (every ${every}th frame; .exr is linear light)"
echo "  screens/<screen>/frame-NNNNNN.png|.exr  what each screen received from its projectors (composed from the captures)"
printf '  reference/<screen>/frame-%06d.png|.exr what a viewer should see on each whole screen at frame %d\n' "$last" "$last"
echo "  run.json (sync summary), frames.csv (per frame and node), master.log, logs/"
