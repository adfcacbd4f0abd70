#!/usr/bin/env bash
# The test command of the README: installs what is missing, runs the RTL's
# Icarus self-checks, then the whole workspace's tests (unit, property,
# co-simulation of rtl/ against the golden model, generators, C driver,
# bench smoke run), then the cocotb example benches (scripts/test-python.sh).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
if [ -n "${COSIM_ALLOW_MISSING_RTL:-}" ]; then
  echo "test: unset COSIM_ALLOW_MISSING_RTL: the tests must co-simulate rtl/." >&2
  exit 1
fi
# Build caches (verilated external cores in $COSIM_CACHE_DIR, the bench's
# harness and Icarus images in $TMPDIR/cancosim-bench, test scratch files in
# $TMPDIR) start empty on every run, CI or not, so every run takes the path
# a fresh machine takes (a warm cache once hid a race from CI; the cold
# path costs about a minute). COSIM_FRESH_CACHES=0 keeps the warm caches
# for quick local runs.
fresh="${COSIM_FRESH_CACHES:-1}"
if [ "$fresh" = 1 ]; then
  cold=$(mktemp -d "${TMPDIR:-/tmp}/cancosim-test.XXXXXX")
  trap 'rm -rf "$cold"' EXIT
  mkdir -p "$cold/cosim-cache" "$cold/tmp"
  export COSIM_CACHE_DIR="$cold/cosim-cache" TMPDIR="$cold/tmp"
  echo "test: empty build caches in $cold (removed at exit; COSIM_FRESH_CACHES=0 keeps the warm ones)"
fi
# Each phase says how long it took, so a slow phase is seen, not guessed.
phase() { echo "== $1 =="; t0=$SECONDS; }
took() { echo "-- $1: $((SECONDS - t0)) s"; }
phase "RTL self-checks (Icarus)"
sh tb/rtl/run.sh
took "RTL self-checks"
phase "Rust workspace tests"
cargo test --workspace --release "$@"
took "Rust workspace tests (build included)"
phase "cocotb benches of rtl/ with the model as scoreboard (Python wheel)"
bash scripts/test-python.sh --quick
took "cocotb benches"
