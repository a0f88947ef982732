#!/usr/bin/env bash
# The corpus of real robots from PyPI (validation/corpus-requirements.txt), filled at 1000 kg/m³, every failure
# explained (validation/corpus.py). Downloads the wheels with `pip download --no-deps` into a work directory
# (never into the tree), unzips them there and removes them at the end.
# Usage: bash validation/corpus.sh [OUT.md]
#   OUT.md defaults to a file in the work directory, so CI leaves the tree clean; regenerate the committed
#   report on purpose with `bash validation/corpus.sh validation/CORPUS.md`.
# Environment: CORPUS_WORK (work directory, default a new temp dir), CORPUS_VENV (default
# validation/.venv-corpus), CORPUS_KEEP=1 keeps the unzipped wheels and the filled files for a look.
set -euo pipefail
cd "$(dirname "$0")/.."
work="${CORPUS_WORK:-$(mktemp -d -t urdf-inertia-corpus.XXXXXX)}"
mkdir -p "$work"
work="$(cd "$work" && pwd)"
out="${1:-$work/CORPUS.md}"
venv="${CORPUS_VENV:-validation/.venv-corpus}"
cleanup() {
  if [ "${CORPUS_KEEP:-0}" != 1 ]; then rm -rf "$work/extract" "$work/wheels"; fi
}
trap cleanup EXIT
if [ ! -x "$venv/bin/python" ]; then
  python3 -m venv "$venv"
fi
"$venv/bin/python" -m pip install --quiet --disable-pip-version-check -r validation/corpus-tools-requirements.txt
# --platform/--python-version: pybullet is the one binary wheel; the others are py3-none-any.
"$venv/bin/python" -m pip download --quiet --disable-pip-version-check --no-deps --only-binary=:all: \
  --platform manylinux2014_x86_64 --python-version 3.11 --implementation cp --abi cp311 \
  -d "$work/wheels" -r validation/corpus-requirements.txt
cargo build --release --quiet
echo "== corpus: work directory $work, report $out"
"$venv/bin/python" validation/corpus.py --binary "${CARGO_TARGET_DIR:-target}/release/urdf-inertia" --wheels "$work/wheels" \
  --requirements validation/corpus-requirements.txt --work "$work" --out "$out" --timings "$work/timings.tsv"
