#!/usr/bin/env bash
# Configures and builds optique into build/ (or $OPTIQUE_BUILD_DIR): everything,
# or only the targets $OPTIQUE_BUILD_TARGETS names (space-separated).
set -euo pipefail
cd "$(dirname "$0")/.."
build_dir="${OPTIQUE_BUILD_DIR:-build}"
generator=()
if command -v ninja >/dev/null 2>&1; then generator=(-G Ninja); fi
if [ ! -f "$build_dir/CMakeCache.txt" ]; then
  cmake -S . -B "$build_dir" "${generator[@]}" -DCMAKE_BUILD_TYPE="${OPTIQUE_BUILD_TYPE:-RelWithDebInfo}" "$@"
fi
targets=()
if [ -n "${OPTIQUE_BUILD_TARGETS:-}" ]; then
  read -ra names <<<"$OPTIQUE_BUILD_TARGETS"
  if [ ${#names[@]} -gt 0 ]; then targets=(--target "${names[@]}"); fi
fi
cmake --build "$build_dir" --parallel "$(nproc)" "${targets[@]}"
