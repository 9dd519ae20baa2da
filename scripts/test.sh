#!/usr/bin/env bash
# Installs the dependencies, builds, and runs every test (unit and integration).
# This is the README's test command and what CI runs.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
bash scripts/build.sh
build_dir="${OPTIQUE_BUILD_DIR:-build}"
cd "$build_dir"
# Integration tests start several processes each and time them: run them one at a
# time on this 2-core machine; unit tests in parallel.
ctest --output-on-failure -L unit --parallel "$(nproc)"
ctest --output-on-failure -L integration
