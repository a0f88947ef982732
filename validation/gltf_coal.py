#!/usr/bin/env python3
"""glTF collision meshes: urdf-inertia's reading against coal's (assimp), the loader pinocchio uses.

Generates the fixtures with `cargo run --release --example make_gltf_fixtures -- DIR` (unless --fixtures
is given), then compares `urdf-inertia mesh FILE --format json` with coal.MeshLoader's computeVolume and
computeCOM. assimp keeps positions and node transforms in float32, so agreement is 1e-6 relative (volume)
and 1e-6 of the size (COM). Two differences are expected and checked as such, not hidden:

* mirrored.glb (a node with scale -1): coal keeps the triangles as wound, so its volume is the negative
  of ours; urdf-inertia reverses mirrored triangles to keep the solid outward.
* tree_single_root.glb: coal (like RViz, whose loader it copies) skips the transform of the assimp root
  node for the nodes below it, and assimp makes a glTF scene's single root node the root. coal's result
  then equals ours for child_only.glb (the same tree without its root); tree_two_roots.glb, where an
  empty second root node makes assimp add its own root, agrees with ours.

* strip_fan.glb and two_primitives.glb (several primitives in one glTF mesh, which assimp turns into
  several meshes on one node): coal 3.0.3 indexes the triangles of the second and later meshes of a node
  without their vertex offset, so they land on the first mesh's vertices (checked: some of coal's
  vertices are referenced by no triangle). strip_fan_nodes.glb, the same strip and fans on three nodes,
  agrees with ours, which checks the strip and fan winding against assimp.

standing_y.glb checks the up axis: neither coal nor urdf-inertia turns glTF's +Y into +Z.
Prints a table; exits non-zero on any other disagreement.
"""

import argparse
import json
import subprocess
import sys
import tempfile
from pathlib import Path

import coal
import numpy as np

TOL = 1e-6


def ours(binary, path):
    out = subprocess.run([binary, "mesh", str(path), "--format", "json", "--digits", "full"], capture_output=True, text=True)
    if out.returncode != 0:
        raise RuntimeError(f"{path.name}: urdf-inertia failed: {out.stderr.strip()}")
    j = json.loads(out.stdout)
    return j["volume"], np.array(j["center_of_mass"]), j["provenance"]


def theirs(path):
    model = coal.MeshLoader().load(str(path))
    return model.computeVolume(), np.array(model.computeCOM()).reshape(3)


def unreferenced_vertices(path):
    """Vertices of coal's model that no triangle uses: the symptom of its per-node offset slip."""
    model = coal.MeshLoader().load(str(path))
    used = {int(i) for k in range(model.num_tris) for i in (lambda t: (t[0], t[1], t[2]))(model.tri_indices(k))}
    return model.num_vertices - len(used)


MULTI_PRIMITIVE = {"strip_fan.glb", "two_primitives.glb"}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--binary", default="target/release/urdf-inertia")
    ap.add_argument("--fixtures", help="directory of fixtures already written by the example")
    args = ap.parse_args()
    tmp = None
    if args.fixtures:
        fx = Path(args.fixtures)
    else:
        tmp = tempfile.TemporaryDirectory()
        fx = Path(tmp.name)
        subprocess.run(["cargo", "run", "--release", "--quiet", "--example", "make_gltf_fixtures", "--", str(fx)], check=True)

    failures = []
    rows = []

    def compare(name, vol, com, ref_vol, ref_com, expect, shown=None):
        size = abs(ref_vol) ** (1 / 3)
        dv = abs(vol - ref_vol) / abs(ref_vol)
        dc = float(np.linalg.norm(com - ref_com)) / size
        ok = dv <= TOL and dc <= TOL
        rows.append(f"| {name} | {vol:.9g} | {ref_vol if shown is None else shown:.9g} | {dv:.1e} | {dc:.1e} | {expect} | {'ok' if ok else 'FAIL'} |")
        if not ok:
            failures.append(f"{name}: volume {vol!r} vs {ref_vol!r}, COM {com} vs {ref_com}")

    files = sorted(p for p in fx.iterdir() if p.suffix in (".glb", ".gltf"))
    for p in files:
        v, c, rung = ours(args.binary, p)
        cv, cc = theirs(p)
        if rung != "exact":
            failures.append(f"{p.name}: urdf-inertia rung {rung}, expected exact")
        if p.name == "mirrored.glb":
            compare(p.name, v, c, -cv, cc, "coal inside out: its volume negated = ours", shown=cv)
            if cv >= 0:
                failures.append(f"{p.name}: coal's volume {cv} is not negative: the expected difference is gone")
        elif p.name in MULTI_PRIMITIVE:
            lost = unreferenced_vertices(p)
            dv = abs(v - cv) / abs(v)
            rows.append(f"| {p.name} | {v:.9g} | {cv:.9g} | {dv:.1e} | | coal drops the vertex offset of later primitives ({lost} vertices unused) | {'ok' if lost else 'FAIL'} |")
            if lost == 0:
                failures.append(f"{p.name}: coal uses every vertex: its multi-primitive slip is gone; compare this file again")
        elif p.name == "tree_single_root.glb":
            v0, c0, _ = ours(args.binary, fx / "child_only.glb")
            compare(p.name, v0, c0, cv, cc, "coal skips the root: = ours for child_only.glb")
            if np.linalg.norm(c - cc) < 1e-3:
                failures.append(f"{p.name}: coal now applies the root transform; update the README")
        else:
            compare(p.name, v, c, cv, cc, "agree")
        if p.name == "standing_y.glb" and not (abs(c[1] - 1.0) < 1e-12 and abs(cc[1] - 1.0) < 1e-6):
            failures.append(f"{p.name}: the box standing on +Y moved: ours {c}, coal {cc}")

    print(f"glTF fixtures against coal {coal.__version__} (assimp): tolerance {TOL:g}\n")
    print("| file | volume (urdf-inertia) | volume (coal) | volume rel. diff | COM diff / size | expectation | |")
    print("|---|---|---|---|---|---|---|")
    print("\n".join(rows))
    if failures:
        print("\nglTF validation FAILED:\n" + "\n".join(f"- {f}" for f in failures), file=sys.stderr)
        return 1
    print(f"\nglTF validation passed: {len(files)} files")
    return 0


if __name__ == "__main__":
    sys.exit(main())
