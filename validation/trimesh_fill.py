#!/usr/bin/env python3
"""A URDF inertia filler built on trimesh, the baseline of the accuracy report's section 6.

It does what `urdf-inertia fill --density RHO` does, the way a Python user would write it: parse the URDF
(xml.etree), resolve `package://` against a share directory, load every collision mesh with trimesh (its
`scale` applied, then its `<origin>`), take boxes, cylinders (along Z) and spheres analytically, compute
volume, centre of mass and inertia of each part at the density, sum them per link (parallel-axis) and
write the link's `<inertial>`. It does not heal meshes (no welding of cracks, caps or hulls): open or
inward-wound meshes give whatever trimesh's signed integrals give.

Usage: trimesh_fill.py --share SHARE [--density 1000] [--out DIR] [--shared-cache] [URDF ...]
  SHARE is the `cmeel.prefix/share` directory of example-robot-data; without URDFs, every `.urdf` under
  SHARE/example-robot-data/robots is filled. Each URDF gets a fresh mesh cache (as one `urdf-inertia fill`
  process per URDF has), or with --shared-cache one cache for all (as one `urdf-inertia fill -i` of all
  URDFs has), in one Python process (imports paid once). Prints JSON: seconds for all URDFs
  (parsing, loading, mass properties, writing), counts and failures.
Pinned in validation/trimesh-requirements.txt.
"""

import argparse
import json
import math
import sys
import time
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import trimesh


def floats(text, default):
    return [float(x) for x in text.split()] if text else list(default)


def rotation(rpy):
    """URDF rpy: fixed axes X, then Y, then Z: R = Rz(yaw) Ry(pitch) Rx(roll)."""
    r, p, y = rpy
    cr, sr, cp, sp, cy, sy = math.cos(r), math.sin(r), math.cos(p), math.sin(p), math.cos(y), math.sin(y)
    return np.array([
        [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
        [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
        [-sp, cp * sr, cp * cr],
    ])


def resolve(filename, urdf, share):
    if filename.startswith("package://"):
        rest = filename[len("package://"):].lstrip("/")
        return share / rest
    if filename.startswith("file://"):
        return Path(filename[len("file://"):])
    p = Path(filename)
    return p if p.is_absolute() else urdf.parent / p


def mesh_part(path, scale, density, cache):
    """Mass, centre of mass and inertia about it (mesh frame) of a mesh file at `scale`."""
    key = (path, tuple(scale))
    if key not in cache:
        mesh = cache.get(path)
        if mesh is None:
            mesh = trimesh.load(str(path), force="mesh")
            cache[path] = mesh
        scaled = mesh.copy()
        # apply_transform reverses the faces when the scale mirrors the mesh.
        scaled.apply_transform(np.diag(list(scale) + [1.0]))
        scaled.density = density
        mp = scaled.mass_properties
        cache[key] = (float(mp["mass"]), np.asarray(mp["center_mass"]), np.asarray(mp["inertia"]))
    return cache[key]


def primitive_part(geometry, density):
    kind = geometry.tag
    if kind == "box":
        a, b, c = floats(geometry.get("size"), (0, 0, 0))
        m = density * a * b * c
        return m, np.zeros(3), np.diag([m * (b * b + c * c), m * (a * a + c * c), m * (a * a + b * b)]) / 12
    if kind == "cylinder":
        r, length = float(geometry.get("radius")), float(geometry.get("length"))
        m = density * math.pi * r * r * length
        side = m * (3 * r * r + length * length) / 12
        return m, np.zeros(3), np.diag([side, side, m * r * r / 2])
    if kind == "sphere":
        r = float(geometry.get("radius"))
        m = density * 4 / 3 * math.pi * r ** 3
        return m, np.zeros(3), np.eye(3) * 0.4 * m * r * r
    raise ValueError(f"unsupported geometry <{kind}>")


def link_body(link, urdf, share, density, cache, failures):
    parts = []
    for collision in link.findall("collision"):
        geometry = collision.find("geometry")
        shape = None if geometry is None else next(iter(geometry), None)
        if shape is None:
            continue
        try:
            if shape.tag == "mesh":
                path = resolve(shape.get("filename"), urdf, share)
                m, c, inertia = mesh_part(path, floats(shape.get("scale"), (1, 1, 1)), density, cache)
            else:
                m, c, inertia = primitive_part(shape, density)
        except Exception as e:  # noqa: BLE001 - one bad part is reported, the others are filled
            failures.append(f"{urdf.name}: link {link.get('name')}: {type(e).__name__}: {e}")
            continue
        origin = collision.find("origin")
        xyz = floats(origin.get("xyz") if origin is not None else None, (0, 0, 0))
        rpy = floats(origin.get("rpy") if origin is not None else None, (0, 0, 0))
        rot = rotation(rpy)
        parts.append((m, rot @ c + np.asarray(xyz), rot @ inertia @ rot.T))
    if not parts:
        return None
    mass = sum(p[0] for p in parts)
    com = sum(p[0] * p[1] for p in parts) / mass
    inertia = np.zeros((3, 3))
    for m, c, i in parts:
        d = c - com
        inertia += i + m * (d @ d * np.eye(3) - np.outer(d, d))
    return mass, com, inertia


def fill(urdf, share, density, out, failures, cache):
    tree = ET.parse(urdf)
    links = 0
    for link in tree.getroot().findall("link"):
        body = link_body(link, urdf, share, density, cache, failures)
        if body is None:
            continue
        links += 1
        mass, com, inertia = body
        for old in link.findall("inertial"):
            link.remove(old)
        inertial = ET.Element("inertial")
        ET.SubElement(inertial, "origin", xyz=" ".join(repr(float(x)) for x in com), rpy="0 0 0")
        ET.SubElement(inertial, "mass", value=repr(float(mass)))
        names = {"ixx": (0, 0), "ixy": (0, 1), "ixz": (0, 2), "iyy": (1, 1), "iyz": (1, 2), "izz": (2, 2)}
        ET.SubElement(inertial, "inertia", {k: repr(float(inertia[i][j])) for k, (i, j) in names.items()})
        link.insert(0, inertial)
    text = ET.tostring(tree.getroot(), encoding="unicode")
    if out is not None:
        (out / (str(urdf).replace("/", "__") + ".urdf")).write_text(text, encoding="utf-8")
    return links, len([k for k in cache if isinstance(k, Path)])


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--share", type=Path, required=True)
    ap.add_argument("--density", type=float, default=1000.0)
    ap.add_argument("--out", type=Path)
    ap.add_argument("--shared-cache", action="store_true",
                    help="one mesh cache for all URDFs (as `urdf-inertia fill -i a.urdf b.urdf ...` has)")
    ap.add_argument("urdfs", nargs="*", type=Path)
    args = ap.parse_args()
    urdfs = args.urdfs or sorted((args.share / "example-robot-data" / "robots").rglob("*.urdf"))
    if args.out is not None:
        args.out.mkdir(parents=True, exist_ok=True)
    failures = []
    links = meshes = 0
    t0 = time.perf_counter()
    shared = {}
    for urdf in urdfs:
        try:
            cache = shared if args.shared_cache else {}
            n, files = fill(urdf, args.share, args.density, args.out, failures, cache)
            links += n
            meshes += files
        except Exception as e:  # noqa: BLE001 - a URDF that does not parse is reported
            failures.append(f"{urdf.name}: {type(e).__name__}: {e}")
    seconds = time.perf_counter() - t0
    if args.shared_cache:
        meshes = len([k for k in shared if isinstance(k, Path)])
    json.dump({"seconds": seconds, "urdfs": len(urdfs), "links": links, "mesh_files": meshes,
               "trimesh": trimesh.__version__, "failures": failures}, sys.stdout)
    print()


if __name__ == "__main__":
    main()
