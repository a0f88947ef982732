#!/usr/bin/env python3
"""Every unique collision mesh of example-robot-data: urdf-inertia's reading against coal's (assimp).

For each (file, scale) used by a <collision> in any URDF: `urdf-inertia mesh FILE --scale … --format json`
gives the rung and, for meshes it integrates as they are, the volume and COM; coal.MeshLoader gives its own.
Exact (closed, outward) meshes must agree: volume and COM to 1e-9 relative for STL (float32 by format, read
exactly by both), 1e-6 for OBJ/DAE (assimp keeps their vertices in float32). Writes a Markdown summary with
the rungs per robot and exits non-zero on an exact mesh that disagrees or a mesh that fails to load.
"""

import argparse
import json
import re
import subprocess
import sys
from collections import Counter, defaultdict
from pathlib import Path

import coal
import numpy as np


def collision_meshes(robots, share):
    """(robot, file, scale) for every mesh referenced inside a <collision>."""
    seen = {}
    for urdf in sorted(robots.rglob("*.urdf")):
        robot = urdf.relative_to(robots).parts[0]
        text = re.sub(r"<!--.*?-->", "", urdf.read_text(encoding="utf-8"), flags=re.S)
        for block in re.findall(r"<collision\b.*?</collision>", text, flags=re.S):
            m = re.search(r"<mesh\b([^>]*)/?>", block)
            if not m:
                continue
            attrs = dict(re.findall(r'(\w+)="([^"]*)"', m.group(1)))
            uri = attrs.get("filename", "")
            if uri.startswith("package://"):
                rest = uri[len("package://"):].lstrip("/")
                path = share / rest
            else:
                path = (urdf.parent / uri).resolve()
            scale = attrs.get("scale", "1 1 1").split()
            if len(scale) == 1:
                scale = scale * 3
            key = (str(path), tuple(float(s) for s in scale))
            seen.setdefault(key, robot)
    return [(robot, Path(p), s) for (p, s), robot in seen.items()]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--binary", required=True)
    ap.add_argument("--share", required=True)
    ap.add_argument("--out", required=True)
    args = ap.parse_args()
    share = Path(args.share)
    robots = share / "example-robot-data" / "robots"
    meshes = collision_meshes(robots, share)
    rungs_by_robot = defaultdict(Counter)
    agree = defaultdict(list)
    failures = []
    errors = []
    for robot, path, scale in meshes:
        proc = subprocess.run([args.binary, "mesh", str(path), "--scale", *map(str, scale), "--format", "json", "--digits", "full"], capture_output=True, text=True)
        if proc.returncode != 0 and "error[UI108]" in proc.stderr:
            # An open mesh whose caps cannot be trusted defines no solid: by default an error with
            # its own code (the hull only when asked for), counted here as what it is.
            rungs_by_robot[robot]["no solid (UI108)"] += 1
            continue
        if proc.returncode != 0:
            errors.append(f"{path.relative_to(robots) if path.is_relative_to(robots) else path}: {proc.stderr.strip()}")
            rungs_by_robot[robot]["error"] += 1
            continue
        ours = json.loads(proc.stdout)
        rung = ours["provenance"]
        mirrored = scale[0] * scale[1] * scale[2] < 0
        # A closed mesh whose components nest or cut each other: its shells are classified, so a region
        # two of them enclose counts once, where coal's integral counts it twice; validation/winding.py
        # checks it against libigl's winding number instead.
        classified = any("shells" in m["message"] for m in ours["warnings"] + ours["notes"])
        rungs_by_robot[robot][rung + (" (mirrored)" if mirrored else "") + (" (shells classified)" if classified else "")] += 1
        # Welded meshes are closed once float-noise cracks are welded and are integrated as stored,
        # as coal integrates them: both must agree.
        if rung not in ("exact", "welded") or mirrored or classified:
            continue
        loader = coal.MeshLoader()
        model = loader.load(str(path), np.array(scale, dtype=float))
        vol = model.computeVolume()
        com = np.array(model.computeCOM()).reshape(3)
        dv = abs(ours["volume"] - vol) / abs(vol)
        size = (abs(vol) ** (1 / 3))
        dc = np.linalg.norm(np.array(ours["center_of_mass"]) - com) / size
        fmt = path.suffix.lower()
        tol = 1e-9 if fmt == ".stl" else 1e-6
        if rung == "welded":
            # A surface closed only up to cracks has a volume that depends on the reference point
            # (coal: the origin; ours: the bounding-box centre); our error estimate bounds that.
            tol = max(tol, ours["error_estimate"], ours["error_center_of_mass"] / size)
        agree[fmt].append(max(dv, dc))
        if max(dv, dc) > tol:
            failures.append(f"{path.relative_to(robots)} (scale {scale}): volume {ours['volume']:.12g} vs coal {vol:.12g}, COM differs by {dc:.2e} of the size")
    total = Counter()
    for c in rungs_by_robot.values():
        total.update(c)
    lines = [
        "# Collision meshes of example-robot-data: urdf-inertia against coal",
        "",
        f"Generated by `bash validation/run.sh`. {len(meshes)} unique (file, scale) pairs used by `<collision>` elements. "
        "For meshes urdf-inertia integrates exactly as they are (closed, outward, not mirrored; `exact`, or `welded`: "
        "closed once corners stored a few ulps apart are welded), volume and COM "
        "are compared with coal's `MeshLoader` (assimp): 1e-9 relative for STL, 1e-6 for OBJ/DAE (float32 in assimp), "
        "or for welded meshes our error estimate if larger (their volume moves with the reference point by that much). "
        "Repaired meshes are not compared: coal integrates open or inward surfaces as they are; nor are closed meshes "
        "whose shells were classified (components that nest or cut each other: coal counts a region two of them "
        "enclose twice; validation/winding.py checks them against libigl's winding number). "
        "`no solid (UI108)`: an open mesh whose flat caps cannot be trusted, which `mesh` refuses unless "
        "`--open-mesh caps|hull` is given.",
        "",
        "| format | exact and welded meshes compared | worst relative difference (volume, COM/size) |",
        "|---|---|---|",
    ]
    for fmt, vals in sorted(agree.items()):
        lines.append(f"| {fmt} | {len(vals)} | {max(vals):.1e} |")
    lines += ["", f"Rungs over all pairs: {', '.join(f'{k} {v}' for k, v in sorted(total.items()))}.", "",
              "| robot | rungs |", "|---|---|"]
    for robot, c in sorted(rungs_by_robot.items()):
        lines.append(f"| {robot} | {', '.join(f'{k} {v}' for k, v in sorted(c.items()))} |")
    if errors:
        lines += ["", "## Meshes that fail to load", ""] + [f"- {e}" for e in errors]
    if failures:
        lines += ["", "## Exact meshes that disagree with coal", ""] + [f"- {f}" for f in failures]
    Path(args.out).write_text("\n".join(lines) + "\n", encoding="utf-8")
    print("\n".join(lines))
    if failures or errors:
        print(f"\nmesh validation FAILED: {len(failures)} disagreements, {len(errors)} load errors", file=sys.stderr)
        return 1
    print(f"\nmesh validation passed: {len(meshes)} meshes")
    return 0


if __name__ == "__main__":
    sys.exit(main())
