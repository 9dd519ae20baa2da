#!/usr/bin/env bash
# Makes the textured torus in configs/assets/torus/ with the tools people export
# glTF with, and validates every shipped glTF asset with the Khronos validator:
#   scripts/make-torus.py        torus.obj + torus.mtl + torus.png (the "modelling tool")
#   obj2gltf -s                  torus.gltf + torus.bin + torus.png (the usual export)
#   obj2gltf                     torus-embedded.gltf (buffers and image as data URIs)
#   obj2gltf -b                  torus.glb
#   gltf-pipeline -d             torus-draco.glb (KHR_draco_mesh_compression)
#   gltf-validator               configs/assets/gltf-validation.jsonl: one line per asset
#                                with its SHA-256 and the validator's counts (a unit test
#                                checks that every shipped asset is listed, unchanged, with
#                                no error)
# Needs node and npm (the npm registry); the tools' versions are pinned here.
# Run it again after changing an asset: scripts/make-gltf-assets.sh
set -euo pipefail
cd "$(dirname "$0")/.."
tools="${OPTIQUE_NPM_TOOLS:-${TMPDIR:-/tmp}/optique-gltf-tools}"
mkdir -p "$tools"
if [ ! -x "$tools/node_modules/.bin/obj2gltf" ] || [ ! -d "$tools/node_modules/gltf-validator" ]; then
  (cd "$tools" && npm init -y >/dev/null &&
    npm install --no-audit --no-fund obj2gltf@3.2.0 gltf-pipeline@4.3.1 gltf-validator@2.0.0-dev.3.10)
fi
bin="$tools/node_modules/.bin"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

python3 scripts/make-torus.py "$work"
out=configs/assets/torus
mkdir -p "$out"
"$bin/obj2gltf" -i "$work/torus.obj" -o "$out/torus.gltf" -s
"$bin/obj2gltf" -i "$work/torus.obj" -o "$out/torus-embedded.gltf"
"$bin/obj2gltf" -i "$work/torus.obj" -o "$out/torus.glb" -b
"$bin/gltf-pipeline" -i "$out/torus.glb" -o "$out/torus-draco.glb" -d

mapfile -t assets < <(find configs/assets -name '*.gltf' -o -name '*.glb' | sort)
GLTF_VALIDATOR="$tools/node_modules/gltf-validator" node scripts/validate-gltf.mjs "${assets[@]}" >"$work/validation.jsonl"
mv "$work/validation.jsonl" configs/assets/gltf-validation.jsonl
cat configs/assets/gltf-validation.jsonl
