#!/usr/bin/env bash
# Ground truth for the xacro expander (docs/xacro.md): every xacro of the shared corpus
# (../shared/xacro-corpus beside the repository) expanded by xacrodoc and by `urdf-inertia xacro`
# and compared element by element; `check`/`fill` of each .xacro against `check`/`fill` of the
# reference expansion; `fill -i` into a temporary copy of each repository, expanded again; and the
# speed of both expanders, whole process against whole process (validation/xacro_compare.py).
# Usage: bash validation/xacro.sh [OUT.md]
#   OUT.md defaults to a file in the work directory, so CI leaves the tree clean.
# Environment: XACRO_VENV (default validation/.venv-xacro), XACRO_WORK (work directory, default a
# new temp dir, removed at the end unless XACRO_KEEP=1), XACRO_CORPUS (default
# ../shared/xacro-corpus beside the repository), XACRO_SPEED_RUNS (default 10; 0 skips the timing),
# XACRO_SPEED_ONLY=1 runs only the timing.
set -euo pipefail
cd "$(dirname "$0")/.."
repo="$(pwd)"
corpus="${XACRO_CORPUS:-$repo/../shared/xacro-corpus}"
if [ ! -d "$corpus" ]; then
  echo "error: the xacro corpus is not at $corpus: it is shared/xacro-corpus beside the repository" \
    "(CI lays shared/ beside the clone); set XACRO_CORPUS=DIR to use another copy" >&2
  exit 1
fi
work="${XACRO_WORK:-$(mktemp -d -t urdf-inertia-xacro.XXXXXX)}"
mkdir -p "$work"
work="$(cd "$work" && pwd)"
out="${1:-$work/XACRO.md}"
venv="${XACRO_VENV:-validation/.venv-xacro}"
# The expansions and temporary copies go; the report stays in the work directory.
cleanup() {
  if [ "${XACRO_KEEP:-0}" != 1 ]; then rm -rf "$work"/case* "$work"/speed-*.urdf; fi
}
trap cleanup EXIT
if [ ! -x "$venv/bin/python" ]; then
  python3 -m venv "$venv"
fi
"$venv/bin/python" -m pip install --quiet --disable-pip-version-check -r validation/xacro-requirements.txt
cargo build --release --quiet
bin="${CARGO_TARGET_DIR:-target}/release/urdf-inertia"
speed_only=()
if [ "${XACRO_SPEED_ONLY:-0}" = 1 ]; then speed_only=(--speed-only); fi
echo "== xacro: corpus $corpus, work directory $work, report $out"
"$venv/bin/python" validation/xacro_compare.py --binary "$bin" --xacrodoc "$venv/bin/xacrodoc" \
  --corpus "$corpus" --work "$work" --out "$out" --speed-runs "${XACRO_SPEED_RUNS:-10}" "${speed_only[@]}"
