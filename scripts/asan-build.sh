# Sourced by scripts/sanitize.sh (address) and scripts/fuzz.sh: the one
# ASan + UBSan build both use, with clang, in build-asan. The tests and the
# libFuzzer targets share it, so CI compiles the code under test once for both
# (a separate fuzz build took 315 s of a 2-core machine), and clang compiles it
# under the sanitizers in about two thirds of gcc's time (gltf.cpp 36 -> 26 s,
# master/app/cli.cpp 37 -> 24 s).
#
# Flags, and why:
#  -O1: the sanitizers' own docs recommend it (usable speed, exact stacks);
#       asserts stay on, they are checks too. A test's own file is built at -O0
#       (OPTIQUE_TEST_COMPILE_OPTIONS): still instrumented, in less time (its
#       loops are few; the code under test and tests/support stay at -O1).
#  -g1: reports keep file and line; full -g makes the build much slower.
#  UBSan without its null and alignment checks in general: they instrument every
#       pointer dereference (gltf.cpp 26 -> 33 s); ASan reports a dereference of
#       null as a SEGV with its stack. The code that decodes peer bytes keeps
#       them, with libFuzzer's coverage (OPTIQUE_FUZZ: tests/fuzz/CMakeLists.txt
#       names those libraries).

asan_build_dir=build-asan

# asan_build_check_clang WHO: exits with a message naming the package when clang
# or its sanitizer and libFuzzer runtimes are missing (clang without its runtime
# package compiles fine and fails only at the link).
asan_build_check_clang() {
  local who="$1" probe_dir
  if ! command -v clang >/dev/null 2>&1 || ! command -v clang++ >/dev/null 2>&1; then
    echo "$who: clang and clang++ are needed (the sanitizer build and libFuzzer use clang)." >&2
    echo "$who: on Debian 12: scripts/install-deps.sh --fuzz (clang libclang-rt-14-dev llvm)" >&2
    exit 1
  fi
  probe_dir="$(mktemp -d)"
  printf '#include <cstddef>\n#include <cstdint>\nextern "C" int LLVMFuzzerTestOneInput(const std::uint8_t*, std::size_t) { return 0; }\n' \
    >"$probe_dir/probe.cpp"
  if ! clang++ -fsanitize=fuzzer,address,undefined "$probe_dir/probe.cpp" -o "$probe_dir/probe" 2>"$probe_dir/err"; then
    echo "$who: clang++ cannot link a sanitized libFuzzer program:" >&2
    sed 's/^/  /' "$probe_dir/err" >&2
    echo "$who: on Debian 12 the runtimes are in libclang-rt-14-dev (apt-get install libclang-rt-14-dev)" >&2
    rm -rf "$probe_dir"
    exit 1
  fi
  rm -rf "$probe_dir"
}

# asan_build_configure ROOT: configures ROOT/build-asan (quietly). A build-asan
# left by an older script with another compiler is removed first: CMake cannot
# change the compiler of a configured build.
asan_build_configure() {
  local root="$1" dir="$1/$asan_build_dir" cached
  if [ -f "$dir/CMakeCache.txt" ]; then
    cached=$(sed -n 's/^CMAKE_CXX_COMPILER:[A-Z]*=//p' "$dir/CMakeCache.txt")
    if [ -n "$cached" ] && [ "$(basename "$cached")" != clang++ ]; then
      echo "asan-build: $asan_build_dir was configured with $cached; removing it for a clang build" >&2
      rm -rf "$dir"
    fi
  fi
  local sanitize="-fsanitize=address,undefined -fno-sanitize=null,alignment -fno-sanitize-recover=undefined"
  local generator=()
  if command -v ninja >/dev/null 2>&1; then generator=(-G Ninja); fi
  CC=clang CXX=clang++ cmake -S "$root" -B "$dir" "${generator[@]}" \
    -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1 -fno-omit-frame-pointer" \
    -DCMAKE_CXX_FLAGS="$sanitize" \
    -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" \
    -DCMAKE_SHARED_LINKER_FLAGS="-fsanitize=address,undefined" \
    -DOPTIQUE_TEST_COMPILE_OPTIONS=-O0 \
    -DOPTIQUE_FUZZ=ON >/dev/null
}
