#!/usr/bin/env bash
# The test command of the README: installs what is missing, runs the RTL's
# Icarus self-checks, then the whole workspace's tests (unit, property,
# co-simulation of rtl/ against the golden model, generators, C driver,
# bench smoke run).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
if [ -n "${COSIM_ALLOW_MISSING_RTL:-}" ]; then
  echo "test: unset COSIM_ALLOW_MISSING_RTL: the tests must co-simulate rtl/." >&2
  exit 1
fi
echo "== RTL self-checks (Icarus) =="
sh tb/rtl/run.sh
echo "== Rust workspace tests =="
cargo test --workspace --release "$@"
