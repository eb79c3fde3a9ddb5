#!/usr/bin/env bash
# Peak memory per triangle of `scx analyze` on a large mesh (issue 29, item 8): a height field of N x N quads
# (2 N^2 triangles, each its own patch; N = 1000 gives 2M triangles) written as binary little-endian PLY,
# binary STL and OBJ into a scratch folder (never the repository), then analysed with each tracer while
# /usr/bin/time records the peak resident memory.
#
#   bash benches/memory.sh [N] [LINES] [DIR]     defaults: 1000, 1e5, /tmp/scx-memory
#
# Prints one row per run: file, format, triangles, tracer, peak MB, bytes per triangle (peak RSS over
# triangles), the tracer's build seconds and the run's lines per second (both from the JSON report).
# Build first: cargo build --release. SCX_BIN picks another binary.
set -euo pipefail
cd "$(dirname "$0")/.."
n="${1:-1000}"
lines="${2:-1e5}"
dir="${3:-/tmp/scx-memory}"
scx="${SCX_BIN:-target/release/scx}"
mkdir -p "$dir"
base="$dir/field$n"

if [ ! -e "$base.ply" ] || [ ! -e "$base.stl" ] || [ ! -e "$base.obj" ]; then
  python3 - "$n" "$base" <<'EOF'
import math, struct, sys
from array import array
n, out = int(sys.argv[1]), sys.argv[2]
v = array("f")
for i in range(n + 1):
    x = i / n
    for j in range(n + 1):
        y = j / n
        v.extend((x, y, 0.05 * math.sin(13.0 * x) * math.cos(17.0 * y) + 0.02 * math.sin(41.0 * x * y)))
if sys.byteorder != "little":
    v.byteswap()
t = []
for i in range(n):
    for j in range(n):
        a = i * (n + 1) + j
        b, c = a + n + 1, a + 1
        t.append((a, b, b + 1))
        t.append((a, b + 1, c))
nv = len(v) // 3
with open(out + ".ply", "wb") as f:
    f.write(("ply\nformat binary_little_endian 1.0\nelement vertex %d\nproperty float x\nproperty float y\n"
             "property float z\nelement face %d\nproperty list uchar int vertex_indices\nend_header\n"
             % (nv, len(t))).encode())
    f.write(v.tobytes())
    face = struct.Struct("<Biii")
    f.write(b"".join(face.pack(3, *k) for k in t))
with open(out + ".stl", "wb") as f:
    f.write(b"height field".ljust(80, b" ") + struct.pack("<I", len(t)))
    tri = struct.Struct("<12fH")
    f.write(b"".join(tri.pack(0.0, 0.0, 0.0, *v[3*a:3*a+3], *v[3*b:3*b+3], *v[3*c:3*c+3], 0) for a, b, c in t))
with open(out + ".obj", "w") as f:
    f.write("".join("v %.9g %.9g %.9g\n" % (v[3*k], v[3*k+1], v[3*k+2]) for k in range(nv)))
    f.write("".join("f %d %d %d\n" % (a + 1, b + 1, c + 1) for a, b, c in t))
EOF
fi

printf '| file | format | triangles | tracer | peak MB | bytes/triangle | build s | lines/s |\n'
printf '|---|---|---:|---|---:|---:|---:|---:|\n'
run() {
  local file="$1" format="$2" tracer="$3" json="$dir/run.json" err="$dir/run.err"
  /usr/bin/time -f "%M" "$scx" analyze "$file" --lines "$lines" --tracer "$tracer" --format json -q \
    >"$json" 2>"$err"
  python3 - "$json" "$(tail -1 "$err")" "$(basename "$file")" "$format" "$tracer" <<'EOF'
import json, sys
d = json.load(open(sys.argv[1]))
kb, name, fmt, tracer = int(sys.argv[2]), sys.argv[3], sys.argv[4], sys.argv[5]
tri = d["triangles"]
rate = d["lines"] / d["seconds"] if d["seconds"] > 0 else float("nan")
build = d.get("build_seconds")  # absent from reports of scx before issue 29
build = "-" if build is None else f"{build:.2f}"
print(f"| {name} | {fmt} | {tri} | {tracer} | {kb / 1024:.0f} | {kb * 1024 / tri:.0f} | {build} | {rate:.3g} |")
EOF
}
run "$base.ply" "binary PLY" rust
run "$base.ply" "binary PLY" embree
run "$base.stl" "binary STL" rust
run "$base.obj" "OBJ" rust
