#!/usr/bin/env bash
# Installs everything optique needs to build and test, from Debian 12 packages.
#   scripts/install-deps.sh          build and test
#   scripts/install-deps.sh --fuzz   also clang for the sanitizer build and the
#                                    libFuzzer targets (CI)
#   scripts/install-deps.sh --run    only what building and running the programs
#                                    needs (scripts/run-local.sh): no browser,
#                                    Prometheus, virtual display or plotting
# Idempotent: when every package is already installed it changes nothing and
# does not touch the network.
set -euo pipefail

run_packages=(
  build-essential cmake ninja-build pkg-config git
  lld                                # links in a quarter of GNU ld's time (CMakeLists.txt: OPTIQUE_LINK_WITH_LLD)
  libboost-dev                       # Asio (header-only)
  libprotobuf-dev protobuf-compiler  # wire format and config schema
  libspdlog-dev libcli11-dev         # logging, command lines
  nlohmann-json3-dev                 # JSON syntax errors with line and column
  libtinygltf-dev                    # glTF 2.0 scene files
  libdraco-dev                       # Draco-compressed glTF meshes (KHR_draco_mesh_compression)
  libglfw3-dev libglm-dev            # windows on projectors, render math
  libeigen3-dev                      # SVD and least squares for calibration
  libopenimageio-dev openimageio-tools  # image files and operations; oiiotool to inspect them
  libepoxy-dev libegl-dev            # GL/EGL function loading, headless contexts
  libegl-mesa0 libgl1-mesa-dri       # Mesa's EGL and llvmpipe: GL without a GPU
  libgtest-dev libgmock-dev          # tests (configured with the programs)
  libssl-dev                         # SHA-256, HKDF, AES-GCM (libcrypto)
  python3                            # configuring: the tests' layer check, the benches' plot series
)
test_packages=(
  xvfb xauth                         # a virtual display for the window tests
  gnuplot-nox                        # bench plots (scripts/plot-bench.sh)
  chromium fonts-dejavu-core         # the operator's page in a real browser (headless), with a font
  prometheus                         # promtool checks /metrics as a site's Prometheus reads it
  systemd                            # systemd-analyze verifies the service units
  python3-protobuf python3-venv python3-setuptools python3-pip python3-cryptography  # the Python client, installed and run
)
packages=("${run_packages[@]}" "${test_packages[@]}")
case "${1:-}" in
  "") ;;
  --fuzz) packages+=(clang libclang-rt-14-dev llvm) ;;  # libFuzzer and its sanitizer runtimes, llvm-symbolizer for stacks
  --run) packages=("${run_packages[@]}") ;;
  *)
    echo "install-deps: unknown argument '$1' (--fuzz or --run)" >&2
    exit 2
    ;;
esac

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages already installed"
  exit 0
fi

if [ "$(id -u)" -ne 0 ]; then
  echo "install-deps: missing packages: ${missing[*]}" >&2
  echo "install-deps: run this script as root (or with sudo) to install them" >&2
  exit 1
fi

echo "install-deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
apt-get update -qq
apt-get install -y -qq --no-install-recommends "${missing[@]}"
