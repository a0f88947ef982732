#!/usr/bin/env bash
# Every collision mesh of example-robot-data that the health ladder repairs, against libigl's fast winding
# number (validation/winding.py): our volume within our estimate plus 3 sigma of the sampled reference.
# Usage: bash validation/winding.sh [OUT.md]
#   OUT.md defaults to a file in a new temp directory, so CI leaves the tree clean; the figures in
#   docs/accuracy.md ("Open and overlapping meshes") are regenerated on purpose from that report.
# Environment: WINDING_VENV (default validation/.venv-winding), WINDING_POINTS (samples per mesh).
set -euo pipefail
cd "$(dirname "$0")/.."
out="${1:-$(mktemp -d -t urdf-inertia-winding.XXXXXX)/WINDING.md}"
venv="${WINDING_VENV:-validation/.venv-winding}"
if [ ! -x "$venv/bin/python" ]; then
  python3 -m venv "$venv"
fi
"$venv/bin/python" -m pip install --quiet --disable-pip-version-check -r validation/winding-requirements.txt
share="$("$venv/bin/python" -c 'import sysconfig, pathlib; print(pathlib.Path(sysconfig.get_paths()["purelib"]) / "cmeel.prefix" / "share")')"
cargo build --release --quiet
echo "== winding: report $out"
"$venv/bin/python" validation/winding.py --binary "${CARGO_TARGET_DIR:-target}/release/urdf-inertia" --share "$share" --out "$out" \
  ${WINDING_POINTS:+--points "$WINDING_POINTS"}
