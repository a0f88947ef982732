#!/usr/bin/env python3
"""Peers for the accuracy report: coal (pinocchio's collision library) and trimesh on the very meshes the
report integrates. Called by examples/accuracy_report.rs with a directory of cases, each NAME.v (f64
vertices, little-endian) and NAME.f (u32 triangles); prints JSON: per case and tool, the central inertia
(unit density) and the median time of one mass-properties computation."""

import json
import sys
import time
from pathlib import Path

import numpy as np


def median_time(fn, budget=0.3):
    samples = []
    start = time.perf_counter()
    while len(samples) < 3 or (time.perf_counter() - start < budget and len(samples) < 200):
        t = time.perf_counter()
        fn()
        samples.append(time.perf_counter() - t)
    samples.sort()
    return samples[len(samples) // 2]


def main():
    d = Path(sys.argv[1])
    out = []
    tools = {}
    try:
        import coal

        def run_coal(v, f):
            m = coal.BVHModelOBBRSS()
            m.beginModel(len(f), len(v))
            verts = coal.StdVec_Vec3s()
            verts.extend(np.asarray(p, dtype=float) for p in v)
            tris = coal.StdVec_Triangle()
            tris.extend(coal.Triangle(int(a), int(b), int(c)) for a, b, c in f)
            m.addSubModel(verts, tris)
            m.endModel()
            def compute():
                return m.computeVolume(), m.computeCOM(), m.computeMomentofInertiaRelatedToCOM()
            vol, com, inertia = compute()
            return np.asarray(inertia), median_time(compute)

        tools["coal"] = run_coal
    except ImportError:
        pass
    try:
        import trimesh

        def run_trimesh(v, f):
            tri = v[f]
            def compute():
                return trimesh.triangles.mass_properties(tri, density=1.0, skip_inertia=False)
            mp = compute()
            return np.asarray(mp["inertia"]), median_time(compute)

        tools["trimesh"] = run_trimesh
    except ImportError:
        pass
    for vfile in sorted(d.glob("*.v")):
        name = vfile.stem
        v = np.fromfile(vfile, dtype="<f8").reshape(-1, 3)
        f = np.fromfile(d / f"{name}.f", dtype="<u4").reshape(-1, 3).astype(np.int64)
        for tool, fn in tools.items():
            try:
                inertia, secs = fn(v, f)
                out.append({"case": name, "tool": tool, "inertia": inertia.tolist(), "seconds": secs})
            except Exception as e:  # noqa: BLE001 - report any failure as such
                out.append({"case": name, "tool": tool, "error": str(e)})
    versions = {}
    for mod in ("coal", "trimesh"):
        try:
            versions[mod] = __import__(mod).__version__
        except Exception:  # noqa: BLE001
            pass
    print(json.dumps({"versions": versions, "results": out}))


if __name__ == "__main__":
    main()
