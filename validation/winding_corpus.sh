#!/usr/bin/env bash
# The winding-number validation on meshes it was not tuned on: every collision mesh of the PyPI robot wheels
# pinned in validation/corpus-requirements.txt (example-robot-data aside: validation/winding.sh) and every
# mesh of the packages of validation/winding-corpus-wheels.txt that the
# health ladder repairs, against libigl's fast winding number (validation/winding_corpus.py). .ci/run runs
# it with WINDING_JOBS=2: about 1,250 rows (docs/accuracy.md, "Open and overlapping meshes", gives its cost).
# Usage: bash validation/winding_corpus.sh [OUT.md]
#   OUT.md defaults to a file in the work directory, so the tree stays clean; the figures in docs/accuracy.md
#   are regenerated on purpose from that report.
# Environment: WINDING_WORK (work directory, default a new temp dir; the wheels are downloaded there and
# removed at the end), WINDING_VENV (default validation/.venv-winding, which winding.sh shares), WINDING_POINTS (samples per mesh),
# WINDING_JOBS (meshes measured at once, default 1; the figures do not depend on it).
set -euo pipefail
cd "$(dirname "$0")/.."
work="${WINDING_WORK:-$(mktemp -d -t urdf-inertia-winding-corpus.XXXXXX)}"
mkdir -p "$work"
work="$(cd "$work" && pwd)"
out="${1:-$work/WINDING-CORPUS.md}"
venv="${WINDING_VENV:-validation/.venv-winding}"
trap 'rm -rf "$work/extract" "$work/wheels"' EXIT
if [ ! -x "$venv/bin/python" ]; then
  python3 -m venv "$venv"
fi
"$venv/bin/python" -m pip install --quiet --disable-pip-version-check -r validation/winding-corpus-requirements.txt
# --platform/--python-version: pybullet is the one binary wheel; the others are py3-none-any (as corpus.sh).
"$venv/bin/python" -m pip download --quiet --disable-pip-version-check --no-deps --only-binary=:all: \
  --platform manylinux2014_x86_64 --python-version 3.11 --implementation cp --abi cp311 \
  -d "$work/wheels" -r validation/corpus-requirements.txt -r validation/winding-corpus-wheels.txt
cargo build --release --quiet
echo "== winding corpus: work directory $work, report $out"
"$venv/bin/python" validation/winding_corpus.py --binary "${CARGO_TARGET_DIR:-target}/release/urdf-inertia" \
  --wheels "$work/wheels" --requirements validation/corpus-requirements.txt \
  --requirements validation/winding-corpus-wheels.txt --work "$work" --out "$out" \
  ${WINDING_POINTS:+--points "$WINDING_POINTS"} ${WINDING_JOBS:+--jobs "$WINDING_JOBS"}
