#!/usr/bin/env bash
# Issue 31's end-to-end ratios, S1 = @cube:30 and S3 = @cube:100 at 3e7 lines on 2 threads, each `scx
# analyze` run just after the raw-Embree yardstick it is divided by (the faster of V2r and V2or), round
# after round: on this shared machine a window's speed drifts by 10-20% within minutes and S3's counting,
# bound by memory, by up to 2x, so a ratio is only worth its own round. Prints one line per run: the
# yardstick's M lines/s, scx's whole-process wall time and peak memory, and the ratio (scx's lines per
# second over the yardstick's).
#
#   bash benches/alternate.sh [ROUNDS] [SCX]     # default 3 rounds, target/release/scx (built first)
#   ANCHOR=/path/to/embree-bench bash benches/alternate.sh
set -euo pipefail
cd "$(dirname "$0")/.."
rounds="${1:-3}"
anchor_dir="${ANCHOR:-../shared/anchors/embree-bench}"
if [ -n "${2:-}" ]; then
  scx="$2"
else
  cargo build --release --bin scx --quiet
  scx=target/release/scx
fi
bench=$(mktemp)
trap 'rm -f "$bench"' EXIT
gcc -O3 -march=native -o "$bench" "$anchor_dir/bench.c" -lembree3 -lpthread -lm

for _ in $(seq "$rounds"); do
  for s in 1 3; do
    n=$([ "$s" = 1 ] && echo 30 || echo 100)
    raw=$("$bench" -s "$s" -v V2r,V2or -t 2 -r 1 -T 4 -W 0 -X 0 2>/dev/null |
      grep -E "^\| S$s \| V2" | awk -F'|' '{print $5}' | sort -g | tail -1 | tr -d ' ')
    read -r wall kb < <({ /usr/bin/time -f "%e %M" "$scx" analyze "@cube:$n" --lines 3e7 --threads 2 -q \
      >/dev/null; } 2>&1 | tail -1)
    ratio=$(awk -v w="$wall" -v r="$raw" 'BEGIN { printf "%.3f", 30 / w / r }')
    echo "S$s  raw ${raw} M lines/s  scx ${wall} s  $((kb / 1024)) MB  ratio ${ratio}"
  done
done
