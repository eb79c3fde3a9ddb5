#!/usr/bin/env bash
# docs/performance.md's table "Throughput against raw Embree", from one window (the machine's speed drifts
# 10-20% over minutes, so every figure of a ratio comes from the same run of this script): raw Embree
# all-hits (the shared yardstick, ../shared/anchors/embree-bench), our kernels (cargo bench --bench
# throughput, "all-hits" column), `scx analyze` end to end through the CLI with its peak memory, and the
# same without the discrete measures, on S1 = @cube:30, S3 = @cube:100 (3e7 lines) and @cube:130 (1e8
# lines), 2 threads.
#
#   bash benches/window.sh            # about 20 minutes; needs the yardstick's C file and libembree3
#   ANCHOR=/path/to/embree-bench bash benches/window.sh
set -euo pipefail
cd "$(dirname "$0")/.."
anchor_dir="${ANCHOR:-../shared/anchors/embree-bench}"
cargo build --release --bin scx --quiet
scx=target/release/scx
bench=$(mktemp)
trap 'rm -f "$bench"' EXIT
gcc -O3 -march=native -o "$bench" "$anchor_dir/bench.c" -lembree3 -lpthread -lm

echo "== raw Embree all-hits (yardstick), 2 threads: the Mlines/s median of V2r and V2or"
for s in 1 3; do
  "$bench" -s "$s" -v V2r,V2or -t 2 -r 3 -T 4 -W 0 -X 0 | grep -E '^\| S.*\| V2' | cut -d'|' -f2-6
done

echo "== scx analyze end to end (CLI), 2 threads, median of 3 runs: M lines/s over the process's wall-clock time"
echo "   (scene, BVH, tracing, counting, every measure, output), the same over the report's seconds (which leave"
echo "   out loading the scene and building the BVH), peak RSS, bytes per distinct pair"
for run in "@cube:30 3e7" "@cube:100 3e7" "@cube:130 1e8"; do
  set -- $run
  for tracer in rust embree; do
    out=$(mktemp)
    for k in 1 2 3; do
      /usr/bin/time -f "%e %M" -o "$out.rss$k" "$scx" analyze "$1" --lines "$2" --tracer "$tracer" \
        --threads 2 --format json -q > "$out.$k"
    done
    python3 - "$out" "$1" "$tracer" <<'PY'
import json, statistics, sys
base = sys.argv[1]
runs = [json.load(open(f"{base}.{k}")) for k in (1, 2, 3)]
timed = [open(f"{base}.rss{k}").read().split()[-2:] for k in (1, 2, 3)]
walls = sorted(a["lines"] / float(t[0]) / 1e6 for a, t in zip(runs, timed))
rates = sorted(a["lines"] / a["seconds"] / 1e6 for a in runs)
rss = max(int(t[1]) * 1024 for t in timed)
d = runs[0]["distinct_pairs"]
print(f"{sys.argv[2]:<10} {sys.argv[3]:<7} {statistics.median(walls):6.2f} M lines/s "
      f"({walls[0]:.2f}-{walls[-1]:.2f}), report's seconds {statistics.median(rates):6.2f}  "
      f"peak {rss / 2**30:5.2f} GiB  {d} distinct pairs  {rss / d:6.1f} B/pair")
PY
    rm -f "$out" "$out".*
  done
done

echo "== the same without the discrete measures (--measures continuous: no pair counts, groups' lists, total or"
echo "   entropy estimates), rust tracer, median of 3: what tracing, drawing and pairing cost by themselves"
for run in "@cube:30 3e7" "@cube:100 3e7"; do
  set -- $run
  walls=()
  for k in 1 2 3; do
    walls+=("$( { /usr/bin/time -f "%e" "$scx" analyze "$1" --lines "$2" --threads 2 --measures continuous \
      -q > /dev/null; } 2>&1 | tail -1)")
  done
  python3 -c 'import statistics,sys; w=sorted(float(x) for x in sys.argv[3:]); n=float(sys.argv[2]);
print(f"{sys.argv[1]:<10} rust    {n/statistics.median(w)/1e6:6.2f} M lines/s ({n/w[-1]/1e6:.2f}-{n/w[0]/1e6:.2f})")' \
    "$1" "$2" "${walls[@]}"
done

echo "== kernels alone (cargo bench --bench throughput, all-hits column; 2-thread rows)"
SCX_BENCH_TRACERS=rust,single cargo bench --quiet --bench throughput -- @cube:30 @cube:100 3e7 \
  | grep -E '^(scene|@)'
