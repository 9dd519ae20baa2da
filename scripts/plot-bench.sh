#!/usr/bin/env bash
# Draws the benchmark plots (DIR/NAME.png) with gnuplot from the CSVs the benches
# wrote (DIR/NAME.csv): tests/bench/plots/series.py takes the medians the tables
# quote, tests/bench/plots/NAME.gp draws them. Every bench runs this for its own
# plot when it finishes; run it by hand to redraw without re-measuring.
#
#   scripts/plot-bench.sh [DIR] [NAME ...]     DIR defaults to docs/bench; NAME to
#                                              every plot whose CSV is in DIR
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
plots="$root/tests/bench/plots"
dir="${1:-$root/docs/bench}"
shift || true
names=("$@")
if [ ${#names[@]} -eq 0 ]; then
  for gp in "$plots"/*.gp; do
    name="$(basename "$gp" .gp)"
    [ "$name" = style ] && continue
    [ -f "$dir/$name.csv" ] && names+=("$name")
  done
  [ ${#names[@]} -gt 0 ] || { echo "plot-bench: no bench CSV in $dir" >&2; exit 2; }
fi
command -v gnuplot >/dev/null || { echo "plot-bench: gnuplot not found (install gnuplot-nox: scripts/install-deps.sh)" >&2; exit 2; }
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
status=0
for name in "${names[@]}"; do
  [ -f "$plots/$name.gp" ] || { echo "plot-bench: no plot named '$name' (tests/bench/plots/$name.gp)" >&2; status=2; continue; }
  [ -f "$dir/$name.csv" ] || { echo "plot-bench: no $dir/$name.csv (run the bench first)" >&2; status=2; continue; }
  python3 "$plots/series.py" "$name" "$dir/$name.csv" "$work/$name.dat" || { status=1; continue; }
  # gnuplot warns on stderr and goes on; a warning here is a broken plot.
  if ! gnuplot -e "dir='$plots'; data='$work/$name.dat'; out='$dir/$name.png'" "$plots/$name.gp" 2>"$work/$name.err" ||
      [ -s "$work/$name.err" ]; then
    echo "plot-bench: gnuplot on $name.gp:" >&2
    cat "$work/$name.err" >&2
    status=1
    continue
  fi
  echo "wrote $dir/$name.png"
done
exit $status
