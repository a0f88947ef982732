#!/usr/bin/env python3
"""The winding-number validation (validation/winding.py) on meshes it was not tuned on: the PyPI robot wheels.

Every wheel pinned in validation/corpus-requirements.txt except example-robot-data (validation/winding.sh covers
it), and those of validation/winding-corpus-wheels.txt (packages of meshes that only this validation reads): every (file, scale) a <collision> of the wheel's URDFs uses, `package://` resolved inside the wheel as
validation/corpus.py does, and every mesh file of a meshes-only package at scale 1. Each mesh whose rung is not
exact or welded is measured as winding.py measures it (libigl's fast winding number on the triangles coal reads,
glTF excepted: trimesh reads those, see reference_triangles; stratified sampling in the bounding box; pass: |ours - reference| <= estimate x ours + 3 sigma). Meshes refused
by default (UI108) are measured under `--open-mesh caps` and reported, not failed; meshes urdf-inertia refuses
for another reason (flat, NaN, missing) are listed (validation/corpus.py explains each). Each mesh has its own
random stream (seeded from its name), so the figures do not depend on the order or the number of jobs.

Exits non-zero on a mesh repaired by default that does not pass and is not listed in KNOWN with its reason.
"""

import argparse
import shutil
import sys
import time
import zipfile
import zlib
from collections import defaultdict
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from corpus import Package, collision_meshes, find_wheel, norm, parse_requirements, read_text  # noqa: E402
from winding import POINTS, RESAMPLE, fmt_scale, measure, mesh_rows, triangles  # noqa: E402

# Meshes (package/relative path) whose estimate is known to be below the reference's difference, each with
# the reason. Keep short: every entry is a number printed without an honest bound.
KNOWN = {}

# Covered by validation/winding.sh, with its own mesh list.
SKIP = {"example-robot-data"}


def reference_triangles(path, scale):
    """The reference's triangles: as coal (assimp) reads them, except glTF, which trimesh reads. coal 3.0.3
    indexes the triangles of a glTF mesh's second and later primitives without their vertex offset
    (validation/gltf_coal.py): dexmate's vega_1u `lift_link.glb` comes out with 1,654 of its 3,878 vertices
    used by no triangle. trimesh applies the node transforms as urdf-inertia does (the volumes of the
    wheel's exact glTF meshes agree to the last digit)."""
    if Path(path).suffix.lower() not in (".glb", ".gltf"):
        return triangles(path, scale)
    import trimesh

    mesh = trimesh.load(str(path), force="mesh", process=False)
    v = np.asarray(mesh.vertices, dtype=np.float64) * np.asarray(scale, dtype=np.float64)
    return v, np.asarray(mesh.faces, dtype=np.int64)


def meshes_of(pkg):
    """{(resolved file, scale): path} for every collision mesh of the package's URDFs (meshes-only: every mesh
    file at scale 1)."""
    pairs = {}
    if pkg.meshes_only:
        for p in pkg.mesh_files:
            pairs.setdefault((str(p.resolve()), (1.0, 1.0, 1.0)), p)
        return pairs
    for urdf in pkg.urdfs:
        text = read_text(urdf)
        pkgs = pkg.package_paths(urdf, text)
        for uri, scale in collision_meshes(text):
            path = pkg.resolve(urdf, uri, pkgs)
            if path is not None and path.is_file() and scale is not None:
                pairs.setdefault((str(path.resolve()), scale), path)
    return pairs


def measure_package(args, name, version, meshes_only, work):
    root = work / "extract" / norm(name)
    if root.exists():
        shutil.rmtree(root)
    root.mkdir(parents=True)
    with zipfile.ZipFile(find_wheel(args.wheels, name, version)) as z:
        z.extractall(root)
    pkg = Package(name, version, root, meshes_only)
    pairs = sorted(meshes_of(pkg).items())

    def one(item):
        (key, scale), path = item
        label = pkg.rel(path)
        if args.only and args.only not in label:
            return None
        rng = np.random.default_rng(zlib.crc32(f"{label}{fmt_scale(scale)}".encode()))
        row = measure(args.binary, label, Path(key), scale, rng, args.points, reference_triangles, args.all)
        if row is not None:
            row["package"] = name
            if "error" in row:
                row["error"] = row["error"].replace(str(root) + "/", f"{name}/")
        return row

    with ThreadPoolExecutor(args.jobs) as ex:
        rows = [r for r in ex.map(one, pairs) if r is not None]
    shutil.rmtree(root)
    return len(pairs), rows


def table(packages, rows):
    """The per-package summary lines."""
    lines = [
        "| package | unique meshes | repaired by default | pass | within 1% (+3 sigma) | refused (UI108) | "
        "refused: estimate bounds the difference | other errors |",
        "|---|---|---|---|---|---|---|---|",
    ]
    by_pkg = defaultdict(list)
    for r in rows:
        by_pkg[r["package"]].append(r)
    total = [0] * 7
    for (name, version), count in packages:
        rs = by_pkg[name]
        measured = [r for r in rs if "error" not in r]
        default = [r for r in measured if not r["refused"]]
        refused = [r for r in measured if r["refused"]]
        within = [r for r in default if r["diff"] <= 0.01 * r["ref"] + 3 * r["sigma"]]
        cells = [count, len(default), sum(r["pass"] for r in default), len(within), len(refused),
                 sum(r["pass"] for r in refused), len(rs) - len(measured)]
        total = [a + b for a, b in zip(total, cells)]
        lines.append(f"| {name} {version} | " + " | ".join(str(c) for c in cells) + " |")
    lines.append("| **total** | " + " | ".join(f"**{c}**" for c in total) + " |")
    return lines


def report(packages, rows, points):
    measured = [r for r in rows if "error" not in r]
    failed = [r for r in measured if not r["refused"] and not r["pass"] and r["name"] not in KNOWN]
    lines = [
        "# Open and overlapping meshes of the PyPI robot wheels: urdf-inertia against libigl's winding number",
        "",
        "Generated by `bash validation/winding_corpus.sh`. The wheels of validation/corpus-requirements.txt "
        "except example-robot-data (validation/winding.sh) and of validation/winding-corpus-wheels.txt: every (file, scale) a `<collision>` uses (meshes-only "
        "packages: every mesh file); the rows are the meshes whose rung is not exact or welded, or whose shells were classified (closed, "
        "components that nest or cut each other). Reference: the "
        "volume of {x : |w(x)| >= 1/2}, w libigl's fast winding number on the triangles coal (assimp) reads (glTF: "
        "trimesh's, as coal 3.0.3 misreads several primitives in one mesh; so are OBJ files of several materials), by "
        f"stratified sampling in the bounding box (about {points:,} points per mesh). Pass: |ours - reference| <= "
        f"estimate x ours + 3 sigma, at the first sample or at a second one with {RESAMPLE} times the points. Refused "
        "meshes (UI108) are measured under `--open-mesh caps`.",
        "",
    ]
    lines += table(packages, rows)
    lines += [""] + mesh_rows(
        rows,
        KNOWN,
        "Meshes urdf-inertia refuses for another reason (explained in validation/CORPUS.md; those of "
        "validation/winding-corpus-wheels.txt in docs/accuracy.md)",
        lambda e: " ".join(e.split())[:300],
    )
    seconds = sum(r["seconds"] for r in measured)
    lines += ["", f"Sampling took {seconds:.0f} s in all."]
    return lines, failed


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--binary", required=True)
    ap.add_argument("--wheels", required=True, help="directory of the downloaded wheels")
    ap.add_argument("--requirements", required=True, action="append", help="a file of pinned wheels (repeatable)")
    ap.add_argument("--work", required=True, help="directory to unzip the wheels into (emptied as it goes)")
    ap.add_argument("--out", required=True)
    ap.add_argument("--points", type=int, default=POINTS)
    ap.add_argument("--jobs", type=int, default=1)
    ap.add_argument("--only", default="", help="substring of the mesh paths (package/path) to measure")
    ap.add_argument("--all", action="store_true",
                    help="every mesh, the clean (exact, welded) ones too: a screen for wrong closed meshes, not run by CI")
    args = ap.parse_args()
    args.binary = str(Path(args.binary).resolve())
    work = Path(args.work).resolve()
    start = time.monotonic()
    packages, rows = [], []
    wheels = [w for r in args.requirements for w in parse_requirements(r)]
    for name, version, meshes_only in wheels:
        if name in SKIP:
            continue
        count, rs = measure_package(args, name, version, meshes_only, work)
        print(f"== {name} {version}: {count} collision meshes, {len(rs)} not exact or welded", flush=True)
        packages.append(((name, version), count))
        rows += rs
    lines, failed = report(packages, rows, args.points)
    Path(args.out).write_text("\n".join(lines) + "\n", encoding="utf-8")
    print("\n".join(lines))
    if failed:
        print(f"\nwinding corpus validation FAILED: {len(failed)} estimates below the reference's difference by more "
              "than 3 sigma:", file=sys.stderr)
        for r in failed:
            print(f"  {r['name']}{fmt_scale(r['scale'])}", file=sys.stderr)
        return 1
    print(f"\nwinding corpus validation passed: {len(rows)} meshes ({time.monotonic() - start:.0f} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
