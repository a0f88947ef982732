#!/usr/bin/env bash
# What a user measures: peak memory (GNU time's maximum resident set size) and time of the whole
# `urdf-inertia mesh FILE` process against the file's size, for one closed torus of about 1.3 M
# triangles written in every format (binary and ASCII STL, OBJ, COLLADA, glTF binary) by
# examples/make_large_inputs.rs into a temp dir. Run on purpose (about a minute on 2 cores), not in
# CI; it leaves the tree clean. The figures in README.md and docs/benchmarks.md come from it.
#
# Usage: bash validation/memory.sh [FACES] [RUNS]          (default: 1300000 faces, 3 runs)
#   URDF_INERTIA_BIN=PATH  the build to measure (default: this checkout's release build)
#   OLD_BIN=PATH           a second build, run interleaved with the first on the same files
#   THREADS="1 2"          RAYON_NUM_THREADS values to run each build with (default: the machine's)
set -euo pipefail
cd "$(dirname "$0")/.."
faces="${1:-1300000}"
runs="${2:-3}"
target="${CARGO_TARGET_DIR:-target}"
cargo build --release --quiet --bin urdf-inertia
cargo build --release --quiet -p urdf-inertia --example make_large_inputs
new="${URDF_INERTIA_BIN:-$target/release/urdf-inertia}"
work="$(mktemp -d /tmp/urdf-inertia-memory.XXXXXX)"
trap 'rm -rf "$work"' EXIT
"$target/release/examples/make_large_inputs" meshes "$work" "$faces" >&2

builds=(new)
if [ -n "${OLD_BIN:-}" ]; then builds+=(old); fi
threads="${THREADS:-default}"

# One run: "peak_kib wall_s cpu_s" of `BIN mesh FILE` with THREADS threads (or the default).
measure() {
  local bin="$1" file="$2" t="$3" log="$work/time.log"
  if [ "$t" = default ]; then
    /usr/bin/time -v "$bin" mesh "$file" >/dev/null 2>"$log"
  else
    RAYON_NUM_THREADS="$t" /usr/bin/time -v "$bin" mesh "$file" >/dev/null 2>"$log"
  fi
  awk -F': ' '
    /Maximum resident set size/ { peak = $2 }
    /User time/ { cpu += $2 }
    /System time/ { cpu += $2 }
    /Elapsed \(wall clock\)/ { n = split($2, p, ":"); wall = 0; for (i = 1; i <= n; i++) wall = wall * 60 + p[i] }
    END { printf "%d %.3f %.3f\n", peak, wall, cpu }' "$log"
}

median() { sort -g | awk '{ v[NR] = $1 } END { print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }

echo "load average before: $(cut -d' ' -f1-3 /proc/loadavg); $(nproc) cores"
echo
echo "| format | file | build | threads | peak memory (median of $runs) | peak / file | wall (median) | CPU (median) |"
echo "| --- | --- | --- | --- | --- | --- | --- | --- |"
for f in torus.stl torus.ascii.stl torus.obj torus.dae torus.glb; do
  size=$(stat -c %s "$work/$f")
  : >"$work/rows"
  # Interleaved: each round runs every build and thread count once, so that a loaded phase of the
  # machine falls on all of them.
  for _ in $(seq "$runs"); do
    for b in "${builds[@]}"; do
      bin="$new"
      if [ "$b" = old ]; then bin="$OLD_BIN"; fi
      for t in $threads; do
        echo "$b $t $(measure "$bin" "$work/$f" "$t")" >>"$work/rows"
      done
    done
  done
  for b in "${builds[@]}"; do
    for t in $threads; do
      sel() { awk -v b="$b" -v t="$t" -v c="$1" '$1 == b && $2 == t { print $c }' "$work/rows" | median; }
      peak=$(sel 3)
      wall=$(sel 4)
      cpu=$(sel 5)
      awk -v f="$f" -v size="$size" -v b="$b" -v t="$t" -v peak="$peak" -v wall="$wall" -v cpu="$cpu" 'BEGIN {
        printf "| %s | %.1f MiB | %s | %s | %.1f MiB | %.2f | %.2f s | %.2f s |\n",
          f, size / 1048576, b, t, peak / 1024, peak * 1024 / size, wall, cpu }'
    done
  done
done
echo
echo "load average after: $(cut -d' ' -f1-3 /proc/loadavg)"
