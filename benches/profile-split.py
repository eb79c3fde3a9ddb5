#!/usr/bin/env python3
# Groups a `perf report --no-children --sort dso,symbol` listing into the profile split of
# docs/performance.md ("Where the time goes"):
#   perf record -e cpu-clock -o p.perf target/release/scx analyze @cube:30 --lines 3e7 -q
#   perf report -i p.perf --no-children --sort dso,symbol | python3 benches/profile-split.py /dev/stdin
import sys, re, collections
# reads `perf report --no-children --sort symbol` lines, groups them
groups = collections.OrderedDict((k,0.0) for k in ["kernel","drawing","hit rules","pairing","counting","measures","other"])
rules = [
 ("kernel", r"BvhTracer|embree|all_hits|rtc|scx_|propose|collect|trace_batch|libembree|watertight"),
 ("drawing", r"global_line|batch_lines|lines_from_points|Pcg|pcg_lanes|DiscPoints|line_from_discs|uniform"),
 ("hit rules", r"canonicali|fill_from_raw|merge_row|insertion_sort|HitRules"),
 ("pairing", r"tally|ends_of|pairs::|segments|Log2Sum|environment|PatchKernel"),
 ("counting", r"sparse|counts::|radix|count_by_group|merge_runs|SparseCounts|PairCounts|sum_batches"),
 ("measures", r"measure::|rows::|entropy|log2|pow|jackknife|estimat"),
]
for line in open(sys.argv[1]):
    m = re.match(r"\s+([0-9.]+)%\s+(\S+)\s+\[(.)\]\s+(.*)", line)
    if not m: continue
    pct, sym = float(m.group(1)), m.group(2) + " " + m.group(4)
    for g, rx in rules:
        if re.search(rx, sym):
            groups[g] += pct; break
    else:
        groups["other"] += pct
print(" | ".join(f"{k} {v:.0f}%" for k, v in groups.items()))
