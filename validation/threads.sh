#!/bin/bash
# One thread against two, whole process, old against new binary (docs/benchmarks.md, "One thread
# against two"). Run on an idle machine:
#   bash validation/threads.sh OLD_BIN NEW_BIN [ROUNDS_1.3M] [ROUNDS_10M] [ROUNDS_ASCII]
# Inputs (made if missing, never in a repository): the torus of `make_large_inputs meshes` at
# 1,299,600 and 9,998,244 faces, binary STL, in $THREADS_INPUTS (default /tmp/urdf-inertia-threads),
# written by `make_large_inputs torus-stl`.
# Rounds are interleaved (old 1, old 2, new 1, new 2 in each round, the order rotated every round);
# each run is the whole `urdf-inertia mesh FILE` process with RAYON_NUM_THREADS=1 or 2. Printed per
# binary, file and thread count: medians of wall, CPU (user + system, the child's rusage), user,
# system, minor page faults and max RSS; then the ratio of wall medians, one thread over two. The
# outputs of every binary and thread count are also compared (md5 of the report without its
# `time` line): all must be equal.
# Then ASCII against binary (docs/benchmarks.md, "ASCII STL against binary STL"): the torus of
# 409,600 faces written as exporters write ASCII STL (`%e`, 248 bytes a face, 101.6 MB) and as
# binary STL (20.5 MB), corners rounded to f32 first; per binary and thread count, the medians and
# the ratio ASCII / binary of wall and CPU time. ROUNDS_ASCII=0 skips it.
set -euo pipefail
old=${1:?old binary}; new=${2:?new binary}; r13=${3:-15}; r10=${4:-5}; ra=${5:-15}
big=${THREADS_INPUTS:-/tmp/urdf-inertia-threads}; mkdir -p "$big"
for n in 1300000:torus13 10000000:torus10m; do
  if [ ! -s "$big/${n#*:}.stl" ]; then
    mkdir -p "$big/gen"
    (cd "$(dirname "$0")/.." && cargo run --release --quiet -p urdf-inertia --example make_large_inputs -- torus-stl "$big/gen" "${n%%:*}")
    mv "$big/gen/torus.stl" "$big/${n#*:}.stl"
  fi
done
echo "load before: $(cat /proc/loadavg)"; nproc
for f in "$big/torus13.stl" "$big/torus10m.stl"; do
  sums=$(for b in "$old" "$new"; do for t in 1 2; do
    RAYON_NUM_THREADS=$t "$b" mesh "$f" | grep -v 'time' | md5sum; done; done | sort -u | wc -l)
  echo "$(basename "$f"): distinct outputs over binaries and thread counts: $sums (must be 1)"
done
python3 - "$old" "$new" "$big/torus13.stl" "$r13" "$big/torus10m.stl" "$r10" <<'PY'
import os, resource, statistics as st, subprocess, sys, time
old, new = sys.argv[1], sys.argv[2]
for f, rounds in ((sys.argv[3], int(sys.argv[4])), (sys.argv[5], int(sys.argv[6]))):
    runs = [(b, t) for b in (old, new) for t in ('1', '2')]
    d = {}
    # Warm the page cache.
    subprocess.run([old, 'mesh', f], stdout=subprocess.DEVNULL, check=True)
    for r in range(rounds):
        k = r % len(runs)
        for b, t in runs[k:] + runs[:k]:
            env = dict(os.environ, RAYON_NUM_THREADS=t)
            r0 = resource.getrusage(resource.RUSAGE_CHILDREN); t0 = time.perf_counter()
            subprocess.run([b, 'mesh', f], env=env, stdout=subprocess.DEVNULL, check=True)
            t1 = time.perf_counter(); r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
            d.setdefault((b, t), []).append((t1 - t0, r1.ru_utime - r0.ru_utime,
                r1.ru_stime - r0.ru_stime, r1.ru_minflt - r0.ru_minflt))
    faces = (os.path.getsize(f) - 84) // 50
    print(f"\n{os.path.basename(f)}: {faces} faces, {rounds} rounds, load after {os.getloadavg()[0]:.2f}")
    for (b, t), v in d.items():
        med = lambda i: st.median(x[i] for x in v)
        cpu = st.median(x[1] + x[2] for x in v)
        print(f"  {os.path.basename(b):>8} {t} thread(s): wall {1e3*med(0):8.1f} ms (min {1e3*min(x[0] for x in v):7.1f}), "
              f"cpu {1e3*cpu:8.1f} ms ({1e9*cpu/faces:5.1f} ns/face; user {1e3*med(1):7.1f}, sys {1e3*med(2):6.1f}), "
              f"faults {med(3):9.0f}")
    for b in (old, new):
        w1 = st.median(x[0] for x in d[(b, '1')]); w2 = st.median(x[0] for x in d[(b, '2')])
        print(f"  {os.path.basename(b):>8}: one thread over two, wall medians: {w1/w2:.2f}x")
PY
[ "$ra" -gt 0 ] || exit 0
if [ ! -s "$big/ascii409600.stl" ] || [ ! -s "$big/binary409600.stl" ]; then
  python3 - "$big" <<'PY'
import math, struct, sys
# The torus of benches/stl.rs at k = 320: common::wild::torus(1.0, 0.4, 640, 320), corners
# f32(0.1 c + 0.2), written with C's `%e`.
big = sys.argv[1]; n, m = 640, 320
f32 = lambda x: struct.unpack('<f', struct.pack('<f', x))[0]
v = []
for i in range(n):
    a = 2 * math.pi * i / n
    for j in range(m):
        b = 2 * math.pi * j / m
        r = 1.0 + 0.4 * math.cos(b)
        v.append(tuple(f32(0.1 * c + 0.2) for c in (r * math.cos(a), r * math.sin(a), 0.4 * math.sin(b))))
at = lambda i, j: (i % n) * m + j % m
faces = []
for i in range(n):
    for j in range(m):
        faces += [(at(i, j), at(i + 1, j), at(i + 1, j + 1)), (at(i, j), at(i + 1, j + 1), at(i, j + 1))]
text = ["solid part\n"]
binary = [b"torus".ljust(80, b"\0"), struct.pack("<I", len(faces))]
for t in faces:
    text.append("  facet normal 0.000000e+00 0.000000e+00 1.000000e+00\n    outer loop\n")
    text += ["      vertex %e %e %e\n" % v[k] for k in t]
    text.append("    endloop\n  endfacet\n")
    binary.append(struct.pack("<3f", 0, 0, 1) + b"".join(struct.pack("<3f", *v[k]) for k in t) + b"\0\0")
text.append("endsolid part\n")
open(f"{big}/ascii409600.stl", "w").write("".join(text))
open(f"{big}/binary409600.stl", "wb").write(b"".join(binary))
PY
fi
python3 - "$old" "$new" "$big/ascii409600.stl" "$big/binary409600.stl" "$ra" <<'PY'
import os, resource, statistics as st, subprocess, sys, time
old, new, ascii, binary, rounds = sys.argv[1], sys.argv[2], sys.argv[3], sys.argv[4], int(sys.argv[5])
runs = [(b, f, t) for b in (old, new) for f in (ascii, binary) for t in ('1', '2')]
d = {}
for b, f, _ in runs:
    subprocess.run([b, 'mesh', f], stdout=subprocess.DEVNULL, check=True)
for r in range(rounds):
    k = r % len(runs)
    for b, f, t in runs[k:] + runs[:k]:
        env = dict(os.environ, RAYON_NUM_THREADS=t)
        r0 = resource.getrusage(resource.RUSAGE_CHILDREN); t0 = time.perf_counter()
        subprocess.run([b, 'mesh', f], env=env, stdout=subprocess.DEVNULL, check=True)
        t1 = time.perf_counter(); r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
        d.setdefault((b, f, t), []).append((t1 - t0, r1.ru_utime - r0.ru_utime + r1.ru_stime - r0.ru_stime))
print(f"\nASCII against binary, 409,600 faces, {rounds} rounds, load after {os.getloadavg()[0]:.2f}")
med = lambda v, i: st.median(x[i] for x in v)
for b in (old, new):
    for t in ('1', '2'):
        a, y = d[(b, ascii, t)], d[(b, binary, t)]
        print(f"  {os.path.basename(b):>8} {t} thread(s): ASCII wall {1e3*med(a, 0):7.1f} ms, cpu {1e3*med(a, 1):7.1f} ms; "
              f"binary wall {1e3*med(y, 0):6.1f} ms, cpu {1e3*med(y, 1):6.1f} ms; "
              f"ASCII / binary wall {med(a, 0)/med(y, 0):.2f}x, cpu {med(a, 1)/med(y, 1):.2f}x")
PY
