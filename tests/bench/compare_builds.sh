#!/usr/bin/env bash
# Two builds of optique side by side on one machine, in alternating runs: the
# shared libraries a running master and a null-renderer node have mapped, and
# the barrier (round and present skew, median and p99) with 1 and 8 null-renderer nodes at
# 60 Hz. For a change that should not slow the cluster down, or that claims it
# made it faster.
#
#   tests/bench/compare_builds.sh BIN_A BIN_B [ROUNDS] [FRAMES]
#
# BIN_A, BIN_B: folders with optique-master and optique-node (e.g. a copy of an
# older build/bin, and build/bin). ROUNDS (default 5) runs of each build for each
# node count, A and B alternating; FRAMES per run (default 600). Prints one line
# per run and a summary of medians; writes nothing else (runs in a temp folder).
set -euo pipefail
a="$1"
b="$2"
rounds="${3:-5}"
frames="${4:-600}"
for bin in "$a" "$b"; do
  for exe in optique-master optique-node; do
    [ -x "$bin/$exe" ] || { echo "compare-builds: no $bin/$exe" >&2; exit 2; }
  done
done
work="$(mktemp -d /tmp/optique-compare.XXXXXX)"
trap 'rm -rf "$work"' EXIT

# One wall cut into N strips, one small projector each (as optique-bench-barrier).
config() {
  local n="$1" i
  {
    printf '{"screens": [{"id": "wall", "origin": [-2, 0, 0], "right": [1, 0, 0], "up": [0, 1, 0], '
    printf '"width": 4, "height": 2.25}], "projectors": ['
    for ((i = 0; i < n; i++)); do
      [ "$i" -eq 0 ] || printf ','
      printf '{"id": "n%d", "width": 160, "height": 90, "screen": "wall", "region": {"x": %s, "y": 0, ' "$i" \
        "$(awk -v i="$i" -v n="$n" 'BEGIN { print 4 * i / n }')"
      printf '"width": %s, "height": 2.25}}' "$(awk -v n="$n" 'BEGIN { print 4 / n }')"
    done
    printf '], "viewer": {"eye": [0, 1.6, 2]}, "master": {"frame_rate": 60}, "scene": {"builtin": "cubes"}}\n'
  } >"$work/wall-$n.json"
  echo "$work/wall-$n.json"
}

# Distinct shared objects in /proc/PID/maps.
mapped() { grep -oE '/[^ ]+\.so[.0-9]*$' "/proc/$1/maps" 2>/dev/null | sort -u | wc -l; }

declare -A samples
for n in 1 8; do
  cfg="$(config "$n")"
  for ((r = 0; r < rounds; r++)); do
    for which in A B; do
      bin="$a"
      [ "$which" = B ] && bin="$b"
      out="$work/$which-$n-$r"
      # A run that does not end a minute after its frames is a hang, not a sample.
      timeout --signal=KILL $((frames / 60 + 60)) "$bin/optique-master" --config "$cfg" --local --frames "$frames" \
        --no-status --out "$out" \
        --node-arg=--renderer=null >"$out.log" 2>&1 &
      run=$!
      libs_master=0
      libs_node=0
      for _ in $(seq 1 100); do  # until the frames run, then look at the processes
        sleep 0.1
        if grep -q "starting frames" "$out.log" 2>/dev/null; then
          master=$(pgrep -P "$run" | head -n 1 || true)
          [ -n "$master" ] && libs_master=$(mapped "$master")
          node=$(pgrep -P "${master:-0}" | head -n 1 || true)
          [ -n "$node" ] && libs_node=$(mapped "$node")
          break
        fi
      done
      wait "$run" || { echo "compare-builds: $which run failed, see $out.log" >&2; cat "$out.log" >&2; exit 1; }
      stat() {  # stat SUMMARY QUANTILE: e.g. stat barrier_round_us median
        grep -A6 "\"$1\"" "$out/run.json" | grep -oE "\"$2\": *[0-9.e+-]+" | head -n 1 | sed 's/.*: *//'
      }
      round_median=$(stat barrier_round_us median)
      round_p99=$(stat barrier_round_us p99)
      skew_median=$(stat present_skew_us median)
      skew_p99=$(stat present_skew_us p99)
      printf '%s nodes=%d run=%d  libs master %3d node %3d  round median %7.1f p99 %7.1f µs  skew median %7.1f p99 %7.1f µs\n' \
        "$which" "$n" "$r" "$libs_master" "$libs_node" "$round_median" "$round_p99" "$skew_median" "$skew_p99"
      samples[$which-$n-round-median]+="$round_median "
      samples[$which-$n-round-p99]+="$round_p99 "
      samples[$which-$n-skew-median]+="$skew_median "
      samples[$which-$n-skew-p99]+="$skew_p99 "
      samples[$which-libs]="master $libs_master, null node $libs_node"
    done
  done
done

median() { tr ' ' '\n' | grep -v '^$' | sort -g | awk '{ v[NR] = $1 } END { print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }
echo
echo "shared libraries mapped: A ${samples[A-libs]}; B ${samples[B-libs]}"
for n in 1 8; do
  for metric in round-median round-p99 skew-median skew-p99; do
    ma=$(median <<<"${samples[A-$n-$metric]}")
    mb=$(median <<<"${samples[B-$n-$metric]}")
    printf '%d node(s), %-12s median of %d runs: A %8.1f µs, B %8.1f µs, B/A %.2f\n' "$n" "$metric" "$rounds" \
      "$ma" "$mb" "$(awk -v a="$ma" -v b="$mb" 'BEGIN { print (a > 0) ? b / a : 0 }')"
  done
done
