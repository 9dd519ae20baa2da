#!/usr/bin/env bash
# Installs the dependencies, builds, and runs every test (labels unit, gpu, process, timing).
# This is the README's test command and what CI runs.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
bash scripts/build.sh
build_dir="${OPTIQUE_BUILD_DIR:-build}"
cd "$build_dir"
# Unit tests run in parallel; the others are marked RUN_SERIAL (they start
# processes, draw or time things), so they run one at a time.
ctest --output-on-failure --parallel "$(nproc)" "$@"
