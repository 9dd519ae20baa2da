#!/usr/bin/env bash
# Builds the libFuzzer targets (tests/fuzz) with clang into build-fuzz and runs
# each for a while, starting from a copy of the committed seed corpus.
#
#   scripts/fuzz.sh [SECONDS]      seconds per target (or FUZZ_SECONDS; default 30)
#
# Environment:
#   FUZZ_TARGETS   which targets (default "frames deltas protocol node tracker")
#   FUZZ_JOBS      build parallelism (default: nproc)
#   FUZZ_PARALLEL  targets run at a time, one core each (default: nproc)
#   FUZZ_KEEP=1    keep the work folder (new corpus entries) even when nothing crashed
#
# Installs nothing (scripts/install-deps.sh --fuzz does). On Debian 12 it needs the packages clang and libclang-rt-14-dev
# (libFuzzer and the sanitizer runtimes), and llvm for readable stacks
# (llvm-symbolizer). Exits non-zero if any target crashed, leaked, timed out or ran
# out of memory; the input that did it is copied to build-fuzz/crashes/.
set -euo pipefail
cd "$(dirname "$0")/.."
root="$PWD"

if ! command -v clang >/dev/null 2>&1 || ! command -v clang++ >/dev/null 2>&1; then
  echo "fuzz: clang and clang++ are needed (libFuzzer comes with clang only)." >&2
  echo "fuzz: on Debian 12: scripts/install-deps.sh --fuzz (clang libclang-rt-14-dev llvm)" >&2
  exit 1
fi

seconds="${1:-${FUZZ_SECONDS:-30}}"
if ! [[ "$seconds" =~ ^[0-9]+$ ]] || [ "$seconds" -eq 0 ]; then
  echo "fuzz: seconds per target must be a positive whole number, not '$seconds'" >&2
  exit 2
fi
read -ra targets <<<"${FUZZ_TARGETS:-frames deltas protocol node tracker}"
jobs="${FUZZ_JOBS:-$(nproc)}"
build_dir="$root/build-fuzz"

# clang without its runtime package compiles fine and fails only at the link.
probe_dir="$(mktemp -d)"
trap 'rm -rf "$probe_dir"' EXIT
printf '#include <cstddef>\n#include <cstdint>\nextern "C" int LLVMFuzzerTestOneInput(const std::uint8_t*, std::size_t) { return 0; }\n' \
  >"$probe_dir/probe.cpp"
if ! clang++ -fsanitize=fuzzer,address,undefined "$probe_dir/probe.cpp" -o "$probe_dir/probe" 2>"$probe_dir/err"; then
  echo "fuzz: clang++ cannot link a libFuzzer target:" >&2
  sed 's/^/  /' "$probe_dir/err" >&2
  echo "fuzz: on Debian 12 the runtime is in libclang-rt-14-dev (apt-get install libclang-rt-14-dev)" >&2
  exit 1
fi

# The whole build dir gets coverage instrumentation and the sanitizers, so the
# library under test is instrumented, not just the entry points; asserts stay on.
flags="-fsanitize=fuzzer-no-link,address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer"
generator=()
if command -v ninja >/dev/null 2>&1; then generator=(-G Ninja); fi
t0=$(date +%s)
CC=clang CXX=clang++ cmake -S . -B "$build_dir" "${generator[@]}" \
  -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g" \
  -DCMAKE_CXX_FLAGS="$flags" \
  -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" \
  -DOPTIQUE_FUZZ=ON >/dev/null
cmake --build "$build_dir" --parallel "$jobs" --target "${targets[@]/#/optique-fuzz-}"
t1=$(date +%s)
echo "fuzz: built in $((t1 - t0)) s"

work="$(mktemp -d /tmp/optique-fuzz.XXXXXX)"
export ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=1}"
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}"
# fuzz_one TARGET: runs one target from a copy of its seeds; what it prints
# goes to $work/TARGET/report, its exit status to $work/TARGET/status.
fuzz_one() {
  local t="$1" corpus="$work/$1/corpus" artifacts="$work/$1/artifacts" seeds rc=0
  mkdir -p "$corpus" "$artifacts"
  # A copy: libFuzzer adds to and prunes its first corpus folder.
  cp "$root/tests/fuzz/corpus/$t/"* "$corpus/"
  seeds=$(find "$corpus" -type f | wc -l)
  {
    echo "fuzz: optique-fuzz-$t for ${seconds} s from $seeds seeds (log: $work/$t/log)"
    "$build_dir/bin/optique-fuzz-$t" "$corpus" -max_total_time="$seconds" -timeout=5 -rss_limit_mb=2048 \
      -artifact_prefix="$artifacts/" -print_final_stats=1 >"$work/$t/log" 2>&1 || rc=$?
    grep -E '^(stat::number_of_executed_units|stat::new_units_added|Done [0-9]+ runs)' "$work/$t/log" | sed 's/^/  /' || true
    echo "  corpus: $seeds -> $(find "$corpus" -type f | wc -l) files"
  } >"$work/$t/report"
  echo "$rc" >"$work/$t/status"
}

# Each target is one process on one core: `runs` of them at a time.
runs="${FUZZ_PARALLEL:-$(nproc)}"
if ! [[ "$runs" =~ ^[0-9]+$ ]] || [ "$runs" -eq 0 ]; then runs=1; fi
echo "fuzz: ${#targets[@]} target(s), $runs at a time"
running=0
for t in "${targets[@]}"; do
  if [ "$running" -ge "$runs" ]; then
    wait -n || true
    running=$((running - 1))
  fi
  fuzz_one "$t" &
  running=$((running + 1))
done
wait || true

failed=()
for t in "${targets[@]}"; do
  cat "$work/$t/report" 2>/dev/null || echo "fuzz: optique-fuzz-$t did not run"
  rc=$(cat "$work/$t/status" 2>/dev/null || echo "not run")
  found=("$work/$t/artifacts"/*)
  if [ "$rc" != 0 ] || [ -e "${found[0]}" ]; then
    failed+=("$t")
    echo "fuzz: optique-fuzz-$t FAILED (exit $rc); the end of its log:" >&2
    tail -n 60 "$work/$t/log" 2>/dev/null | sed 's/^/  /' >&2
    mkdir -p "$build_dir/crashes/$t"
    for a in "${found[@]}"; do
      [ -e "$a" ] || continue
      cp "$a" "$build_dir/crashes/$t/"
      echo "fuzz: crash input: $build_dir/crashes/$t/$(basename "$a")" >&2
      echo "fuzz:   replay with: $build_dir/bin/optique-fuzz-$t $build_dir/crashes/$t/$(basename "$a")" >&2
    done
  fi
done

if [ ${#failed[@]} -gt 0 ] || [ "${FUZZ_KEEP:-0}" = 1 ]; then
  echo "fuzz: work folder kept: $work"
else
  rm -rf "$work"
fi
if [ ${#failed[@]} -gt 0 ]; then
  echo "fuzz: failed: ${failed[*]}" >&2
  exit 1
fi
echo "fuzz: no crashes (${targets[*]}, ${seconds} s each)"
