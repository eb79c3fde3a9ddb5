#!/usr/bin/env bash
# scx on real scene files, as a user has them (issue 29: the table of real files tried, before and after).
#
#   bash benches/real_files.sh SCX_BIN OUT.csv [FOLDER...]
#   bash benches/real_files.sh --compare BEFORE_BIN AFTER_BIN BEFORE.csv AFTER.csv [FOLDER...]
#   bash benches/real_files.sh --table BEFORE.csv AFTER.csv
#
# Runs `SCX_BIN analyze FILE --lines 1e6 --format json -q` on every scene file (.obj .gltf .glb .ply .stl,
# any case) found recursively in the folders (default: /work/shared/real-scenes, plus /tmp/mcg when present),
# and on conversions of a few of those OBJs to .glb, .ply and .stl that the script makes with `scx export`
# into a scratch folder (never the repository), so that every format appears. One CSV row per file:
#
#   file          the folder's name and the path inside it (`exported/` for the conversions)
#   format        obj, gltf, glb, ply, ply-ascii, stl, stl-ascii (from the extension and the first bytes)
#   patches       from the JSON report (empty when the file is refused)
#   exit          scx's exit code (124: killed by the time limit SCX_TIMEOUT, default 600 s)
#   key_warning   the `code` of the JSON report's first warning; scx before issue 29 wrote warnings as English
#                 strings: their first 60 characters, after the leading "SCENE: "; a refused file: the first
#                 60 characters of the first line of stderr, after "scx: error: " and the scene's path
#   mlines_per_s  lines over the report's `seconds` (the casting, not the reading), in millions
#   peak_mb       peak resident memory of the whole process, /usr/bin/time -f %M, in MiB
#   seconds       wall-clock seconds of the whole process (reading, building, casting, writing)
#
# --compare runs both binaries on each file in turn (interleaved, the order alternating from file to file)
# so that a busy machine slows both alike, writes both CSVs and prints the Markdown table of --table.
# The conversions are made by SCX_EXPORT_BIN (default: SCX_BIN, or AFTER_BIN with --compare); an export
# that does not write the format asked for (scx before issue 29 wrote OBJ text into `.ply`/`.stl`) is
# dropped with a note. SCX_LINES (default 1e6) sets the lines.
set -euo pipefail

lines="${SCX_LINES:-1e6}"
limit="${SCX_TIMEOUT:-600}"

usage() {
  sed -n '3,6p' "$0" | sed 's/^# *//' >&2
  exit 2
}

# The Markdown table of two CSVs written by this script, one row per file of either.
table() {
  python3 - "$1" "$2" <<'EOF'
import csv, sys
def rows(path):
    with open(path, newline="") as f:
        return {r["file"]: r for r in csv.DictReader(f)}
before, after = rows(sys.argv[1]), rows(sys.argv[2])
files = list(before) + [f for f in after if f not in before]
def pair(a, b):
    return a if a == b else f"{a} → {b}"
def cell(r, key):
    return (r or {}).get(key, "") or "-"
print("| file | format | patches | exit before | exit after | key warning before | key warning after "
      "| M lines/s before | M lines/s after | peak MB before | peak MB after |")
print("|---|---|---:|---:|---:|---|---|---:|---:|---:|---:|")
for f in files:
    b, a = before.get(f), after.get(f)
    fmt = cell(a or b, "format")
    esc = lambda s: s.replace("|", "\\|")
    print("| " + " | ".join([
        f, fmt, pair(cell(b, "patches"), cell(a, "patches")),
        cell(b, "exit"), cell(a, "exit"),
        esc(cell(b, "key_warning")), esc(cell(a, "key_warning")),
        cell(b, "mlines_per_s"), cell(a, "mlines_per_s"),
        cell(b, "peak_mb"), cell(a, "peak_mb"),
    ]) + " |")
EOF
}

# Every scene file under the folders, one "LABEL<TAB>PATH" line each, sorted.
scene_files() {
  local folder
  for folder in "$@"; do
    [ -d "$folder" ] || { echo "real_files.sh: $folder: no such folder, skipped" >&2; continue; }
    local label
    label="$(basename "$folder")"
    find "$folder" -type f \( -iname '*.obj' -o -iname '*.gltf' -o -iname '*.glb' -o -iname '*.ply' \
      -o -iname '*.stl' \) -print | LC_ALL=C sort | while IFS= read -r path; do
      printf '%s\t%s\n' "$label/${path#"$folder"/}" "$path"
    done
  done
}

# Conversions of a few OBJs to the other formats, into $1; prints their "LABEL<TAB>PATH" lines.
conversions() {
  local dir="$1" exporter="$2" objects=/work/shared/real-scenes/objects
  local -a jobs=(
    "$objects/cow.obj glb" "$objects/cow.obj ply" "$objects/cow.obj stl"
    "$objects/teapot.obj glb" "$objects/suzanne.obj ply" "$objects/fandisk.obj stl"
    "/tmp/mcg/CornellBox-Original.obj glb" "/tmp/mcg/CornellBox-Glossy.obj ply"
  )
  local job src ext out
  for job in "${jobs[@]}"; do
    src="${job% *}" ext="${job##* }"
    [ -e "$src" ] || continue
    out="$dir/$(basename "${src%.*}").$ext"
    if ! "$exporter" export "$src" -o "$out" -q 2>"$dir/export.err"; then
      echo "real_files.sh: export of $src to .$ext failed: $(head -1 "$dir/export.err")" >&2
      continue
    fi
    if ! python3 - "$out" "$ext" <<'EOF'; then
import sys
head = open(sys.argv[1], "rb").read(84)
ok = {"glb": head[:4] == b"glTF", "ply": head[:4] == b"ply\n"}.get(sys.argv[2])
if ok is None:  # stl: binary (80-byte header, a count) or ASCII, never OBJ text
    ok = len(head) == 84 and not head.lstrip().startswith((b"v ", b"#", b"o ", b"g ", b"mtllib"))
sys.exit(0 if ok else 1)
EOF
      echo "real_files.sh: $exporter wrote no .$ext for $src (not that format), dropped" >&2
      continue
    fi
    printf '%s\t%s\n' "exported/$(basename "$out")" "$out"
  done
}

header='file,format,patches,exit,key_warning,mlines_per_s,peak_mb,seconds'

# One run of scx on one file: appends its CSV row to $4.
run_one() {
  local scx="$1" label="$2" path="$3" out="$4" work="$5" rc=0
  rm -f "$work/json" "$work/err" "$work/time"
  timeout "$limit" /usr/bin/time -o "$work/time" -f '%M %e' \
    "$scx" analyze "$path" --lines "$lines" --format json -q </dev/null >"$work/json" 2>"$work/err" || rc=$?
  [ -s "$work/time" ] || echo '0 0' >"$work/time"
  python3 - "$label" "$path" "$rc" "$work" >>"$out" <<'EOF'
import csv, json, re, sys
label, path, rc, work = sys.argv[1], sys.argv[2], int(sys.argv[3]), sys.argv[4]
def fmt():
    ext = path.rsplit(".", 1)[-1].lower()
    head = open(path, "rb").read(512)
    if ext == "ply" and b"format ascii" in head:
        return "ply-ascii"
    if ext == "stl" and head.lstrip().startswith(b"solid") and b"facet" in head:
        return "stl-ascii"
    return ext
# /usr/bin/time puts "Command exited with non-zero status N" before its line on failure.
last = open(f"{work}/time").read().split("\n")
kb, secs = next(l for l in reversed(last) if l.strip()).split()
patches = warning = rate = ""
try:
    d = json.load(open(f"{work}/json"))
except (OSError, ValueError):
    d = None
if d is not None:
    patches = d.get("patches", "")
    if d.get("seconds"):
        rate = f"{d['lines'] / d['seconds'] / 1e6:.3g}"
    w = (d.get("warnings") or [None])[0]
    if isinstance(w, dict):
        warning = w.get("code", "")
    elif isinstance(w, str):
        warning = w.removeprefix(path + ": ")[:60]
else:
    err = open(f"{work}/err", errors="replace").read().strip().split("\n")[0]
    err = err.removeprefix("scx: error: ").removeprefix("error: ").removeprefix(path)
    err = re.sub(r"^:(\d+): ", r"line \1: ", err).removeprefix(": ")
    warning = err[:60] if rc != 124 else "timed out"
csv.writer(sys.stdout, lineterminator="\n").writerow(
    [label, fmt(), patches, rc, warning, rate, f"{int(kb) / 1024:.0f}", secs])
EOF
}

mode=single
case "${1:-}" in
  --table) [ $# -eq 3 ] || usage; table "$2" "$3"; exit 0 ;;
  --compare) [ $# -ge 5 ] || usage; mode=compare; bins=("$2" "$3"); outs=("$4" "$5"); shift 5 ;;
  -h|--help|'') usage ;;
  *) [ $# -ge 2 ] || usage; bins=("$1"); outs=("$2"); shift 2 ;;
esac
for b in "${bins[@]}"; do
  [ -x "$b" ] || { echo "real_files.sh: $b: not an executable" >&2; exit 2; }
done
folders=("$@")
if [ ${#folders[@]} -eq 0 ]; then
  folders=(/work/shared/real-scenes)
  [ -d /tmp/mcg ] && folders+=(/tmp/mcg)
fi

work="$(mktemp -d "${TMPDIR:-/tmp}/scx-real.XXXXXX")"
trap 'rm -rf "$work"' EXIT
mkdir "$work/exported"
exporter="${SCX_EXPORT_BIN:-${bins[${#bins[@]}-1]}}"
{ scene_files "${folders[@]}"; conversions "$work/exported" "$exporter"; } >"$work/files"
for out in "${outs[@]}"; do echo "$header" >"$out"; done

n=0
while IFS=$'\t' read -r label path; do
  order=(0)
  if [ "$mode" = compare ]; then
    if [ $((n % 2)) -eq 0 ]; then order=(0 1); else order=(1 0); fi
  fi
  for k in "${order[@]}"; do
    run_one "${bins[$k]}" "$label" "$path" "${outs[$k]}" "$work"
  done
  n=$((n + 1))
  echo "real_files.sh: $n $label" >&2
done <"$work/files"
[ "$mode" = compare ] && table "${outs[0]}" "${outs[1]}"
exit 0
