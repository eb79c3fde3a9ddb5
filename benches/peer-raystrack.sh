#!/usr/bin/env bash
# Form factors against a peer (issue 31, docs/sampling.md "Form factors against a peer: raystrack"): scx's
# `analyze --form-factors` (independent and sobol lines) and raystrack's view-factor matrix on the same scenes,
# both on 2 threads, interleaved in one process window, each against the closed-form F of the unit cube's
# patches; prints a markdown table of seconds and error per budget and the time to 1% and 0.5% error.
#
#   bash benches/peer-raystrack.sh                         # @cube:4, about 5 minutes after the venv exists
#   bash benches/peer-raystrack.sh --scenes @cube:2,@cube:4,@cube:6
#   SCX=/path/to/scx PEER_VENV=/tmp/peer-venv bash benches/peer-raystrack.sh --selftest
#
# The venv (default target/peer-venv) is made on first use with raystrack pinned (RAYSTRACK_VERSION, default
# 2.0.0, the current release on PyPI in November 2026) and numpy; pip pulls numba. numba's cache is emptied
# before each run (PEER_KEEP_NUMBA_CACHE=1 keeps it) so that the warm-up reports the cold compilation.
# The scx binary is $SCX, else target/release/scx (built here if missing). Other arguments go to
# benches/peer_raystrack.py (--help lists them: budgets, seeds, scenes, targets, --work DIR).
set -euo pipefail
cd "$(dirname "$0")/.."
venv="${PEER_VENV:-target/peer-venv}"
version="${RAYSTRACK_VERSION:-2.0.0}"
if [ ! -x "$venv/bin/python" ] || ! "$venv/bin/python" -c "import raystrack, importlib.metadata as m; \
assert m.version('raystrack') == '$version'" 2>/dev/null; then
  python3 -m venv "$venv"
  "$venv/bin/pip" install --quiet "raystrack==$version" numpy
fi
scx="${SCX:-target/release/scx}"
if [ ! -x "$scx" ]; then
  nice cargo build --release --bin scx --quiet
fi
export NUMBA_CACHE_DIR="$venv/numba-cache"
if [ "${PEER_KEEP_NUMBA_CACHE:-0}" != 1 ]; then
  rm -rf "$NUMBA_CACHE_DIR"
fi
export NUMBA_NUM_THREADS=2
uptime
exec "$venv/bin/python" benches/peer_raystrack.py --scx "$scx" --threads 2 "$@"
