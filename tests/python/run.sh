#!/usr/bin/env bash
# The Python client as a user gets it: installed from the checkout into a
# fresh virtual environment over Debian's python3-protobuf (no network), then
# its tests and examples run against real masters and nodes.
#   tests/python/run.sh BIN_DIR
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
bin_dir="$(cd "$1" && pwd)"
scratch="$(mktemp -d -t optique-python-XXXXXX)"
trap 'rm -rf "$scratch"' EXIT
# Debian's interpreter, whose packages (python3-protobuf) the venv sees.
python=/usr/bin/python3
"$python" -m venv --system-site-packages "$scratch/venv"
# A copy of the client, so the build's files stay out of the checkout.
mkdir -p "$scratch/copy/clients" "$scratch/copy/proto"
cp -r "$root/clients/python" "$scratch/copy/clients/"
cp -r "$root/proto/optique" "$scratch/copy/proto/"
"$scratch/venv/bin/pip" install --quiet --no-build-isolation --no-index --no-deps "$scratch/copy/clients/python"
cd "$scratch"
OPTIQUE_BIN_DIR="$bin_dir" OPTIQUE_SOURCE_DIR="$root" "$scratch/venv/bin/python" "$here/test_client.py" -v
