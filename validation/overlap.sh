#!/usr/bin/env bash
# Whole-process cost of one link made of N overlapping convex pieces (what V-HACD/CoACD give), for
# N = 1, 10, 100, 300, 1000: `urdf-inertia fill pieces_N.urdf --density 1000` on one thread, its
# CPU time, wall time (bash's `time`) and peak memory (GNU time's maximum resident set size). The
# link and its N STL files are written by examples/make_large_inputs.rs into a temp dir. Run on
# purpose (about a minute), not in CI; it leaves the tree clean. The table in docs/benchmarks.md
# comes from it.
#
# Usage: bash validation/overlap.sh [RUNS]                 (default: 5 runs)
#   URDF_INERTIA_BIN=PATH  the build to measure (default: this checkout's release build)
#   OLD_BIN=PATH           a second build (say, main's), run interleaved with the first; the table
#                          then gives the ratio of the medians, this build / OLD_BIN
#   PARTS="1 10 100"       the part counts
#   INSTRUCTIONS=1         also count each build's instructions once per part count under
#                          valgrind's cachegrind: exact and the same however loaded the machine is
set -euo pipefail
cd "$(dirname "$0")/.."
runs="${1:-5}"
target="${CARGO_TARGET_DIR:-target}"
cargo build --release --quiet --bin urdf-inertia
cargo build --release --quiet -p urdf-inertia --example make_large_inputs
new="${URDF_INERTIA_BIN:-$target/release/urdf-inertia}"
work="$(mktemp -d /tmp/urdf-inertia-overlap.XXXXXX)"
trap 'rm -rf "$work"' EXIT

builds=(new)
if [ -n "${OLD_BIN:-}" ]; then builds+=(old); fi

# One run: "cpu_s wall_s peak_kib" of `BIN fill URDF` on one thread: CPU and wall time from bash's
# `time` (milliseconds; GNU time prints CPU time in hundredths of a second), peak memory from GNU
# time (`/usr/bin/time -f %M`, the maximum resident set size), whose own cost is in the CPU time.
measure() {
  local TIMEFORMAT='%3U %3S %3R'
  { time RAYON_NUM_THREADS=1 /usr/bin/time -f '%M' -o "$work/rss" "$1" fill "$2" --density 1000 \
    >/dev/null 2>&1; } 2>"$work/time.log"
  awk -v rss="$(cat "$work/rss")" '{ printf "%.3f %.3f %d\n", $1 + $2, $3, rss }' "$work/time.log"
}

# Instructions executed by `BIN fill URDF` on one thread (cachegrind's "I refs").
instructions() {
  RAYON_NUM_THREADS=1 valgrind --tool=cachegrind --cache-sim=no --cachegrind-out-file=/dev/null \
    "$1" fill "$2" --density 1000 2>&1 >/dev/null | sed -n 's/.*I *refs: *//p' | tr -d ,
}

median() { sort -g | awk '{ v[NR] = $1 } END { print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }

echo "load average before: $(cut -d' ' -f1-3 /proc/loadavg); $(nproc) cores; one thread (RAYON_NUM_THREADS=1)"
echo
if [ "${#builds[@]}" = 2 ]; then
  echo "| parts | CPU, this build | CPU, OLD_BIN | CPU ratio | wall, this build | wall, OLD_BIN | peak memory | overlap estimate (this build) |"
  echo "| --- | --- | --- | --- | --- | --- | --- | --- |"
else
  echo "| parts | CPU | wall | peak memory | overlap estimate |"
  echo "| --- | --- | --- | --- | --- |"
fi
for n in ${PARTS:-1 10 100 300 1000}; do
  "$target/release/examples/make_large_inputs" pieces "$work" "$n"
  urdf="$work/pieces_$n.urdf"
  : >"$work/rows"
  # Interleaved: each round runs every build once, so that a loaded phase falls on all of them.
  for _ in $(seq "$runs"); do
    for b in "${builds[@]}"; do
      bin="$new"
      if [ "$b" = old ]; then bin="$OLD_BIN"; fi
      echo "$b $(measure "$bin" "$urdf")" >>"$work/rows"
    done
  done
  sel() { awk -v b="$1" -v c="$2" '$1 == b { print $c }' "$work/rows" | median; }
  # What the warning says: the excess, its bound and the grid.
  said=$(RAYON_NUM_THREADS=1 "$new" fill "$urdf" --density 1000 2>&1 >/dev/null |
    sed -n 's/.*about \([0-9.e+-]* m³\).*on a \([0-9]*³\) grid.*within \(±[0-9.e+-]* m³\).*/\1 \3, \2 grid/p' | head -1)
  said="${said:-none reported}"
  if [ "${#builds[@]}" = 2 ]; then
    awk -v n="$n" -v c1="$(sel new 2)" -v c0="$(sel old 2)" -v w1="$(sel new 3)" -v w0="$(sel old 3)" \
      -v p="$(sel new 4)" -v s="$said" 'BEGIN {
      printf "| %d | %.1f ms | %.1f ms | %.2f | %.1f ms | %.1f ms | %.1f MiB | %s |\n",
        n, 1000 * c1, 1000 * c0, (c0 > 0 ? c1 / c0 : 0), 1000 * w1, 1000 * w0, p / 1024, s }'
  else
    awk -v n="$n" -v c1="$(sel new 2)" -v w1="$(sel new 3)" -v p="$(sel new 4)" -v s="$said" 'BEGIN {
      printf "| %d | %.1f ms | %.1f ms | %.1f MiB | %s |\n", n, 1000 * c1, 1000 * w1, p / 1024, s }'
  fi
  if [ -n "${INSTRUCTIONS:-}" ]; then
    i1=$(instructions "$new" "$urdf")
    i0=0
    if [ "${#builds[@]}" = 2 ]; then i0=$(instructions "$OLD_BIN" "$urdf"); fi
    echo "$n $i1 $i0" >>"$work/instructions"
  fi
  rm -f "$work"/pieces_"$n"*
done
if [ -s "$work/instructions" ]; then
  echo
  echo "| parts | instructions, this build | instructions, OLD_BIN | ratio |"
  echo "| --- | --- | --- | --- |"
  awk '{ printf "| %d | %.1f M | %.1f M | %s |\n", $1, $2 / 1e6, $3 / 1e6, ($3 > 0 ? sprintf("%.3f", $2 / $3) : "—") }' \
    "$work/instructions"
fi
echo
echo "load average after: $(cut -d' ' -f1-3 /proc/loadavg)"
