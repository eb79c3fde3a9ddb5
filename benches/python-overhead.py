"""scx.analyze against `scx analyze` (issue 30): the same run, the same tracer, timed interleaved.

    python benches/python-overhead.py [SCENE] [LINES] [REPEATS] [SCX]
    defaults: @cube:30 3e7 5 target/release/scx

Run it with the Python of a venv where the package is installed (`pip install ./python`). Each repeat runs
the command line (`scx analyze SCENE --lines LINES --tracer rust --format json`) and then the same run
from Python (`scx.analyze(scx.load(SCENE), lines=LINES)`, with keep_state=False and the default
keep_state=True), in turn, so that a busy machine slows all alike. Per run it records the run's own
seconds (the report's `seconds`: casting and measuring), the wall time of the whole (the process for the
command line, the call for Python: both with the tracer's build) and the CPU seconds of all threads;
prints each, and the medians with Python's against the command line's. Checks that both give the same
I_s^c to the bit.
"""

import json
import resource
import statistics
import subprocess
import sys
import time

import scx

scene_name = sys.argv[1] if len(sys.argv) > 1 else "@cube:30"
lines = float(sys.argv[2]) if len(sys.argv) > 2 else 3e7
repeats = int(sys.argv[3]) if len(sys.argv) > 3 else 5
binary = sys.argv[4] if len(sys.argv) > 4 else "target/release/scx"


def cpu_of_children() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def cpu_of_self() -> float:
    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime + r.ru_stime


def cli() -> dict:
    before, began = cpu_of_children(), time.perf_counter()
    out = subprocess.run(
        [binary, "analyze", scene_name, "--lines", f"{lines:g}", "--tracer", "rust", "--format", "json", "-q"],
        check=True, capture_output=True, text=True,
    )
    wall, cpu = time.perf_counter() - began, cpu_of_children() - before
    doc = json.loads(out.stdout)
    return {"run": doc["seconds"], "wall": wall, "cpu": cpu,
            "isc": doc["visibility"]["continuous_mutual_information"]["value"]}


def python(keep_state: bool) -> dict:
    scene = scx.load(scene_name)
    before, began = cpu_of_self(), time.perf_counter()
    a = scx.analyze(scene, lines=lines, keep_state=keep_state)
    wall, cpu = time.perf_counter() - began, cpu_of_self() - before
    return {"run": a.seconds, "wall": wall, "cpu": cpu, "isc": a.continuous_mutual_information.value}


runs = {"cli": [], "python keep_state=False": [], "python": []}
for k in range(repeats):
    for name, run in (("cli", cli), ("python keep_state=False", lambda: python(False)),
                      ("python", lambda: python(True))):
        r = run()
        runs[name].append(r)
        print(f"repeat {k + 1} {name:24s} run {r['run']:7.3f} s  wall {r['wall']:7.3f} s  cpu {r['cpu']:7.3f} s",
              flush=True)
isc = {r["isc"] for rs in runs.values() for r in rs}
assert len(isc) == 1, f"the runs differ: {isc}"
print(f"\n{scene_name}, {lines:g} lines, {repeats} interleaved repeats; medians, and Python's against the CLI's:")
base = {m: statistics.median(r[m] for r in runs["cli"]) for m in ("run", "wall", "cpu")}
for name, rs in runs.items():
    med = {m: statistics.median(r[m] for r in rs) for m in ("run", "wall", "cpu")}
    print(f"  {name:24s} " + "  ".join(
        f"{m} {med[m]:7.3f} s ({100 * (med[m] / base[m] - 1):+5.1f}%)" for m in ("run", "wall", "cpu")))
