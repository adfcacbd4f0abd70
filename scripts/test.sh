#!/usr/bin/env bash
# The test command of the README: installs what is missing, then runs the
# whole workspace's tests (unit, property, co-simulation, generators).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cargo test --workspace --release "$@"
