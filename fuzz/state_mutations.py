#!/usr/bin/env python3
"""Random CRC-fixed mutations of a state file: one integer leaf of its CBOR payload changed (to 0, 1, one
more or less, 2^63, 2^64 - 1, twice or half, or a random value), the checksum recomputed, then `scx merge`
on it with a 60 s limit. Prints the exit codes, the hangs, and for exit 0 whether the report's numbers
(all but timings) moved, by field: what the meaning checks of a state (src/run/consistency.rs) let by.

    python3 -m venv /tmp/v && /tmp/v/bin/pip install cbor2
    scx analyze @cube:2 --lines 1e4 --save /tmp/m/s.scx
    /tmp/v/bin/python fuzz/state_mutations.py target/release/scx /tmp/m/s.scx 400 7
"""
import cbor2, random, struct, subprocess, sys, zlib, os, json
scx, state, n, seed = sys.argv[1], sys.argv[2], int(sys.argv[3]), int(sys.argv[4])
raw = open(state, 'rb').read()
head, payload = raw[:12], raw[24:]
doc = cbor2.loads(payload)
def leaves(v, path=()):
    if isinstance(v, dict):
        for k, x in v.items(): yield from leaves(x, path + (k,))
    elif isinstance(v, list):
        for i, x in enumerate(v): yield from leaves(x, path + (i,))
    elif isinstance(v, int) and not isinstance(v, bool):
        yield path, v
ints = list(leaves(doc))
def report(path):
    r = subprocess.run([scx, 'merge', path, '--format', 'json'], capture_output=True, timeout=60, cwd=os.path.dirname(path))
    return r
base = json.loads(report(state).stdout)
def numbers(j):
    j = {k: v for k, v in j.items() if k not in ('seconds', 'command_line', 'cpu', 'threads')}
    return json.dumps(j, sort_keys=True)
rng = random.Random(seed)
codes = {}; moved = 0; same = 0; timeouts = 0; moved_fields = {}
for t in range(n):
    d = cbor2.loads(payload)
    path, v = rng.choice(ints)
    new = rng.choice([0, 1, v + 1, max(v - 1, 0), 1 << 63, (1 << 64) - 1, rng.getrandbits(64), v * 2, v // 2])
    if new == v: new = v + 1
    new = min(new, (1 << 64) - 1)
    x = d
    for k in path[:-1]: x = x[k]
    x[path[-1]] = new
    p = cbor2.dumps(d)
    out = head + struct.pack('<QI', len(p), zlib.crc32(p) & 0xffffffff) + p
    f = os.path.join(os.path.dirname(state), 'm.scx'); open(f, 'wb').write(out)
    try:
        r = report(f)
    except subprocess.TimeoutExpired:
        timeouts += 1; continue
    codes[r.returncode] = codes.get(r.returncode, 0) + 1
    if r.returncode == 0:
        j = json.loads(r.stdout)
        key = '/'.join(str(k) for k in path if not isinstance(k, int)) 
        if numbers(j) != numbers(base):
            moved += 1; moved_fields[key] = moved_fields.get(key, 0) + 1
        else: same += 1
    if r.returncode not in (0, 2):
        print('exit', r.returncode, path, v, new, r.stderr.decode()[-300:])
print(json.dumps({'mutations': n, 'exit_codes': codes, 'timeouts': timeouts, 'exit0_numbers_moved': moved, 'exit0_numbers_same': same, 'moved_fields': moved_fields}, indent=1))
