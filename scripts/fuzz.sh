#!/usr/bin/env bash
# Builds the libFuzzer targets (tests/fuzz) in build-asan, the clang ASan + UBSan
# build scripts/sanitize.sh uses too (scripts/asan-build.sh), and runs each for a
# while, starting from a copy of the committed seed corpus. After
# scripts/sanitize.sh only the targets' own files are left to build.
#
#   scripts/fuzz.sh [SECONDS]      seconds per target (or FUZZ_SECONDS; default 30)
#
# Environment:
#   FUZZ_TARGETS   which targets (default "frames deltas protocol node tracker session")
#   FUZZ_JOBS      build parallelism (default: nproc)
#   FUZZ_PARALLEL  targets run at a time, one core each (default: nproc)
#   FUZZ_KEEP=1    keep the work folder (new corpus entries) even when nothing crashed
#
# Installs nothing (scripts/install-deps.sh --fuzz does). On Debian 12 it needs the packages clang and libclang-rt-14-dev
# (libFuzzer and the sanitizer runtimes), and llvm for readable stacks
# (llvm-symbolizer). Exits non-zero if any target crashed, leaked, timed out or ran
# out of memory; the input that did it is copied to build-asan/crashes/.
set -euo pipefail
cd "$(dirname "$0")/.."
root="$PWD"

# shellcheck source=asan-build.sh
source "$root/scripts/asan-build.sh"
asan_build_check_clang fuzz

seconds="${1:-${FUZZ_SECONDS:-30}}"
if ! [[ "$seconds" =~ ^[0-9]+$ ]] || [ "$seconds" -eq 0 ]; then
  echo "fuzz: seconds per target must be a positive whole number, not '$seconds'" >&2
  exit 2
fi
read -ra targets <<<"${FUZZ_TARGETS:-frames deltas protocol node tracker session}"
jobs="${FUZZ_JOBS:-$(nproc)}"
build_dir="$root/$asan_build_dir"

t0=$(date +%s)
asan_build_configure "$root"
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
