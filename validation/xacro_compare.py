#!/usr/bin/env python3
"""Ground truth for the xacro expander: every xacro of the shared corpus expanded by xacrodoc (ROS 2
xacro 2.x without ROS) and by `urdf-inertia xacro`, compared element by element; `check` and `fill`
of each `.xacro` against `check` and `fill` of the reference expansion; `fill -i` into a temporary
copy of the repository, expanded again by xacrodoc; and the speed of both, whole process against
whole process. Run through validation/xacro.sh, which makes the venv and builds the binary.

Exit status 0 when every requirement holds (exceptions are listed in the report with their reason),
1 otherwise.
"""

import argparse
import json
import os
import re
import shutil
import statistics
import subprocess
import sys
import time
import xml.etree.ElementTree as ET
from pathlib import Path

REL = 1e-12
DENSITY = "1000"
XACRO_NS = "http://www.ros.org/wiki/xacro"


def run(cmd, cwd=None):
    """Runs a command, returns (exit code, stdout, stderr, seconds)."""
    t0 = time.perf_counter()
    p = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True)
    return p.returncode, p.stdout, p.stderr, time.perf_counter() - t0


def packages(root):
    """Every package.xml under root: {name: folder}."""
    found = {}
    for xml in sorted(root.rglob("package.xml")):
        name = ET.parse(xml).getroot().findtext("name")
        if name:
            found[name.strip()] = xml.parent
    return found


def package_args(pkgs):
    out = []
    for name, folder in sorted(pkgs.items()):
        out += ["--package-path", f"{name}={folder}"]
    return out


def cases(corpus):
    """(repository folder, xacro file, args): default args, and every ur_type in config/ for a file
    that declares the `ur_type` argument (with name:=ur, which its root's name needs)."""
    out = []
    for repo in sorted(p for p in corpus.iterdir() if p.is_dir()):
        types = sorted(p.name for p in (repo / "config").iterdir() if p.is_dir()) if (repo / "config").is_dir() else []
        for f in sorted(repo.rglob("*.xacro")):
            text = f.read_text(encoding="utf-8")
            if types and re.search(r'<xacro:arg\s+name="ur_type"', text):
                for t in types:
                    out.append((repo, f, [f"ur_type:={t}", "name:=ur"]))
            else:
                out.append((repo, f, []))
    return out


def resolve_uri(value, pkgs, base):
    """A mesh URI as a real path: file:// (xacrodoc), package:// (ours), or relative to the file."""
    if value.startswith("file://"):
        return os.path.realpath(value[len("file://"):])
    if value.startswith("package://"):
        name, _, rest = value[len("package://"):].partition("/")
        if name in pkgs:
            return os.path.realpath(pkgs[name] / rest)
        return value
    return os.path.realpath(base / value)


def numbers(text):
    try:
        return [float(t) for t in text.split()]
    except ValueError:
        return None


def same_value(a, b, pkgs, base):
    if a == b:
        return True
    if any(v.startswith(("file://", "package://")) for v in (a, b)):
        return resolve_uri(a, pkgs, base) == resolve_uri(b, pkgs, base)
    na, nb = numbers(a), numbers(b)
    if na is None or nb is None or len(na) != len(nb) or not na:
        return False
    return all(x == y or abs(x - y) <= REL * max(abs(x), abs(y)) for x, y in zip(na, nb))


def children(e):
    return [c for c in e if isinstance(c.tag, str)]


def compare_element(a, b, path, pkgs, base, diffs):
    """Appends to diffs every difference between reference a and ours b (tags, attributes, text,
    children in order)."""
    if a.tag != b.tag:
        diffs.append(f"{path}: element <{a.tag}> against <{b.tag}>")
        return
    for k in sorted(set(a.attrib) | set(b.attrib)):
        va, vb = a.attrib.get(k), b.attrib.get(k)
        if va is None or vb is None:
            diffs.append(f"{path}@{k}: {va!r} against {vb!r}")
        elif not same_value(va, vb, pkgs, base):
            diffs.append(f"{path}@{k}: {va!r} against {vb!r}")
    ta, tb = (a.text or "").strip(), (b.text or "").strip()
    if ta != tb and not same_value(ta, tb, pkgs, base):
        diffs.append(f"{path} text: {ta[:60]!r} against {tb[:60]!r}")
    ca, cb = children(a), children(b)
    if len(ca) != len(cb):
        diffs.append(f"{path}: {len(ca)} child elements against {len(cb)}")
    for i, (x, y) in enumerate(zip(ca, cb)):
        compare_element(x, y, f"{path}/{x.tag}[{i}]", pkgs, base, diffs)


def compare_robots(ref, ours, pkgs, base):
    """Differences between two expansions: links and joints by name, every other top-level element
    in order."""
    diffs = []
    ra, rb = ref.getroot(), ours.getroot()
    if ra.attrib.get("name") != rb.attrib.get("name"):
        diffs.append(f"robot name {ra.attrib.get('name')!r} against {rb.attrib.get('name')!r}")
    for kind in ("link", "joint"):
        ea = {e.attrib.get("name"): e for e in ra.findall(kind)}
        eb = {e.attrib.get("name"): e for e in rb.findall(kind)}
        if len(ea) != len(ra.findall(kind)) or len(eb) != len(rb.findall(kind)):
            diffs.append(f"duplicate {kind} names")
        if set(ea) != set(eb):
            diffs.append(f"{kind}s only in xacrodoc: {sorted(set(ea) - set(eb))}; only in ours: {sorted(set(eb) - set(ea))}")
        for name in sorted(set(ea) & set(eb)):
            compare_element(ea[name], eb[name], f"{kind} {name}", pkgs, base, diffs)
    oa = [e for e in children(ra) if e.tag not in ("link", "joint")]
    ob = [e for e in children(rb) if e.tag not in ("link", "joint")]
    if len(oa) != len(ob):
        diffs.append(f"{len(oa)} other top-level elements against {len(ob)}")
    for i, (x, y) in enumerate(zip(oa, ob)):
        compare_element(x, y, f"{x.tag}[{i}]", pkgs, base, diffs)
    return diffs


def flagged(text):
    """The links named in check's messages."""
    return {m.group(1) for line in text.splitlines() for m in [re.search(r"link `([^`]+)`", line)] if m}


def inertials(path):
    """{link: inertial element} of a URDF."""
    return {e.attrib["name"]: e.find("inertial") for e in ET.parse(path).getroot().findall("link")}


def same_inertial(a, b):
    if a is None or b is None:
        return a is None and b is None
    diffs = []
    compare_element(a, b, "inertial", {}, Path("."), diffs)
    return not diffs


def literal_links(repo):
    """Link names written literally in the repository's xacro files: outside any macro body, a plain
    name (no `${`, no `$(`), no xacro element inside (a macro call there makes part of the link).
    The write-back must write these."""
    names = set()

    def from_xacro(e):
        return any(isinstance(c.tag, str) and c.tag.startswith(f"{{{XACRO_NS}}}") for c in e.iter())

    def walk(e, in_macro):
        if not isinstance(e.tag, str):
            return
        in_macro = in_macro or e.tag == f"{{{XACRO_NS}}}macro"
        if e.tag == "link" and not in_macro:
            name = e.attrib.get("name", "")
            if "$" not in name and not from_xacro(e):
                names.add(name)
        for c in e:
            walk(c, in_macro)

    for f in repo.rglob("*.xacro"):
        walk(ET.parse(f).getroot(), False)
    return names


class Report:
    def __init__(self):
        self.rows = []
        self.failures = []
        self.exceptions = []

    def fail(self, case, msg):
        self.failures.append(f"{case}: {msg}")


def rel(path, root):
    try:
        return str(path.relative_to(root))
    except ValueError:
        return str(path)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--binary", required=True)
    ap.add_argument("--xacrodoc", required=True)
    ap.add_argument("--corpus", required=True)
    ap.add_argument("--work", required=True)
    ap.add_argument("--out", required=True)
    ap.add_argument("--speed-runs", type=int, default=10)
    ap.add_argument("--speed-only", action="store_true")
    a = ap.parse_args()
    binary = os.path.realpath(a.binary)
    xacrodoc = os.path.realpath(a.xacrodoc)
    corpus = Path(a.corpus).resolve()
    work = Path(a.work).resolve()
    work.mkdir(parents=True, exist_ok=True)
    pkgs = packages(corpus)
    report = Report()
    lines = []
    started = time.perf_counter()
    t_ref = t_ours = 0.0
    n_top = n_macro = n_rt_written = n_rt_macro = n_rt_named = n_rt_literal = n_flat_written = 0

    for i, (repo, f, args) in enumerate([] if a.speed_only else cases(corpus)):
        case = rel(f, corpus) + ("" if not args else " " + " ".join(args))
        d = work / f"case{i:02}"
        d.mkdir(exist_ok=True)
        ref_path, ours_path = d / "ref.urdf", d / "ours.urdf"
        # From the file's folder: xacrodoc hands xacro the file's text, so a relative include in the
        # top-level file is looked up from the working directory (xacro itself looks beside the file).
        rc_r, _, err_r, s_r = run([xacrodoc, "-d", str(corpus), str(f), "-o", str(ref_path)] + args, cwd=f.parent)
        rc_o, out_o, err_o, s_o = run([binary, "xacro", str(f)] + args + package_args(pkgs))
        t_ref += s_r
        t_ours += s_o
        ours_path.write_text(out_o, encoding="utf-8")
        row = {"case": case, "ref_s": s_r, "ours_s": s_o}
        report.rows.append(row)
        if rc_r != 0:
            # The reference rejects it: ours must reject it too, as an expansion error (exit 2).
            row["result"] = "both reject" if rc_o == 2 else "FAIL"
            if rc_o != 2:
                report.fail(case, f"xacrodoc rejects it ({err_r.strip().splitlines()[-1:]}) but ours exits {rc_o}")
            else:
                report.exceptions.append(f"{case}: rejected by both; xacrodoc: {err_r.strip().splitlines()[-1][:160]}; ours: {err_o.strip().splitlines()[-1][:160]}")
            continue
        if rc_o != 0:
            row["result"] = "FAIL"
            report.fail(case, f"ours exits {rc_o}: {err_o.strip()[:300]}")
            continue
        ref, ours = ET.parse(ref_path), ET.parse(ours_path)
        diffs = compare_robots(ref, ours, pkgs, f.parent)
        nl = len(ref.getroot().findall("link"))
        nj = len(ref.getroot().findall("joint"))
        row["links"], row["joints"] = nl, nj
        if diffs:
            row["result"] = "FAIL"
            report.fail(case, f"{len(diffs)} difference(s): " + "; ".join(diffs[:8]))
            continue
        row["result"] = "identical"
        if nl == 0:
            n_macro += 1
            row["result"] = "identical (macro file, empty robot)"
            continue
        n_top += 1

        # check and fill of the .xacro against check and fill of the reference expansion.
        common = ["--density", DENSITY]
        rc_cx, o_cx, e_cx, _ = run([binary, "check", str(f)] + common + package_args(pkgs) + [f"--arg={x}" for x in args])
        rc_cr, o_cr, e_cr, _ = run([binary, "check", str(ref_path)] + common)
        row["check"] = f"{rc_cx}/{rc_cr}"
        if rc_cx != rc_cr:
            report.fail(case, f"check exits {rc_cx} on the .xacro, {rc_cr} on the reference expansion")
        flagged_x, flagged_r = flagged(o_cx + e_cx), flagged(o_cr + e_cr)
        if flagged_x != flagged_r:
            report.fail(case, f"check flags {sorted(flagged_x)} on the .xacro, {sorted(flagged_r)} on the reference expansion")
        fx, fr = d / "fill-xacro.urdf", d / "fill-ref.urdf"
        fill = ["fill", "--keep-going", "--format", "json"] + common
        rc_fx, out_fx, _, _ = run([binary] + fill + [str(f), "-o", str(fx)] + package_args(pkgs) + [f"--arg={x}" for x in args])
        rc_fr, out_fr, _, _ = run([binary] + fill + [str(ref_path), "-o", str(fr)])
        row["fill"] = f"{rc_fx}/{rc_fr}"
        if rc_fx != rc_fr:
            report.fail(case, f"fill exits {rc_fx} on the .xacro, {rc_fr} on the reference expansion")
        sx, sr = json.loads(out_fx), json.loads(out_fr)
        computed = sorted(l["link"] for l in sr["links"])
        failed = sorted(e.get("link", "") for e in sr["errors"])
        if sorted(l["link"] for l in sx["links"]) != computed or sorted(e.get("link", "") for e in sx["errors"]) != failed:
            report.fail(case, "fill computes or fails other links on the .xacro than on the reference expansion")
        if rc_fr != 0:
            report.exceptions.append(f"`{case}`: fill exits {rc_fr} on both (--keep-going fills the other links): "
                                     + "; ".join(f"link `{e.get('link')}`: {e['message'].splitlines()[0]}" for e in sr["errors"]))
        if not fx.exists() or not fr.exists():
            report.fail(case, "fill wrote no output")
            continue
        ix, ir = inertials(fx), inertials(fr)
        bad = sorted(n for n in set(ix) | set(ir) if not same_inertial(ir.get(n), ix.get(n)))
        if bad:
            report.fail(case, f"fill gives different inertials for {bad}")

        # fill -i into a temporary copy of the repository, then expanded again by xacrodoc.
        copy_root = d / "copy"
        copy = copy_root / repo.name
        shutil.copytree(repo, copy)
        # shared/ is laid without write bits; the copy is ours to write.
        for p in [copy, *copy.rglob("*")]:
            p.chmod(p.stat().st_mode | 0o200)
        cf = copy / f.relative_to(repo)
        cpkgs = dict(pkgs)
        cpkgs.update(packages(copy_root))
        rc_fi, out_fi, err_fi, _ = run([binary, "fill", "-i", str(cf), "--keep-going"] + common + package_args(cpkgs) + [f"--arg={x}" for x in args])
        said = out_fi + err_fi
        re_path = d / "re.urdf"
        rc_re, _, err_re, _ = run([xacrodoc, "-d", str(copy_root), str(cf), "-o", str(re_path)] + args, cwd=cf.parent)
        if rc_fi != rc_fr:
            report.fail(case, f"fill -i exits {rc_fi}, fill of the reference expansion {rc_fr}")
        if rc_re != 0:
            report.fail(case, f"xacrodoc cannot expand the source after fill -i: {err_re.strip()[-300:]}")
            continue
        ire = inertials(re_path)
        literal = literal_links(copy)
        written, named = [], []
        for n in computed:
            if n in ire and same_inertial(ir[n], ire[n]):
                written.append(n)
            elif re.search(rf"link `{re.escape(n)}`[^\n]*not written", said):
                named.append(n)
                if n in literal:
                    report.fail(case, f"literal link {n} not written by fill -i")
            else:
                report.fail(case, f"link {n}: fill -i neither wrote the inertial fill gives nor named it")
        n_rt_written += len(written)
        n_rt_macro += sum(1 for n in written if n not in literal)
        n_rt_named += len(named)
        n_rt_literal += sum(1 for n in computed if n in literal)

        # The corpus writes (almost) every link in a macro body, so the write-back into literal links
        # is also run on the reference expansion saved as a xacro source beside the top-level file:
        # every link there is literal, so every computed link must be written, byte for byte where
        # xacrodoc finds it again.
        flat = cf.parent / (cf.name.split(".")[0] + ".flat.xacro")
        text = ref_path.read_text(encoding="utf-8")
        if "xmlns:xacro" not in text:
            text = text.replace("<robot ", f'<robot xmlns:xacro="{XACRO_NS}" ', 1)
        flat.write_text(text, encoding="utf-8")
        rc_ff, _, _, _ = run([binary, "fill", "-i", str(flat), "--keep-going"] + common)
        re_flat = d / "re-flat.urdf"
        rc_rf, _, err_rf, _ = run([xacrodoc, "-d", str(copy_root), str(flat), "-o", str(re_flat)], cwd=flat.parent)
        if rc_ff != rc_fr or rc_rf != 0:
            report.fail(case, f"fill -i of the saved expansion exits {rc_ff} (fill: {rc_fr}); xacrodoc after it exits {rc_rf} {err_rf.strip()[-200:]}")
            continue
        iflat = inertials(re_flat)
        missing = [n for n in computed if not same_inertial(ir[n], iflat.get(n))]
        if missing:
            report.fail(case, f"fill -i of the saved expansion did not write what fill gives for {missing}")
        n_flat_written += len(computed) - len(missing)
        row["fill -i"] = f"{len(written)} written, {len(named)} named; saved expansion: {len(computed) - len(missing)} of {len(computed)} written"

    speed = speed_run(a, binary, xacrodoc, corpus, pkgs, work)
    total = time.perf_counter() - started

    lines.append("# xacro validation report\n")
    lines.append(f"Corpus: `{corpus}`; reference: xacrodoc (`{xacrodoc}`); ours: `{binary}`.\n")
    if not a.speed_only:
        lines.append(f"{len(report.rows)} expansions: {n_top} top-level (links), {n_macro} macro-only files; "
                     f"`fill -i` round trip: {n_rt_written} link(s) written into the source and found again by xacrodoc "
                     f"({n_rt_macro} of them into macro bodies with nothing computed inside the link), "
                     f"{n_rt_named} macro link(s) not written and named ({n_rt_literal} computed link(s) written literally in the sources, "
                     "outside macro bodies with a plain name, all of which must be written); "
                     f"on the reference expansions saved as xacro sources, {n_flat_written} link(s) written and found again.\n")
        lines.append("| case | links | joints | expansion | check exit (xacro/ref) | fill exit (xacro/ref) | fill -i | xacrodoc s | ours s |")
        lines.append("|---|---|---|---|---|---|---|---|---|")
        for r in report.rows:
            lines.append(f"| `{r['case']}` | {r.get('links', '')} | {r.get('joints', '')} | {r['result']} | {r.get('check', '')} | "
                         f"{r.get('fill', '')} | {r.get('fill -i', '')} | {r['ref_s']:.3f} | {r['ours_s']:.4f} |")
        lines.append(f"\nExpansion time summed over the cases: xacrodoc {t_ref:.2f} s, ours {t_ours:.3f} s.\n")
        lines.append("## Exceptions\n")
        lines += [f"- {e}" for e in report.exceptions] or ["none"]
        lines.append("\n## Failures\n")
        lines += [f"- {e}" for e in report.failures] or ["none"]
    lines.append("\n## Speed\n")
    lines += speed
    lines.append(f"\nTotal run time: {total:.1f} s.")
    text = "\n".join(lines) + "\n"
    Path(a.out).write_text(text, encoding="utf-8")
    print(text)
    return 1 if report.failures else 0


def speed_run(a, binary, xacrodoc, corpus, pkgs, work):
    """Whole process against whole process, interleaved: ur.urdf.xacro ur_type:=ur5e name:=ur."""
    ur = next((p for p in corpus.rglob("ur.urdf.xacro")), None)
    if ur is None or a.speed_runs <= 0:
        return ["not run"]
    args = ["ur_type:=ur5e", "name:=ur"]
    ref_cmd = [xacrodoc, "-d", str(corpus), str(ur), "-o", str(work / "speed-ref.urdf")] + args
    ours_cmd = [binary, "xacro", str(ur)] + args + package_args(pkgs)
    tr, to = [], []
    for _ in range(a.speed_runs):
        rc, _, err, s = run(ref_cmd)
        if rc != 0:
            return [f"xacrodoc failed: {err.strip()[-200:]}"]
        tr.append(s)
        with open(work / "speed-ours.urdf", "w") as out:
            t0 = time.perf_counter()
            rc = subprocess.run(ours_cmd, stdout=out, stderr=subprocess.DEVNULL).returncode
            to.append(time.perf_counter() - t0)
        if rc != 0:
            return [f"urdf-inertia xacro failed with exit {rc}"]
    mr, mo = statistics.median(tr), statistics.median(to)
    return [
        f"`{ur.name} {' '.join(args)}`, {a.speed_runs} runs each, interleaved, whole process (wall clock):\n",
        "| expander | median s | min s | max s |",
        "|---|---|---|---|",
        f"| xacrodoc | {mr:.4f} | {min(tr):.4f} | {max(tr):.4f} |",
        f"| urdf-inertia xacro | {mo:.4f} | {min(to):.4f} | {max(to):.4f} |",
        f"\nRatio of medians: **{mr / mo:.0f}×** (target at least 20×).",
    ]


if __name__ == "__main__":
    sys.exit(main())
