#!/usr/bin/env python3
"""Validate urdf-inertia against pinocchio on every robot of example-robot-data.

For every URDF: strip all <inertial>, run `urdf-inertia fill --density RHO`, load the result with
pinocchio, and compare each joint's inertia (pinocchio merges links joined by fixed joints) with an
independent reference: pinocchio's own collision model of the original URDF, each geometry's coal
volume / COM / inertia about the COM at the same density, moved by its placement and summed per joint
(a cylinder with a sphere of its radius on each end as one coal.Capsule, their union).

Joints whose parts are all closed, outward meshes or primitives must agree to 1e-9 (STL, primitives)
or 1e-6 (OBJ/DAE: assimp keeps vertices in float32). Every other joint is reported with the reason our
number differs (a repaired mesh, a mirrored scale coal does not handle, pinocchio's capsule extension).

Writes a Markdown report and exits non-zero if a URDF fails to fill, a filled URDF fails to load, or a
closed-mesh joint disagrees.
"""

import argparse
import json
import os
import re
import subprocess
import sys
import time
from pathlib import Path

import coal
import numpy as np
import pinocchio as pin

try:  # optional: the filled URDFs must also load in MuJoCo and Drake (validation/run.sh installs both)
    import mujoco
    from pydrake.multibody.parsing import Parser
    from pydrake.multibody.plant import MultibodyPlant
    SIMULATORS = True
except ImportError:  # pragma: no cover
    SIMULATORS = False

DENSITY = 1000.0
TOL_STL = 1e-9
TOL_FLOAT32 = 1e-6


def strip_inertials(text):
    text = re.sub(r"[ \t]*<inertial\b[^>]*/>[ \t]*\r?\n?", "", text)
    return re.sub(r"[ \t]*<inertial\b.*?</inertial>[ \t]*\r?\n?", "", text, flags=re.S)


class Body:
    """Mass, COM and central inertia; composed by hand because pin.Inertia refuses the negative volumes
    coal returns for inward-wound or mirrored meshes."""

    def __init__(self, mass, lever, inertia):
        self.mass = float(mass)
        self.lever = np.asarray(lever, dtype=float).reshape(3)
        self.inertia = np.asarray(inertia, dtype=float).reshape(3, 3)

    def __add__(self, o):
        m = self.mass + o.mass
        c = (self.mass * self.lever + o.mass * o.lever) / m
        def shift(b):
            d = b.lever - c
            return b.inertia + b.mass * (d @ d * np.eye(3) - np.outer(d, d))
        return Body(m, c, shift(self) + shift(o))


def rel_inertia_diff(a, b):
    """Relative differences (mass, COM, central inertia) of two bodies."""
    dm = abs(a.mass - b.mass) / max(abs(b.mass), 1e-300)
    # COM relative to the body's size: its radius of gyration (or the COM's own distance if larger).
    gyr = np.sqrt(abs(np.trace(b.inertia)) / max(abs(b.mass), 1e-300))
    dc = np.linalg.norm(a.lever - b.lever) / max(gyr, np.linalg.norm(b.lever), 1e-300)
    di = np.linalg.norm(a.inertia - b.inertia) / max(np.linalg.norm(b.inertia), 1e-300)
    return dm, dc, di


def capsules(objects):
    """The geometry objects with each capsule written as a cylinder and a sphere of its radius centred
    on each end (example-robot-data's panda_collision.urdf) replaced by one coal.Capsule at the
    cylinder's placement: their union, which urdf-inertia computes (note UI402). A sphere within 1e-9
    of the radius of an end centre (and of the radius) counts; each sphere joins one capsule."""
    objects = list(objects)
    used = set()
    out = []
    for i, go in enumerate(objects):
        g = go.geometry
        if type(g).__name__ != "Cylinder" or i in used:
            continue
        r, h = g.radius, g.halfLength
        ends = []
        for s in (1.0, -1.0):
            e = go.placement.act(np.array([0.0, 0.0, s * h]))
            match = next((j for j, o in enumerate(objects)
                          if j not in used and j != i and o.parentFrame == go.parentFrame
                          and type(o.geometry).__name__ == "Sphere"
                          and np.linalg.norm(o.placement.translation - e) + abs(o.geometry.radius - r) <= 1e-9 * r),
                         None)
            if match is None:
                break
            used.add(match)
            ends.append(match)
        if len(ends) == 2:
            used.add(i)
            out.append((go, coal.Capsule(r, 2 * h)))
        else:
            used.difference_update(ends)
    return [(go, go.geometry) for i, go in enumerate(objects) if i not in used] + out


def reference_inertias(model, urdf, package_dirs):
    geom = pin.buildGeomFromUrdf(model, str(urdf), pin.GeometryType.COLLISION, package_dirs=package_dirs)
    per_joint = {}
    for go, g in capsules(geom.geometryObjects):
        vol = g.computeVolume()
        com = np.array(g.computeCOM()).reshape(3)
        inertia_com = np.array(g.computeMomentofInertiaRelatedToCOM()) * DENSITY
        R = go.placement.rotation
        moved = Body(DENSITY * vol, go.placement.act(com), R @ inertia_com @ R.T)
        j = go.parentJoint
        per_joint[j] = per_joint[j] + moved if j in per_joint else moved
    return per_joint


def without_geometry(text):
    """The URDF with <visual> and <collision> removed: simulators then judge only the inertials."""
    return re.sub(r"<(visual|collision)\b.*?</\1>|<(visual|collision)\b[^>]*/>", "", text, flags=re.S)


def _load(which, path):
    if which == "mujoco":
        mujoco.MjModel.from_xml_path(str(path))
    else:
        _drake_load(path)


def _error(which, path):
    """The loader's message (paths and line numbers removed), or None if it loads."""
    try:
        _load(which, path)
        return None
    except Exception as e:  # noqa: BLE001 - each loader has its own exception types
        msg = " ".join(str(e).split())
        return re.sub(r"\S*\.urdf(:\d+)?:?", "", msg).strip()


def simulator_checks(filled_text, original_text, filled_links, work, stem):
    """Loads the filled robot (without geometry) in MuJoCo and Drake. Returns (mujoco, drake) verdicts:
    "ok"; "explained: …" when the shipped file fails the same way (a structural problem, not an inertial),
    or the message names only links urdf-inertia does not fill (no collision geometry, their inertials
    stripped by this validation); otherwise "FAILED: …"."""
    filled = work / f"{stem}.geomless.urdf"
    filled.write_text(without_geometry(filled_text), encoding="utf-8")
    original = work / f"{stem}.original.geomless.urdf"
    original.write_text(without_geometry(original_text), encoding="utf-8")
    verdicts = []
    for which in ("mujoco", "drake"):
        msg = _error(which, filled)
        if msg is None:
            verdicts.append("ok")
            continue
        named = re.findall(r"(?:Element name|[Bb]ody|[Ll]ink)\s*'?\"?([A-Za-z0-9_.\-]+)", msg)
        if msg == _error(which, original):
            verdicts.append(f"explained: the shipped file fails the same way: {msg[:200]}")
        elif named and not any(n in filled_links for n in named):
            verdicts.append(f"explained: {msg[:160]} (a link without collision geometry, which urdf-inertia leaves as it is; this validation stripped its shipped <inertial>)")
        else:
            verdicts.append(f"FAILED: {msg[:300]}")
    return verdicts


def _drake_load(path):
    plant = MultibodyPlant(0.0)
    Parser(plant).AddModels(str(path))
    plant.Finalize()


def link_joints(model):
    """Link (BODY frame) name -> parent joint index."""
    out = {}
    for f in model.frames:
        if f.type == pin.FrameType.BODY:
            out[f.name] = f.parentJoint
    return out


def reason_for(parts, urdf_text):
    """Why a joint's number may legitimately differ from coal's, or None when it must agree."""
    reasons = []
    for p in parts:
        prov = p["provenance"]
        if prov == "convex-hull":
            reasons.append(f"{Path(p['geometry']).name}: open mesh replaced by its convex hull (coal integrates the open surface)")
        elif prov == "capped":
            reasons.append(f"{Path(p['geometry']).name}: open mesh, holes closed with flat caps (coal integrates the open surface about the origin)")
        elif prov == "non-manifold":
            reasons.append(f"{Path(p['geometry']).name}: non-manifold closed mesh, integrated about its bounding-box centre (coal: about the origin)")
        elif prov in ("reoriented", "inverted"):
            reasons.append(f"{Path(p['geometry']).name}: {prov} winding fixed (coal integrates it as wound)")
        elif classified(p):
            reasons.append(f"{Path(p['geometry']).name}: closed shells that overlap, a region two of them enclose counted once (coal counts it twice)")
    return reasons


def classified(part):
    """Whether urdf-inertia classified the shells of a closed mesh (components that nest or cut each other):
    its messages say so; its volume is then Omega's, not the stored integral coal gives."""
    return any("shells" in m["message"] for m in part.get("warnings", []) + part.get("notes", []))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--binary", required=True)
    ap.add_argument("--share", required=True, help="the cmeel.prefix/share directory")
    ap.add_argument("--out", required=True)
    ap.add_argument("--work", required=True, help="directory for logs")
    args = ap.parse_args()

    share = Path(args.share)
    robots = share / "example-robot-data" / "robots"
    work = Path(args.work)
    work.mkdir(parents=True, exist_ok=True)
    urdfs = sorted(p for p in robots.rglob("*.urdf"))
    rows = []
    explained = []
    failures = []
    expected_failures = []
    all_rungs = {}
    shipped_notes = []
    t_all = time.time()
    for urdf in urdfs:
        rel = urdf.relative_to(robots)
        robot = rel.parts[0]
        text = urdf.read_text(encoding="utf-8")
        # Copies beside the original, so that relative mesh paths still resolve.
        stripped = urdf.with_name(urdf.name + ".stripped")
        filled = urdf.with_name(urdf.name + ".filled")
        stripped.write_text(strip_inertials(text), encoding="utf-8")
        t0 = time.time()
        # `--digits full`: every bit of the computation, compared at 1e-9. By default the numbers are
        # written within the input's precision (2^-24 for the f32 corners of binary STL), which is
        # coarser than the comparison; that rounding is the README's and its tests'.
        command = [args.binary, "fill", str(stripped), "--density", str(DENSITY), "-o", str(filled), "--format", "json",
                   "--digits", "full", "--package-path", f"example-robot-data={share / 'example-robot-data'}"]
        proc = subprocess.run(command, capture_output=True, text=True)
        no_solid = [l for l in proc.stderr.splitlines() if l.startswith("error[UI108]")]
        if proc.returncode != 0 and no_solid:
            # Open meshes whose caps cannot be trusted fail their links by default (UI108): the
            # expected outcome, listed. The comparison with pinocchio then asks for the convex hull
            # explicitly (an upper bound; such joints are explained, coal integrating the open surface).
            which = sorted({f"{m.group(1)} ({Path(m.group(2)).name})" for m in
                            (re.search(r"link `([^`]*)`: collision \d+ \(line \d+\): (.*?): mesh is ", l) for l in no_solid) if m})
            expected_failures.append(f"| {rel} | {len(no_solid)} | {', '.join(which)[:600]} |")
            proc = subprocess.run(command + ["--open-mesh", "hull"], capture_output=True, text=True)
        seconds = time.time() - t0
        (work / (str(rel).replace("/", "__") + ".log")).write_text(proc.stderr)
        if proc.returncode != 0:
            failures.append(f"{rel}: fill exited {proc.returncode}: {proc.stderr.strip().splitlines()[-1] if proc.stderr.strip() else ''}")
            rows.append((robot, str(rel), "FAILED", 0, "-", "-", f"{seconds:.2f}", "-", "-"))
            continue
        summary = json.loads(proc.stdout)
        check = subprocess.run([args.binary, "check", str(filled)], capture_output=True, text=True)
        if check.returncode != 0:
            failures.append(f"{rel}: `urdf-inertia check` of the filled file exited {check.returncode}: {check.stdout.strip()[:300]}")
        try:
            original_model = pin.buildModelFromUrdf(str(urdf))
        except Exception as e:  # noqa: BLE001 - the shipped file itself is not a URDF urdfdom reads
            first = str(e).strip().splitlines()
            why = next((l.strip() for l in first if "Error" in l), first[0] if first else "")
            explained.append(f"| {rel} | - | - | the shipped file does not load in pinocchio either ({why}); urdf-inertia fills it (nothing to fill) and warns |")
            rows.append((robot, str(rel), summary["links_filled"], 0, "original not loadable", "-", f"{seconds:.2f}", "-", "-"))
            for p in (stripped, filled):
                p.unlink(missing_ok=True)
            continue
        try:
            filled_model = pin.buildModelFromUrdf(str(filled))
        except Exception as e:  # noqa: BLE001 - any loader failure is a validation failure
            failures.append(f"{rel}: pinocchio cannot load the filled URDF: {e}")
            rows.append((robot, str(rel), summary["links_filled"], 0, "load FAILED", "-", f"{seconds:.2f}", "-", "-"))
            continue
        sim = ("-", "-")
        if SIMULATORS:
            filled_links = {l["link"] for l in summary["links"]}
            sim = simulator_checks(filled.read_text(encoding="utf-8"), text, filled_links, work, str(rel).replace("/", "__"))
            for which, verdict in zip(("MuJoCo", "Drake"), sim):
                if verdict.startswith("FAILED"):
                    failures.append(f"{rel}: {which} cannot load the filled URDF: {verdict}")
                elif verdict.startswith("explained"):
                    explained.append(f"| {rel} | - | - | {which}: {verdict[len('explained: '):]} |")
        ref = reference_inertias(original_model, urdf, [str(share)])
        joints_of = link_joints(filled_model)
        parts_by_joint = {}
        for link in summary["links"]:
            j = joints_of.get(link["link"])
            if j is None:
                continue
            parts_by_joint.setdefault(j, []).extend(link["parts"])
        rungs = {}
        for link in summary["links"]:
            for p in link["parts"]:
                rungs[p["provenance"]] = rungs.get(p["provenance"], 0) + 1
                all_rungs[p["provenance"]] = all_rungs.get(p["provenance"], 0) + 1
        mirrored = set(re.findall(r'filename="([^"]+)"\s+scale="[^"]*-[^"]*"', text)) | set(
            re.findall(r'scale="[^"]*-[^"]*"\s+filename="([^"]+)"', text))
        worst = 0.0
        compared = 0
        for j, want in sorted(ref.items()):
            if want.mass == 0.0:
                continue
            fi = filled_model.inertias[j]
            got = Body(fi.mass, fi.lever, fi.inertia)
            dm, dc, di = rel_inertia_diff(got, want)
            diff = max(dm, dc, di)
            parts = parts_by_joint.get(j, [])
            reasons = reason_for(parts, text)
            if any(p["geometry"] in mirrored for p in parts):
                reasons.append("mirrored scale (coal keeps the inverted winding: negative volume)")
            if "collision_checking" in text and "capsule" in text:
                reasons.append("pinocchio's <collision_checking> turns the cylinder into a capsule; the URDF says cylinder")
            float32 = any(Path(p["geometry"]).suffix.lower() in (".obj", ".dae") for p in parts)
            tol = TOL_FLOAT32 if float32 else TOL_STL
            # A welded mesh (closed once float-noise cracks are welded) is integrated as stored, as
            # coal does, about another reference point: they agree within our error estimate.
            welded = [p["error_estimate"] for p in parts if p["provenance"] == "welded"]
            if welded:
                tol = max(tol, 3 * max(welded))
            compared += 1
            name = filled_model.names[j]
            if reasons:
                if diff > tol:
                    explained.append(f"| {rel} | {name} | {diff:.2e} | {'; '.join(sorted(set(reasons)))} |")
                continue
            worst = max(worst, diff)
            if diff > tol:
                failures.append(f"{rel}: joint {name}: closed-mesh joint differs by {diff:.3e} (mass {dm:.2e}, COM {dc:.2e}, inertia {di:.2e}; tolerance {tol:g})")
        # Shipped (CAD) inertials against computed ones, informational.
        bad = 0
        ratios = []
        for j in range(1, original_model.njoints):
            shipped = original_model.inertias[j]
            ev = np.linalg.eigvalsh(shipped.inertia)
            if shipped.mass > 0 and (ev[0] < -1e-9 * abs(ev[2]) or ev[2] > ev[0] + ev[1] + 1e-9 * abs(ev[2])):
                bad += 1
            if shipped.mass > 0 and filled_model.inertias[j].mass > 0:
                ratios.append(shipped.mass / filled_model.inertias[j].mass)
        if ratios or bad:
            rng = f"{min(ratios):.3g}–{max(ratios):.3g}" if ratios else "-"
            shipped_notes.append(f"| {rel} | {rng} | {bad} |")
        rung_text = ", ".join(f"{k} {v}" for k, v in sorted(rungs.items()))
        short = lambda v: v if v in ("ok", "-") else v.split(":")[0]
        rows.append((robot, str(rel), summary["links_filled"], compared, f"{worst:.1e}", rung_text, f"{seconds:.2f}", short(sim[0]), short(sim[1])))
        for p in (stripped, filled):
            p.unlink(missing_ok=True)
    # The demo robot of this repository, filled with its density map, in all three.
    demo = Path(__file__).resolve().parent.parent / "robots" / "demo_arm_description"
    demo_filled = work / "demo_arm.filled.urdf"
    proc = subprocess.run([args.binary, "fill", str(demo / "urdf" / "demo_arm.urdf"), "--density-map", str(demo / "densities.toml"), "-o", str(demo_filled)], capture_output=True, text=True)
    demo_line = "demo robot: fill failed"
    if proc.returncode != 0:
        failures.append(f"robots/demo_arm_description: fill exited {proc.returncode}: {proc.stderr.strip()}")
    else:
        try:
            m = pin.buildModelFromUrdf(str(demo_filled))
            verdicts = simulator_checks(demo_filled.read_text(encoding="utf-8"), (demo / "urdf" / "demo_arm.urdf").read_text(encoding="utf-8"), set(), work, "demo_arm") if SIMULATORS else ["-", "-"]
            demo_line = f"demo robot (robots/demo_arm_description, {m.nbodies} bodies): pinocchio ok, MuJoCo {verdicts[0]}, Drake {verdicts[1]}"
            for which, v in zip(("MuJoCo", "Drake"), verdicts):
                if v != "ok" and v != "-":
                    failures.append(f"demo robot: {which}: {v}")
        except Exception as e:  # noqa: BLE001
            failures.append(f"demo robot: pinocchio cannot load it: {e}")
    total = time.time() - t_all

    lines = [
        "# Validation against pinocchio on example-robot-data",
        "",
        "Generated by `bash validation/run.sh` (pin 4.1.0, example-robot-data 6.0.0, density "
        f"{DENSITY:g} kg/m³). Each URDF is stripped of its `<inertial>` elements, filled by urdf-inertia, "
        "loaded with `pinocchio.buildModelFromUrdf`, and each joint's inertia is compared with pinocchio's "
        "own collision model of the original URDF (coal volume, COM and inertia per geometry, moved by its "
        "placement and summed per joint; a `<cylinder>` with a `<sphere>` of its radius centred on each "
        "end, as `panda_collision.urdf` writes its capsules, is one `coal.Capsule`, their union, as "
        "urdf-inertia computes it). The difference is the largest of the relative mass, COM "
        "(against the radius of gyration) and central-inertia (Frobenius) differences. The filled URDF, "
        "with its geometry removed so that only the inertials are judged, is also loaded in MuJoCo "
        f"{mujoco.__version__ if SIMULATORS else '(not installed)'} (`MjModel.from_xml_path`: mass above "
        "mjMINVAL, strict triangle inequality) and Drake (`Parser.AddModels`, `Finalize`: physically valid "
        "spatial inertias).",
        "",
        f"URDFs: {len(urdfs)}; failures: {len(failures)}; total time {total:.1f} s. "
        f"Parts by provenance over all URDFs: {', '.join(f'{k} {v}' for k, v in sorted(all_rungs.items()))}.",
        "",
        demo_line + ".",
        "",
        "| robot | URDF | links filled | joints compared | worst diff, closed-mesh joints | parts by provenance | fill time (s) | MuJoCo | Drake |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    lines += [f"| {' | '.join(str(x) for x in r)} |" for r in rows]
    lines += [
        "",
        "Tolerances for closed-mesh joints: 1e-9 relative for STL meshes and primitives, 1e-6 where OBJ or "
        "DAE meshes are involved (assimp, pinocchio's loader, keeps their vertices in float32).",
        "",
        "## Joints that differ, and why our number is the right one",
        "",
        "| URDF | joint | diff | reason |",
        "|---|---|---|---|",
    ]
    lines += explained or ["| - | - | - | none |"]
    lines += [
        "",
        "## Expected failures: open meshes with no solid to trust (UI108)",
        "",
        "By default `fill` fails a link whose open mesh's flat caps cannot be trusted (bound above 1e-3) "
        "instead of silently taking its convex hull. These URDFs were then filled again with "
        "`--open-mesh hull` (an explicit upper bound) for the comparisons above.",
        "",
        "| URDF | links failing by default | links (mesh) |",
        "|---|---|---|",
    ]
    lines += expected_failures or ["| - | - | none |"]
    lines += [
        "",
        "## Shipped (CAD) inertials against computed ones (informational)",
        "",
        f"Mass ratio shipped/computed per joint at a uniform {DENSITY:g} kg/m³ (real robots are not uniform "
        "and not solid, so ratios far from 1 are expected), and the number of shipped joint inertias that "
        "are not physically valid (not positive definite, or breaking the triangle inequality).",
        "",
        "| URDF | mass ratio range | invalid shipped inertias |",
        "|---|---|---|",
    ]
    lines += shipped_notes
    if failures:
        lines += ["", "## Failures", ""] + [f"- {f}" for f in failures]
    Path(args.out).write_text("\n".join(lines) + "\n", encoding="utf-8")
    print("\n".join(lines))
    if failures:
        print(f"\nvalidation FAILED: {len(failures)} problem(s)", file=sys.stderr)
        return 1
    print(f"\nvalidation passed: {len(urdfs)} URDFs, {len(failures)} failures")
    return 0


if __name__ == "__main__":
    sys.exit(main())
