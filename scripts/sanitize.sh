#!/usr/bin/env bash
# Builds optique with sanitizers in a build dir of its own and runs the tests.
#
#   scripts/sanitize.sh [address] [ctest args...]   ASan + UBSan, clang -> build-asan
#   scripts/sanitize.sh thread    [ctest args...]   TSan, gcc           -> build-tsan
#
# build-asan is the build scripts/fuzz.sh uses too (scripts/asan-build.sh says
# how and why); it needs clang (scripts/install-deps.sh --fuzz).
#
# Environment:
#   SANITIZE_LABELS   test labels (the test folders), a regex (default 'unit|process|gpu';
#                     under TSan 'unit'). The gpu tests draw with llvmpipe, see
#                     tests/sanitizers/README.md; the timing tests measure time, which
#                     a sanitizer's slowdown fails, not a bug. Unit tests run one
#                     process per test executable (all its cases at once: cheaper
#                     than ctest's one process per case); the other labels run
#                     through ctest.
#   SANITIZE_ALL=1    build every target, not only the tests of those labels and the
#                     binaries they start (slower; the benches never run here)
#   SANITIZE_JOBS     build and ctest parallelism (default: nproc)
#   SANITIZE_EXCLUDE  ctest -E regex of tests not to run (default: none)
#   SANITIZE_SKIP_BUILD  regex of test executables not to build at all (default:
#                     none): those every test of which SANITIZE_EXCLUDE leaves out,
#                     so that their compiling and linking is saved too
#   SANITIZE_PRELOAD_MESA=0  do not keep Mesa's driver loaded (see below); expect
#                     LSan reports from every process that drew with llvmpipe
#
# Every process the tests start (master, node) is built with the same sanitizer
# and writes its reports to BUILD/sanitizer-logs/; any report there fails the run,
# even when the test that started the process passed.
set -euo pipefail
cd "$(dirname "$0")/.."
root="$PWD"

mode=address
case "${1:-}" in
  address | thread)
    mode="$1"
    shift
    ;;
  -h | --help)
    sed -n '2,/^set -euo/{/^#/s/^# \{0,1\}//p}' "$0"
    exit 0
    ;;
esac

if [ "$mode" = address ]; then
  # shellcheck source=asan-build.sh
  source "$root/scripts/asan-build.sh"
  build_dir="$asan_build_dir"
else
  build_dir=build-tsan
  # -O1 -g1 as in scripts/asan-build.sh. gcc 12 warns (-Wtsan) that TSan does
  # not model atomic_thread_fence, which Boost.Asio's handler queue uses;
  # -Werror would stop the build on it. -Wno-maybe-uninitialized: gcc's flow
  # analysis at -O1 under instrumentation reports "may be used uninitialized"
  # for a std::optional's vector that is initialized (fuzz_protocol_bodies.cpp).
  tsan_flags="-fsanitize=thread -Wno-tsan -Wno-maybe-uninitialized"
fi
# Under TSan (5-15x slower) nodes that draw with llvmpipe on 2 cores cannot answer
# within the master's 500 ms frame timeout: only the unit tests by default.
# Under ASan every label but timing: glTF loading, light splits, depth of field
# and oblique rendering run sanitized in-process (gpu) and as nodes (process).
default_labels='unit|process|gpu'
if [ "$mode" = thread ]; then default_labels='unit'; fi
labels="${SANITIZE_LABELS:-$default_labels}"
exclude="${SANITIZE_EXCLUDE:-}"
jobs="${SANITIZE_JOBS:-$(nproc)}"
log_dir="$root/$build_dir/sanitizer-logs"

if [ "$mode" = address ]; then
  asan_build_check_clang sanitize
elif ! command -v gcc >/dev/null 2>&1 || ! command -v g++ >/dev/null 2>&1; then
  echo "sanitize: gcc/g++ not found (scripts/install-deps.sh installs them)" >&2
  exit 1
fi

stamp() { date +%s; }
t0=$(stamp)

if [ "$mode" = address ]; then
  asan_build_configure "$root"
else
  generator=()
  if command -v ninja >/dev/null 2>&1; then generator=(-G Ninja); fi
  CC=gcc CXX=g++ cmake -S . -B "$build_dir" "${generator[@]}" \
    -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1 -fno-omit-frame-pointer" \
    -DCMAKE_CXX_FLAGS="$tsan_flags" \
    -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=thread" \
    -DCMAKE_SHARED_LINKER_FLAGS="-fsanitize=thread" \
    -DOPTIQUE_TEST_COMPILE_OPTIONS=-O0 >/dev/null
fi
t1=$(stamp)

# The test executables whose label matches regex $1, read from the optique_test()
# calls in tests/*/CMakeLists.txt: a test's label is its folder's name, or the
# LABEL it names.
tests_labelled() {
  local file folder
  for file in tests/*/CMakeLists.txt; do
    folder=$(basename "$(dirname "$file")")
    # One awk, no grep: under pipefail a folder without tests (grep finding
    # nothing) would end the loop early.
    awk -v folder="$folder" -v re="^($1)\$" '
      match($0, /optique_test\([A-Za-z0-9_]+/) {
        name = substr($0, RSTART + 13, RLENGTH - 13)
        label = folder
        if (match($0, / LABEL [a-z]+/)) label = substr($0, RSTART + 7, RLENGTH - 7)
        if (label ~ re) print name
      }' "$file"
  done | sort -u
}

# The tests' add_dependencies pull in optique-master and optique-node where they run them.
targets=()
if [ "${SANITIZE_ALL:-0}" != 1 ]; then
  mapfile -t targets < <(tests_labelled "$labels" | { if [ -n "${SANITIZE_SKIP_BUILD:-}" ]; then
    grep -Ev "$SANITIZE_SKIP_BUILD" || true
  else cat; fi; })
  if [ ${#targets[@]} -eq 0 ]; then
    echo "sanitize: no test matches the labels '$labels'" >&2
    exit 1
  fi
  targets+=(optique-master optique-node)
  cmake --build "$build_dir" --parallel "$jobs" --target "${targets[@]}"
else
  cmake --build "$build_dir" --parallel "$jobs"
fi
t2=$(stamp)

rm -rf "$log_dir" "$log_dir.benign"
mkdir -p "$log_dir"
supp="$root/tests/sanitizers"
if [ "$mode" = address ]; then
  # Mesa's llvmpipe keeps 112 bytes reachable from its own globals after compiling
  # a shader; eglTerminate unloads the driver, those globals go, and LSan reports
  # an "Indirect leak ... (<unknown module>)" at exit of every process that drew,
  # which no suppression can match (no module name). Preloading the driver keeps it
  # mapped, so nothing is reported. It costs ~0.1 s per process; the ASan runtime
  # then no longer comes first in the library list, which is harmless here (the
  # driver defines no allocator) but must be told to ASan.
  mesa_driver=""
  for candidate in /usr/lib/*/dri/swrast_dri.so; do
    if [ -f "$candidate" ]; then mesa_driver="$candidate"; fi
  done
  asan_link_order=""
  if [ -n "$mesa_driver" ] && [ "${SANITIZE_PRELOAD_MESA:-1}" = 1 ]; then
    export LD_PRELOAD="$mesa_driver${LD_PRELOAD:+:$LD_PRELOAD}"
    asan_link_order="verify_asan_link_order=0:"
  fi
  export ASAN_OPTIONS="${asan_link_order}detect_leaks=1:halt_on_error=1:strict_init_order=1:check_initialization_order=1:log_path=$log_dir/asan${ASAN_OPTIONS:+:$ASAN_OPTIONS}"
  export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1:log_path=$log_dir/ubsan${UBSAN_OPTIONS:+:$UBSAN_OPTIONS}"
  if [ -f "$supp/lsan.supp" ]; then
    export LSAN_OPTIONS="suppressions=$supp/lsan.supp:print_suppressions=0${LSAN_OPTIONS:+:$LSAN_OPTIONS}"
  fi
else
  # llvmpipe's worker threads synchronize in uninstrumented code: without them
  # TSan has nothing of Mesa's to report, and nodes keep up with the frame rate.
  export LP_NUM_THREADS="${LP_NUM_THREADS:-0}"
  tsan_supp=""
  if [ -f "$supp/tsan.supp" ]; then tsan_supp="suppressions=$supp/tsan.supp:"; fi
  export TSAN_OPTIONS="${tsan_supp}second_deadlock_stack=1:history_size=4:log_path=$log_dir/tsan${TSAN_OPTIONS:+:$TSAN_OPTIONS}"
fi
# Bounds on how late things may happen are loosened by this factor (see
# timing_scale() in tests/support/process.h); what must happen is not.
if [ "$mode" = address ]; then time_scale=4; else time_scale=10; fi
export OPTIQUE_TEST_TIME_SCALE="${OPTIQUE_TEST_TIME_SCALE:-$time_scale}"

status=0
# Unit tests: each executable once, with every case in it, `jobs` at a time.
if [[ unit =~ ^(${labels})$ ]]; then
  unit_logs="$root/$build_dir/unit-logs"
  rm -rf "$unit_logs"
  mkdir -p "$unit_logs"
  mapfile -t unit_tests < <(tests_labelled unit)
  run_unit() {
    local exe
    exe=$(find "$2/tests" -mindepth 2 -maxdepth 2 -type f -executable -name "$1" | head -n 1)
    if [ -z "$exe" ]; then
      echo "sanitize: unit test $1 was not built" >"$3/$1.log"
      return 1
    fi
    # ctest gives every case 60 s; a whole executable gets 10 minutes.
    (cd "$(dirname "$exe")" && timeout -k 10 600 "$exe" --gtest_brief=1) >"$3/$1.log" 2>&1
  }
  export -f run_unit
  failed_units=()
  answered=0
  while read -r result name; do
    answered=$((answered + 1))
    if [ "$result" != 0 ]; then failed_units+=("$name"); fi
  done < <(printf '%s\n' "${unit_tests[@]}" |
    xargs -P "$jobs" -I{} bash -c 'run_unit "$1" "$2" "$3"; echo "$? $1"' _ {} "$root/$build_dir" "$unit_logs")
  echo "sanitize: ${#unit_tests[@]} unit test executables, $((answered - ${#failed_units[@]})) passed"
  if [ "$answered" -ne "${#unit_tests[@]}" ]; then
    echo "sanitize: only $answered of ${#unit_tests[@]} unit test executables reported a result" >&2
    status=1
  fi
  for name in "${failed_units[@]}"; do
    echo "===== unit test $name FAILED; the end of its output:"
    tail -n 40 "$unit_logs/$name.log"
    status=1
  done
fi
other_labels=$(tr '|' '\n' <<<"$labels" | grep -vx unit | paste -sd '|' || true)
if [ -n "$other_labels" ]; then
  exclude_args=()
  if [ -n "$exclude" ]; then exclude_args=(-E "$exclude"); fi
  ctest --test-dir "$build_dir" -L "^(${other_labels})\$" "${exclude_args[@]}" --output-on-failure \
    --parallel "$jobs" "$@" || status=$?
fi
t3=$(stamp)

# LSan's "Unable to get registers from thread N" is no report: a thread being
# created or ending as the exit-time leak check stops the world cannot be read,
# and LSan skips it (LLVM made the line verbose-only for that reason: llvm-project
# pull request 116555). A log holding only such lines is set aside, and said.
for r in "$log_dir"/*; do
  [ -e "$r" ] || continue
  if [ -s "$r" ] && ! grep -qv '^==[0-9]*==Unable to get registers from thread [0-9]*\.$' "$r"; then
    echo "sanitize: $(basename "$r"): LSan could not read a thread that was starting or ending; no report"
    mkdir -p "$log_dir.benign"
    mv "$r" "$log_dir.benign/"
  fi
done
reports=("$log_dir"/*)
if [ -e "${reports[0]}" ]; then
  echo
  echo "sanitize: ${#reports[@]} sanitizer report(s) in $log_dir:"
  for r in "${reports[@]}"; do
    echo "===== $r"
    head -n 80 "$r"
  done
  echo
  echo "sanitize: summary of the reports:"
  grep -h '^SUMMARY' "${reports[@]}" | sed 's/+0x[0-9a-f]*//' | sort | uniq -c || true
  [ "$status" -ne 0 ] || status=1
fi

echo
echo "sanitize ($mode): configure $((t1 - t0)) s, build $((t2 - t1)) s, tests $((t3 - t2)) s" \
  "(load average now: $(cut -d' ' -f1-3 /proc/loadavg))"
exit "$status"
