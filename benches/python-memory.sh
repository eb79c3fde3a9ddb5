#!/usr/bin/env bash
# Peak memory of scx.Scene.from_arrays against loading the same mesh from PLY (issue 30): a height field
# of N x N quads (2 N^2 triangles, each its own patch; N = 1000 gives 2M triangles, as benches/memory.sh),
# kept as numpy arrays (float64 vertices, int64 triangles: what trimesh and most code hold) and written as
# binary little-endian PLY with float32 coordinates (the arrays hold the same float32 values). Each case is
# its own Python process under /usr/bin/time, which reports the peak resident memory:
#
#   baseline   import numpy and scx
#   arrays     ... and np.load the two arrays (what a caller of from_arrays already holds)
#   ply        scx.load("field.ply")
#   from_arrays  np.load the arrays, then scx.Scene.from_arrays(vertices, triangles)
#
#   bash benches/python-memory.sh [N] [DIR] [PYTHON]    defaults: 1000, /tmp/scx-pymemory, python3
#
# PYTHON must have the package installed (pip install ./python).
set -euo pipefail
n="${1:-1000}"
dir="${2:-/tmp/scx-pymemory}"
py="${3:-python3}"
mkdir -p "$dir"
base="$dir/field$n"
if [ ! -e "$base.ply" ]; then
  "$py" - "$n" "$base" <<'PYEOF'
import sys
import numpy as np
n, out = int(sys.argv[1]), sys.argv[2]
x, y = np.meshgrid(np.arange(n + 1) / n, np.arange(n + 1) / n, indexing="ij")
z = 0.05 * np.sin(13.0 * x) * np.cos(17.0 * y) + 0.02 * np.sin(41.0 * x * y)
v32 = np.stack([x, y, z], axis=-1).reshape(-1, 3).astype("<f4")
a = (np.arange(n)[:, None] * (n + 1) + np.arange(n)[None, :]).ravel()
b, c = a + n + 1, a + 1
t = np.empty((2 * n * n, 3), dtype=np.int64)
t[0::2] = np.stack([a, b, b + 1], axis=1)
t[1::2] = np.stack([a, b + 1, c], axis=1)
np.save(out + "-vertices.npy", v32.astype(np.float64))
np.save(out + "-triangles.npy", t)
faces = np.empty(len(t), dtype=[("n", "u1"), ("v", "<i4", (3,))])
faces["n"], faces["v"] = 3, t
with open(out + ".ply", "wb") as f:
    f.write(("ply\nformat binary_little_endian 1.0\nelement vertex %d\nproperty float x\nproperty float y\n"
             "property float z\nelement face %d\nproperty list uchar int vertex_indices\nend_header\n"
             % (len(v32), len(t))).encode())
    f.write(v32.tobytes())
    f.write(faces.tobytes())
PYEOF
fi
run() {
  local name="$1" code="$2" kb
  kb=$( { /usr/bin/time -f "%M" "$py" -c "$code" >/dev/null; } 2>&1 | tail -1)
  printf '| %s | %d |\n' "$name" "$((kb / 1024))"
}
arrays="import numpy as np, scx; v = np.load('$base-vertices.npy'); t = np.load('$base-triangles.npy')"
printf '| case (%s triangles) | peak MB |\n|---|---:|\n' "$((2 * n * n))"
run baseline "import numpy, scx"
run arrays "$arrays"
run ply "import numpy, scx; s = scx.load('$base.ply'); print(s)"
run from_arrays "$arrays; s = scx.Scene.from_arrays(v, t); print(s)"
# The two are the same scene, to the bit.
"$py" -c "$arrays; s = scx.Scene.from_arrays(v, t); p = scx.load('$base.ply')
print('same scene (fingerprints):', s.fingerprint == p.fingerprint)"
