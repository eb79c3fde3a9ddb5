#!/bin/bash
# Submits a sharded scx run and its merge:  SHARDS=16 SCENE=room.obj LINES=1e10 OUT=/shared/run1 \
#   examples/slurm/submit.sh
# The merge waits for every shard (afterok); `sbatch --wait` on it blocks until the report is written.
# A shard that fails cancels the merge (--kill-on-invalid-dep), rather than leaving it pending forever.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
shards=${SHARDS:-4}
export SCENE=${SCENE:-@cube:30} LINES=${LINES:-1e9} OUT=${OUT:-$PWD/scx-states} SCX=${SCX:-scx}
array=$(sbatch --parsable --export=ALL --array="1-$shards" "$here/shards.sbatch")
echo "shards: job $array"
sbatch --parsable --export=ALL --dependency="afterok:$array" --kill-on-invalid-dep=yes "${@}" \
  "$here/merge.sbatch"
