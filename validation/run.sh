#!/usr/bin/env bash
# Validation against pinocchio on every robot of example-robot-data (downloaded from PyPI, not committed).
# Usage: bash validation/run.sh [OUT.md]   (default: validation/RESULTS.md)
set -euo pipefail
cd "$(dirname "$0")/.."
out="${1:-validation/RESULTS.md}"
venv="${VALIDATION_VENV:-validation/.venv}"
if [ ! -x "$venv/bin/python" ]; then
  python3 -m venv "$venv"
fi
"$venv/bin/python" -m pip install --quiet --disable-pip-version-check -r validation/requirements.txt
share="$("$venv/bin/python" -c 'import sysconfig, pathlib; print(pathlib.Path(sysconfig.get_paths()["purelib"]) / "cmeel.prefix" / "share")')"
cargo build --release --quiet
"$venv/bin/python" validation/meshes.py --binary "${CARGO_TARGET_DIR:-target}/release/urdf-inertia" --share "$share" --out "$(dirname "$out")/MESHES.md"
"$venv/bin/python" validation/gltf_coal.py --binary "${CARGO_TARGET_DIR:-target}/release/urdf-inertia"
"$venv/bin/python" validation/validate.py --binary "${CARGO_TARGET_DIR:-target}/release/urdf-inertia" --share "$share" --out "$out" --work validation/work
